//! RGB frames to H.264 NAL units through Cisco's OpenH264 encoder (the `openh264` crate builds
//! it from its bundled source with the C++ compiler): 4:2:0 (yuv420p) BT.601 limited range, the
//! colour space browsers assume, a key frame every two seconds, no skipped frames.

use openh264::encoder::{
    Encoder, EncoderConfig, FrameRate, FrameType, IntraFramePeriod, QpRange, RateControlMode,
    VuiConfig,
};
use openh264::formats::{RgbSliceU8, YUVBuffer};
use openh264::OpenH264API;

/// The quantiser range, constant quality without rate control (which OpenH264 cannot keep
/// without skipping frames): about libx264's default CRF 23.
const QP: (u8, u8) = (20, 24);

/// One encoded frame: its NAL units without start codes, and whether it is a key (IDR) frame.
#[derive(Debug)]
pub(super) struct EncodedFrame {
    pub nals: Vec<Vec<u8>>,
    pub keyframe: bool,
}

/// An H.264 encoder for frames of one size; odd sizes are padded to even ones (4:2:0 chroma
/// needs them) by repeating the last column and row.
pub(super) struct H264Encoder {
    encoder: Encoder,
    size: (usize, usize),
    padded: (usize, usize),
    /// The padded RGB frame (only used for odd sizes).
    scratch: Vec<u8>,
}

impl H264Encoder {
    /// An encoder for `width × height` frames shown at `fps`.
    pub fn new(width: usize, height: usize, fps: f64) -> Result<Self, String> {
        let padded = (width + width % 2, height + height % 2);
        let config = EncoderConfig::new()
            .max_frame_rate(FrameRate::from_hz(fps as f32))
            .rate_control_mode(RateControlMode::Off)
            .qp(QpRange::new(QP.0, QP.1))
            .skip_frames(false)
            .intra_frame_period(IntraFramePeriod::from_num_frames(
                (2.0 * fps).round().max(1.0) as u32,
            ))
            .vui(VuiConfig::bt601());
        let encoder = Encoder::with_api_config(OpenH264API::from_source(), config)
            .map_err(|e| format!("the H.264 encoder did not start: {e}"))?;
        Ok(Self {
            encoder,
            size: (width, height),
            padded,
            scratch: Vec::new(),
        })
    }

    /// The size of the encoded pictures: the frame size rounded up to even.
    pub fn padded_size(&self) -> (usize, usize) {
        self.padded
    }

    /// Encodes `rgb` (`width · height · 3` bytes of the size given to [`new`](Self::new)).
    pub fn encode(&mut self, rgb: &[u8]) -> Result<EncodedFrame, String> {
        let rgb = if self.padded == self.size {
            rgb
        } else {
            pad_to_even(rgb, self.size, self.padded, &mut self.scratch);
            &self.scratch
        };
        let yuv = YUVBuffer::from_rgb8_source(RgbSliceU8::new(rgb, self.padded));
        let stream = self
            .encoder
            .encode(&yuv)
            .map_err(|e| format!("the H.264 encoder failed: {e}"))?;
        if matches!(stream.frame_type(), FrameType::Skip | FrameType::Invalid) {
            return Err("the H.264 encoder dropped a frame".into());
        }
        let mut nals = Vec::new();
        for layer in (0..stream.num_layers()).filter_map(|l| stream.layer(l)) {
            for nal in (0..layer.nal_count()).filter_map(|n| layer.nal_unit(n)) {
                nals.push(strip_start_code(nal).to_vec());
            }
        }
        let keyframe = nals.iter().any(|nal| nal_type(nal) == Some(NAL_IDR));
        Ok(EncodedFrame { nals, keyframe })
    }
}

/// NAL unit types (H.264 Table 7-1) the muxer needs.
pub(super) const NAL_IDR: u8 = 5;
/// Sequence parameter set.
pub(super) const NAL_SPS: u8 = 7;
/// Picture parameter set.
pub(super) const NAL_PPS: u8 = 8;

/// The type of a NAL unit (without start code).
pub(super) fn nal_type(nal: &[u8]) -> Option<u8> {
    nal.first().map(|b| b & 0x1F)
}

/// `nal` without its Annex B start code (`00 00 01` or `00 00 00 01`).
fn strip_start_code(nal: &[u8]) -> &[u8] {
    nal.strip_prefix(&[0, 0, 0, 1])
        .or_else(|| nal.strip_prefix(&[0, 0, 1]))
        .unwrap_or(nal)
}

/// Copies `rgb` of `size` into `out` of `padded`, repeating the last column and row.
fn pad_to_even(rgb: &[u8], size: (usize, usize), padded: (usize, usize), out: &mut Vec<u8>) {
    let (row, padded_row) = (size.0 * 3, padded.0 * 3);
    out.clear();
    for y in 0..padded.1 {
        let line = &rgb[y.min(size.1 - 1) * row..][..row];
        out.extend_from_slice(line);
        out.extend_from_slice(&line[row - 3..][..padded_row - row]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padding_repeats_the_last_column_and_row() {
        // 3×1 pixels, grey levels 1, 2, 3.
        let rgb = [1, 1, 1, 2, 2, 2, 3, 3, 3];
        let mut out = Vec::new();
        pad_to_even(&rgb, (3, 1), (4, 2), &mut out);
        let grey: Vec<u8> = out.chunks(3).map(|p| p[0]).collect();
        assert_eq!(grey, [1, 2, 3, 3, 1, 2, 3, 3]);
    }

    #[test]
    fn start_codes_of_both_lengths_are_removed() {
        assert_eq!(strip_start_code(&[0, 0, 0, 1, 0x67, 9]), [0x67, 9]);
        assert_eq!(strip_start_code(&[0, 0, 1, 0x68]), [0x68]);
        assert_eq!(nal_type(&[0x65, 0]), Some(NAL_IDR));
    }

    #[test]
    fn every_frame_is_encoded_and_the_first_is_a_key_frame() {
        let (w, h) = (33, 25);
        let mut encoder = H264Encoder::new(w, h, 25.0).unwrap();
        assert_eq!(encoder.padded_size(), (34, 26));
        for n in 0..5u8 {
            let frame = encoder.encode(&vec![n * 40; w * h * 3]).unwrap();
            // Later frames may be key frames too where the encoder sees a scene change.
            assert!(frame.keyframe || n > 0, "frame {n}");
            assert!(!frame.nals.is_empty());
            if n == 0 {
                let types: Vec<_> = frame.nals.iter().filter_map(|n| nal_type(n)).collect();
                assert!(
                    types.contains(&NAL_SPS) && types.contains(&NAL_PPS),
                    "{types:?}"
                );
            }
        }
    }
}
