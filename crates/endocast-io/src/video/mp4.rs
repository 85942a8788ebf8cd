//! A streaming MP4 (ISO/IEC 14496-12 and -15) muxer for one H.264 video track.
//!
//! Samples go into `mdat` as they come and only their sizes and key-frame numbers are kept
//! (a few bytes per frame), so a flight of any length muxes in bounded memory; `moov` follows
//! `mdat`, and `mdat`'s 64-bit size is patched at the end. The MP4 crates at hand either keep
//! every sample in memory until the end (muxide) or want the avcC record and length-prefixed
//! samples built by the caller anyway (mp4), so the dozen boxes one track needs are written
//! here. Frame timing is exact for rates with up to three decimals: the media timescale is
//! 1000 × fps and each frame lasts 1000 ticks.

use super::h264::{nal_type, EncodedFrame, NAL_PPS, NAL_SPS};
use std::io::{self, Seek, SeekFrom, Write};

/// The movie header's timescale (ms).
const MOVIE_TIMESCALE: u32 = 1000;
/// Ticks of the media timescale per frame.
const FRAME_TICKS: u32 = 1000;

/// Writes one H.264 track into `W` as frames are pushed.
pub(super) struct Mp4Muxer<W: Write + Seek> {
    out: W,
    /// Where `mdat`'s 64-bit size field is, and where its header starts.
    mdat_start: u64,
    mdat_bytes: u64,
    sample_sizes: Vec<u32>,
    /// 1-based numbers of the key frames.
    key_frames: Vec<u32>,
    sps: Option<Vec<u8>>,
    pps: Option<Vec<u8>>,
    width: u16,
    height: u16,
    /// Media ticks per second: 1000 × fps.
    timescale: u32,
}

impl<W: Write + Seek> Mp4Muxer<W> {
    /// Starts the file: `ftyp` and the header of `mdat`. `width × height` are the coded
    /// picture's (even) edges.
    pub fn new(mut out: W, width: u16, height: u16, fps: f64) -> io::Result<Self> {
        let mut ftyp = Vec::new();
        ftyp.extend_from_slice(b"isom");
        ftyp.extend_from_slice(&0x200u32.to_be_bytes());
        for brand in [b"isom", b"iso2", b"avc1", b"mp41"] {
            ftyp.extend_from_slice(brand);
        }
        out.write_all(&boxed(b"ftyp", &ftyp))?;
        let mdat_start = out.stream_position()?;
        // size 1: the 64-bit size follows the type; patched in `finish`.
        out.write_all(&1u32.to_be_bytes())?;
        out.write_all(b"mdat")?;
        out.write_all(&0u64.to_be_bytes())?;
        Ok(Self {
            out,
            mdat_start,
            mdat_bytes: 16,
            sample_sizes: Vec::new(),
            key_frames: Vec::new(),
            sps: None,
            pps: None,
            width,
            height,
            timescale: (fps * f64::from(FRAME_TICKS)).round().max(1.0) as u32,
        })
    }

    /// Appends one frame: its parameter sets go to the sample description (the first ones
    /// seen), the other NAL units into `mdat` with 4-byte lengths.
    pub fn push(&mut self, frame: &EncodedFrame) -> io::Result<()> {
        let mut size = 0u32;
        for nal in &frame.nals {
            match nal_type(nal) {
                Some(NAL_SPS) if self.sps.is_none() => self.sps = Some(nal.clone()),
                Some(NAL_PPS) if self.pps.is_none() => self.pps = Some(nal.clone()),
                Some(NAL_SPS | NAL_PPS) | None => {}
                Some(_) => {
                    let length = u32::try_from(nal.len()).map_err(|_| too_big())?;
                    self.out.write_all(&length.to_be_bytes())?;
                    self.out.write_all(nal)?;
                    size = size.checked_add(length + 4).ok_or_else(too_big)?;
                }
            }
        }
        self.mdat_bytes += u64::from(size);
        self.sample_sizes.push(size);
        if frame.keyframe {
            self.key_frames.push(self.sample_sizes.len() as u32);
        }
        Ok(())
    }

