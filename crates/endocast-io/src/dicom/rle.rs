//! RLE Lossless frames (transfer syntax 1.2.840.10008.1.2.5, PS3.5 annex G), decoded here
//! rather than by dicom-rs 0.10, which trusts the RLE header: it reserves four bytes for every
//! segment the first word claims (a JPEG stream relabelled as RLE asks for 15 GB) and inflates
//! each segment whole before cutting it to the image size.
//!
//! Here the header is checked against the fragment (one segment per byte of a sample, offsets
//! increasing inside the fragment) and every segment is decoded into exactly Rows × Columns
//! bytes: nothing is allocated beyond the frame, and a segment that decodes to fewer bytes is
//! an error, not a zero-filled image.

use super::frame::compressed_frame;
use dicom_object::DefaultDicomObject;

/// RLE Lossless.
const UID: &str = "1.2.840.10008.1.2.5";
/// The RLE header: the segment count and fifteen offsets, 4 bytes each.
const HEADER_BYTES: usize = 64;

/// Whether `uid` (trailing padding allowed) names RLE Lossless.
pub(super) fn is_rle(uid: &str) -> bool {
    uid.trim_end_matches(['\0', ' ']) == UID
}

/// The little-endian sample bytes of frame `frame` of `object`, `bytes_per_sample` (1 or 2)
/// bytes a pixel, one sample a pixel.
pub(super) fn decode_frame(
    object: &DefaultDicomObject,
    frame: u32,
    bytes_per_sample: usize,
) -> Result<Vec<u8>, String> {
    let (rows, columns, data) = compressed_frame(object, frame)?;
    let pixels = usize::from(rows) * usize::from(columns);
    let segments = segments(&data, bytes_per_sample)?;
    let mut out = vec![0u8; pixels * bytes_per_sample];
    let mut plane = Vec::with_capacity(pixels);
    // Segment 0 holds the most significant byte of every sample.
    for (n, segment) in segments.into_iter().enumerate() {
        unpack(segment, pixels, &mut plane);
        if plane.len() < pixels {
            return Err(format!(
                "RLE segment {n} decodes to {} bytes, but Rows × Columns ({rows} × {columns}) \
                 need {pixels}: the header or the pixel data are wrong",
                plane.len()
            ));
        }
        let byte = bytes_per_sample - 1 - n;
        for (sample, &value) in out.chunks_exact_mut(bytes_per_sample).zip(&plane) {
            sample[byte] = value;
        }
    }
    Ok(out)
}

/// The `count` segments of an RLE fragment, checked against its header: the segment count,
/// then offsets that start after the header, increase, and stay inside the fragment.
fn segments(data: &[u8], count: usize) -> Result<Vec<&[u8]>, String> {
    let word = |i: usize| {
        data.get(4 * i..4 * i + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let claimed = match word(0) {
        Some(claimed) if data.len() >= HEADER_BYTES => claimed,
        _ => return Err("the RLE fragment is shorter than its 64-byte header".into()),
    };
    if claimed != count {
        return Err(format!(
            "the RLE header declares {claimed} segments, a grey-scale image of {count} byte(s) \
             a sample has {count} (is the transfer syntax right?)"
        ));
    }
    let mut bounds: Vec<usize> = (1..=count).filter_map(word).collect();
    bounds.push(data.len());
    if bounds[0] != HEADER_BYTES || bounds.windows(2).any(|w| w[0] > w[1]) {
        return Err(format!(
            "the RLE segment offsets {:?} do not lie in order inside the {}-byte fragment",
            &bounds[..count],
            data.len()
        ));
    }
    Ok(bounds.windows(2).map(|w| &data[w[0]..w[1]]).collect())
}

/// PackBits-decodes `segment` into `plane`, stopping at `limit` bytes.
fn unpack(segment: &[u8], limit: usize, plane: &mut Vec<u8>) {
    plane.clear();
    let mut rest = segment;
    while let Some((&header, tail)) = rest.split_first() {
        if plane.len() >= limit {
            break;
        }
        let room = limit - plane.len();
        rest = match header {
            // A literal run of header + 1 bytes.
            0..=127 => {
                let take = (usize::from(header) + 1).min(tail.len());
                plane.extend_from_slice(&tail[..take.min(room)]);
                &tail[take..]
            }
            // No operation.
            128 => tail,
            // The next byte, 257 − header times.
            _ => match tail.split_first() {
                Some((&value, after)) => {
                    let times = 257 - usize::from(header);
                    plane.resize(plane.len() + times.min(room), value);
                    after
                }
                None => tail,
            },
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fragment(segments: &[&[u8]]) -> Vec<u8> {
        let mut data = vec![0u8; HEADER_BYTES];
        data[..4].copy_from_slice(&(segments.len() as u32).to_le_bytes());
        let mut offset = HEADER_BYTES;
        for (i, segment) in segments.iter().enumerate() {
            data[4 + 4 * i..8 + 4 * i].copy_from_slice(&(offset as u32).to_le_bytes());
            offset += segment.len();
        }
        segments.iter().for_each(|s| data.extend_from_slice(s));
        data
    }

    #[test]
    fn unpacks_literal_and_repeated_runs_up_to_the_limit() {
        let mut plane = Vec::new();
        // Two literal bytes, then 7 repeated 4 times, then a no-op.
        unpack(&[1, 9, 8, 253, 7, 128], 100, &mut plane);
        assert_eq!(plane, [9, 8, 7, 7, 7, 7]);
        unpack(&[129, 5], 10, &mut plane);
        assert_eq!(plane, [5; 10]);
    }

    #[test]
    fn checks_the_header_against_the_fragment() {
        let data = fragment(&[&[0, 1], &[0, 2]]);
        assert_eq!(segments(&data, 2).unwrap(), [&[0u8, 1][..], &[0, 2][..]]);
        assert!(segments(&data, 1)
            .unwrap_err()
            .contains("declares 2 segments"));
        // A JPEG stream's first word claims billions of segments.
        let jpeg = [0xFF, 0xD8, 0xFF, 0xE0, 0, 16];
        assert!(segments(&jpeg, 2).is_err());
        let mut beyond = data.clone();
        beyond[8..12].copy_from_slice(&1000u32.to_le_bytes());
        assert!(segments(&beyond, 2).unwrap_err().contains("offsets"));
    }
}
