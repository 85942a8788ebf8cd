//! MP4 by the built-in H.264 encoder and muxer: the boxes parsed here (frame count, timescale,
//! duration, size, key frames), every frame decoded back, and `ffprobe`'s reading when it is
//! installed (required under CI).

use crate::video::{frame, listing};
use endocast_io::video::{open_sink, VideoOptions};
use openh264::decoder::Decoder;
use openh264::formats::YUVSource;
use std::path::Path;
use std::process::Command;

/// The boxes directly inside `data`: (type, body).
fn boxes(mut data: &[u8]) -> Vec<(String, &[u8])> {
    let mut found = Vec::new();
    while data.len() >= 8 {
        let word = |at: usize| u32::from_be_bytes(data[at..at + 4].try_into().unwrap());
        let kind = String::from_utf8_lossy(&data[4..8]).into_owned();
        let (header, size) = match word(0) {
            1 => (
                16,
                u64::from_be_bytes(data[8..16].try_into().unwrap()) as usize,
            ),
            0 => (8, data.len()),
            n => (8, n as usize),
        };
        assert!(
            size >= header && size <= data.len(),
            "box {kind} of {size} bytes"
        );
        found.push((kind, &data[header..size]));
        data = &data[size..];
    }
    assert!(data.is_empty(), "{} stray bytes", data.len());
    found
}

/// The body of the box at `path` (containers only on the way), inside `data`.
fn find<'a>(data: &'a [u8], path: &[&str]) -> &'a [u8] {
    let (first, rest) = path.split_first().unwrap();
    let body = boxes(data)
        .into_iter()
        .find(|(kind, _)| kind == first)
        .unwrap_or_else(|| panic!("no {first} box"))
        .1;
    if rest.is_empty() {
        body
    } else {
        find(body, rest)
    }
}

fn u32_at(data: &[u8], at: usize) -> u32 {
    u32::from_be_bytes(data[at..at + 4].try_into().unwrap())
}

/// A full box's words after version and flags.
fn words(full_box: &[u8]) -> Vec<u32> {
    full_box[4..]
        .chunks_exact(4)
        .map(|c| u32::from_be_bytes(c.try_into().unwrap()))
        .collect()
}

/// What a player needs from the file.
#[derive(Debug)]
struct Track {
    timescale: u32,
    media_duration: u32,
    movie_ms: u32,
    size: (u16, u16),
    sample_sizes: Vec<u32>,
    key_frames: Vec<u32>,
    /// The frames' bytes, as Annex B with the parameter sets in front of the first.
    annex_b: Vec<Vec<u8>>,
}

fn parse(bytes: &[u8]) -> Track {
    let top = boxes(bytes);
    assert_eq!(top[0].0, "ftyp", "ftyp comes first");
    assert_eq!(&top[0].1[..4], b"isom");
    let moov = find(bytes, &["moov"]);
    let mvhd = find(moov, &["mvhd"]);
    let stbl = find(moov, &["trak", "mdia", "minf", "stbl"]);
    let mdhd = find(moov, &["trak", "mdia", "mdhd"]);
    assert_eq!(&find(moov, &["trak", "mdia", "hdlr"])[8..12], b"vide");
    let stsd = find(stbl, &["stsd"]);
    assert_eq!(u32_at(stsd, 4), 1, "one sample entry");
    let avc1 = find(&stsd[8..], &["avc1"]);
    let size = (
        u16::from_be_bytes([avc1[24], avc1[25]]),
        u16::from_be_bytes([avc1[26], avc1[27]]),
    );
    let avcc = find(&avc1[78..], &["avcC"]);
    let sps_len = usize::from(u16::from_be_bytes([avcc[6], avcc[7]]));
    let sps = &avcc[8..8 + sps_len];
    let pps_at = 8 + sps_len + 3;
    let pps_len = usize::from(u16::from_be_bytes([avcc[pps_at - 2], avcc[pps_at - 1]]));
    let pps = &avcc[pps_at..pps_at + pps_len];

    let stts = words(find(stbl, &["stts"]));
    let stsz = words(find(stbl, &["stsz"]));
    let stss = words(find(stbl, &["stss"]));
    let stco = words(find(stbl, &["stco"]));
    let stsc = words(find(stbl, &["stsc"]));
    let sample_sizes = stsz[2..].to_vec();
    assert_eq!(stsz[1] as usize, sample_sizes.len());
    assert_eq!(stts, [1, stsz[1], 1000], "one frame duration for all");
    assert_eq!(stsc, [1, 1, stsz[1], 1], "one chunk");
    assert_eq!(stco[0], 1);
    let mut at = stco[1] as usize;
    let annex_b = sample_sizes
        .iter()
        .enumerate()
        .map(|(n, &size)| {
            let mut out = Vec::new();
            if n == 0 {
                for set in [sps, pps] {
                    out.extend_from_slice(&[0, 0, 0, 1]);
                    out.extend_from_slice(set);
                }
            }
            let end = at + size as usize;
            while at < end {
                let len = u32_at(bytes, at) as usize;
                out.extend_from_slice(&[0, 0, 0, 1]);
                out.extend_from_slice(&bytes[at + 4..at + 4 + len]);
                at += 4 + len;
            }
            assert_eq!(at, end, "sample {n}'s NAL units fill it exactly");
            out
        })
        .collect();
    let mdat = top.iter().find(|(k, _)| k == "mdat").unwrap().1;
    let samples: u32 = sample_sizes.iter().sum();
    assert_eq!(
        mdat.len(),
        samples as usize,
        "mdat holds the samples and nothing else"
    );
    Track {
        timescale: u32_at(mdhd, 12),
        media_duration: u32_at(mdhd, 16),
        movie_ms: u32_at(mvhd, 16) * 1000 / u32_at(mvhd, 12),
        size,
        sample_sizes,
        key_frames: stss[1..].to_vec(),
        annex_b,
    }
}