    /// Number of frames pushed.
    pub fn frames(&self) -> usize {
        self.sample_sizes.len()
    }

    /// Patches `mdat`'s size, writes `moov` and returns the output.
    pub fn finish(mut self) -> io::Result<W> {
        let (Some(sps), Some(pps)) = (&self.sps, &self.pps) else {
            return Err(io::Error::other("the H.264 stream has no parameter sets"));
        };
        let moov = self.moov(sps, pps)?;
        self.out.seek(SeekFrom::Start(self.mdat_start + 8))?;
        self.out.write_all(&self.mdat_bytes.to_be_bytes())?;
        self.out.seek(SeekFrom::End(0))?;
        self.out.write_all(&moov)?;
        self.out.flush()?;
        Ok(self.out)
    }

    fn moov(&self, sps: &[u8], pps: &[u8]) -> io::Result<Vec<u8>> {
        let frames = u32::try_from(self.sample_sizes.len()).map_err(|_| too_big())?;
        let media_duration = u64::from(frames) * u64::from(FRAME_TICKS);
        let movie_duration =
            media_duration * u64::from(MOVIE_TIMESCALE) / u64::from(self.timescale);
        let movie_duration = u32::try_from(movie_duration).map_err(|_| too_big())?;
        let media_duration = u32::try_from(media_duration).map_err(|_| too_big())?;
        let first_sample = u32::try_from(self.mdat_start + 16).map_err(|_| too_big())?;

        let stbl = [
            boxed(
                b"stsd",
                &full(0, &[&1u32.to_be_bytes(), &self.avc1(sps, pps)?]),
            ),
            boxed(
                b"stts",
                &full(
                    0,
                    &[
                        &1u32.to_be_bytes(),
                        &frames.to_be_bytes(),
                        &FRAME_TICKS.to_be_bytes(),
                    ],
                ),
            ),
            boxed(
                b"stss",
                &full(0, &[&u32s(self.key_frames.len() as u32, &self.key_frames)]),
            ),
            boxed(b"stsc", &full(0, &[&u32s(1, &[1, frames, 1])])),
            boxed(
                b"stsz",
                &full(0, &[&0u32.to_be_bytes(), &u32s(frames, &self.sample_sizes)]),
            ),
            boxed(b"stco", &full(0, &[&u32s(1, &[first_sample])])),
        ]
        .concat();
        let url = boxed(b"url ", &full(1, &[]));
        let dinf = boxed(
            b"dinf",
            &boxed(b"dref", &full(0, &[&1u32.to_be_bytes(), &url])),
        );
        let vmhd = boxed(b"vmhd", &full(1, &[&[0u8; 8]]));
        let minf = boxed(b"minf", &[vmhd, dinf, boxed(b"stbl", &stbl)].concat());
        let mdhd = full(
            0,
            &[
                &[0u8; 8],
                &self.timescale.to_be_bytes(),
                &media_duration.to_be_bytes(),
                &0x55C4u16.to_be_bytes(), // language "und"
                &[0u8; 2],
            ],
        );
        let hdlr = full(0, &[&[0u8; 4], b"vide", &[0u8; 12], b"VideoHandler\0"]);
        let mdia = boxed(
            b"mdia",
            &[boxed(b"mdhd", &mdhd), boxed(b"hdlr", &hdlr), minf].concat(),
        );
        let tkhd = full(
            3,
            &[
                &[0u8; 8],
                &1u32.to_be_bytes(), // track ID
                &[0u8; 4],
                &movie_duration.to_be_bytes(),
                &[0u8; 16], // reserved, layer, alternate group, volume, reserved
                &MATRIX,
                &(u32::from(self.width) << 16).to_be_bytes(),
                &(u32::from(self.height) << 16).to_be_bytes(),
            ],
        );
        let trak = boxed(b"trak", &[boxed(b"tkhd", &tkhd), mdia].concat());
        let mvhd = full(
            0,
            &[
                &[0u8; 8],
                &MOVIE_TIMESCALE.to_be_bytes(),
                &movie_duration.to_be_bytes(),
                &0x0001_0000u32.to_be_bytes(), // rate 1.0
                &0x0100u16.to_be_bytes(),      // volume 1.0
                &[0u8; 10],
                &MATRIX,
                &[0u8; 24],
                &2u32.to_be_bytes(), // next track ID
            ],
        );
        Ok(boxed(b"moov", &[boxed(b"mvhd", &mvhd), trak].concat()))
    }