/// Writes `frames` frames of `width × height` at `fps` through the built-in encoder.
fn write(path: &Path, frames: usize, (width, height): (usize, usize), fps: f64) {
    let mut options = VideoOptions::default();
    options.fps = fps;
    let mut sink = open_sink(path, &options).unwrap();
    for n in 0..frames {
        sink.push(&frame(n, width, height), width, height).unwrap();
    }
    assert_eq!(sink.frames(), frames);
    assert!(
        !path.exists(),
        "written under a temporary name until finished"
    );
    sink.finish().unwrap();
}

#[test]
fn built_in_mp4_has_every_frame_at_the_right_rate_and_decodes_back() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flight.mp4");
    // An odd size: padded to even for 4:2:0.
    write(&path, 12, (33, 25), 25.0);
    assert_eq!(listing(dir.path()), ["flight.mp4"]);
    let track = parse(&std::fs::read(&path).unwrap());
    assert_eq!(track.sample_sizes.len(), 12);
    assert_eq!((track.timescale, track.media_duration), (25_000, 12_000));
    assert_eq!(track.movie_ms, 480);
    assert_eq!(track.size, (34, 26));
    assert_eq!(track.key_frames[0], 1, "the first frame is a key frame");

    let mut decoder = Decoder::new().unwrap();
    for (n, sample) in track.annex_b.iter().enumerate() {
        let yuv = decoder
            .decode(sample)
            .unwrap()
            .expect("a picture per sample");
        assert_eq!(yuv.dimensions(), (34, 26));
        let mut rgb = vec![0; 34 * 26 * 3];
        yuv.write_rgb8(&mut rgb);
        // The red channel of pixel (20, 10) steps by 40 per frame.
        let red = i32::from(rgb[3 * (20 + 34 * 10)]);
        let want = (n * 40 % 256) as i32;
        assert!(
            (red - want).abs() <= 16,
            "frame {n}: red {red}, want {want}"
        );
    }
}

#[test]
fn built_in_mp4_keeps_fractional_frame_rates_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ntsc.mp4");
    write(&path, 60, (16, 16), 29.97);
    let track = parse(&std::fs::read(&path).unwrap());
    assert_eq!((track.timescale, track.media_duration), (29_970, 60_000));
    // A key frame at least every two seconds (more where the scene changes).
    assert_eq!(track.key_frames[0], 1);
    assert!(
        track.key_frames.windows(2).all(|w| w[1] - w[0] <= 60),
        "{:?}",
        track.key_frames
    );
    assert_eq!(track.movie_ms, 2002);
}

/// `ffprobe`'s reading of `path`: the JSON it prints.
fn ffprobe(path: &Path) -> Option<serde_json::Value> {
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args([
            "-show_entries",
            "stream=codec_name,pix_fmt,width,height,r_frame_rate,nb_read_frames",
        ])
        .args(["-show_entries", "format=duration", "-of", "json"])
        .arg(path)
        .output();
    match out {
        Ok(out) if out.status.success() => Some(serde_json::from_slice(&out.stdout).unwrap()),
        Ok(out) => panic!("ffprobe failed: {}", String::from_utf8_lossy(&out.stderr)),
        Err(e) => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "ffprobe is required under CI (apt package ffmpeg): {e}"
            );
            eprintln!("skipping: ffprobe is not on PATH ({e})");
            None
        }
    }
}

#[test]
fn ffprobe_reads_the_built_in_mp4_as_h264() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flight.mp4");
    write(&path, 30, (64, 48), 25.0);
    let Some(probe) = ffprobe(&path) else { return };
    let stream = &probe["streams"][0];
    assert_eq!(stream["codec_name"], "h264", "{probe}");
    assert_eq!(stream["pix_fmt"], "yuv420p", "{probe}");
    assert_eq!(
        (stream["width"].as_u64(), stream["height"].as_u64()),
        (Some(64), Some(48))
    );
    assert_eq!(stream["r_frame_rate"], "25/1", "{probe}");
    assert_eq!(stream["nb_read_frames"], "30", "{probe}");
    let duration: f64 = probe["format"]["duration"]
        .as_str()
        .unwrap()
        .parse()
        .unwrap();
    assert!((duration - 1.2).abs() < 1e-3, "{probe}");
}