    /// The `avc1` sample entry with its `avcC` decoder configuration.
    fn avc1(&self, sps: &[u8], pps: &[u8]) -> io::Result<Vec<u8>> {
        let (Ok(sps_len), Ok(pps_len)) = (u16::try_from(sps.len()), u16::try_from(pps.len()))
        else {
            return Err(too_big());
        };
        let [_, profile, compatibility, level, ..] = *sps else {
            return Err(io::Error::other(
                "the H.264 sequence parameter set is too short",
            ));
        };
        let mut avcc = vec![1, profile, compatibility, level, 0xFF, 0xE1];
        avcc.extend_from_slice(&sps_len.to_be_bytes());
        avcc.extend_from_slice(sps);
        avcc.push(1);
        avcc.extend_from_slice(&pps_len.to_be_bytes());
        avcc.extend_from_slice(pps);
        if matches!(profile, 100 | 110 | 122 | 144) {
            // High profiles: 4:2:0, 8-bit, no SPS extensions.
            avcc.extend_from_slice(&[0xFD, 0xF8, 0xF8, 0]);
        }
        let mut entry = vec![0u8; 6];
        entry.extend_from_slice(&1u16.to_be_bytes()); // data reference index
        entry.extend_from_slice(&[0u8; 16]);
        entry.extend_from_slice(&self.width.to_be_bytes());
        entry.extend_from_slice(&self.height.to_be_bytes());
        entry.extend_from_slice(&0x0048_0000u32.to_be_bytes()); // 72 dpi
        entry.extend_from_slice(&0x0048_0000u32.to_be_bytes());
        entry.extend_from_slice(&[0u8; 4]);
        entry.extend_from_slice(&1u16.to_be_bytes()); // frames per sample
        entry.extend_from_slice(&[0u8; 32]); // compressor name
        entry.extend_from_slice(&0x0018u16.to_be_bytes()); // depth
        entry.extend_from_slice(&0xFFFFu16.to_be_bytes());
        entry.extend_from_slice(&boxed(b"avcC", &avcc));
        Ok(boxed(b"avc1", &entry))
    }
}

/// The identity transformation matrix of `mvhd` and `tkhd`.
const MATRIX: [u8; 36] = {
    let mut m = [0u8; 36];
    m[1] = 1; // a = 1.0 (16.16)
    m[17] = 1; // d = 1.0
    m[32] = 0x40; // w = 1.0 (2.30)
    m
};

fn too_big() -> io::Error {
    io::Error::other("the video is too long for an MP4 sample table")
}

/// A box: 32-bit size, type, payload.
fn boxed(kind: &[u8; 4], payload: &[u8]) -> Vec<u8> {
    let size = (payload.len() + 8) as u32;
    [&size.to_be_bytes()[..], kind, payload].concat()
}

/// A full box's payload: version, 24-bit flags, then `parts`.
fn full(flags: u32, parts: &[&[u8]]) -> Vec<u8> {
    let mut payload = (flags & 0x00FF_FFFF).to_be_bytes().to_vec();
    for part in parts {
        payload.extend_from_slice(part);
    }
    payload
}

/// A count followed by big-endian words.
fn u32s(count: u32, words: &[u32]) -> Vec<u8> {
    let mut bytes = count.to_be_bytes().to_vec();
    for word in words {
        bytes.extend_from_slice(&word.to_be_bytes());
    }
    bytes
}
