//! PNG and `.npy` image writers: the files decode back to the pixels written.

use endocast_io::{write_npy_f32, write_png_rgb8, write_png_rgba8};
use std::path::Path;
use std::process::Command;

/// Decodes a PNG with the `png` crate: (width, height, colour type, bytes).
fn decode_png(path: &Path) -> (u32, u32, png::ColorType, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    (info.width, info.height, info.color_type, buf)
}

/// A `width × height` test pattern with `channels` bytes per pixel, distinct per position.
fn pattern(width: u32, height: u32, channels: u32) -> Vec<u8> {
    (0..width * height * channels)
        .map(|i| (i * 7 % 251) as u8)
        .collect()
}

#[test]
fn png_rgb_and_rgba_decode_back() {
    let dir = tempfile::tempdir().unwrap();
    let rgb = pattern(5, 3, 3);
    let p = dir.path().join("rgb.png");
    write_png_rgb8(&p, 5, 3, &rgb).unwrap();
    assert_eq!(decode_png(&p), (5, 3, png::ColorType::Rgb, rgb));

    let rgba = pattern(2, 7, 4);
    let p = dir.path().join("rgba.png");
    write_png_rgba8(&p, 2, 7, &rgba).unwrap();
    assert_eq!(decode_png(&p), (2, 7, png::ColorType::Rgba, rgba));
}

#[test]
fn npy_layout_is_little_endian_rows_after_the_header() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("depth.npy");
    let values = [1.5f32, f32::NAN, -2.0, 0.25, 1e30, f32::INFINITY];
    write_npy_f32(&p, 3, 2, &values).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    let header_len = usize::from(u16::from_le_bytes([bytes[8], bytes[9]]));
    let data = &bytes[10 + header_len..];
    assert_eq!((10 + header_len) % 64, 0);
    assert_eq!(data.len(), 6 * 4);
    for (chunk, v) in data.chunks(4).zip(values) {
        let read = f32::from_le_bytes(chunk.try_into().unwrap());
        assert!(read == v || (read.is_nan() && v.is_nan()));
    }
}

/// A Python interpreter that has NumPy: the peers' venv or the system's, else `None`.
fn python_with_numpy() -> Option<&'static str> {
    ["/opt/peers-venv/bin/python", "python3"]
        .into_iter()
        .find(|py| {
            Command::new(py)
                .args(["-c", "import numpy"])
                .output()
                .is_ok_and(|o| o.status.success())
        })
}

#[test]
fn npy_loads_in_numpy() {
    let Some(python) = python_with_numpy() else {
        eprintln!("skipping: no python with numpy");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("depth.npy");
    let values: Vec<f32> = (0..12).map(|i| i as f32 * 0.5).chain([f32::NAN]).collect();
    write_npy_f32(&p, 13, 1, &values).unwrap();
    let q = dir.path().join("img.npy");
    write_npy_f32(&q, 4, 3, &values[..12]).unwrap();
    let script = "import numpy as n, sys\n\
                  a = n.load(sys.argv[1]); b = n.load(sys.argv[2]); n.save(sys.argv[3], b)\n\
                  print(a.dtype, a.shape, n.isnan(a[0, 12]), a[0, 3], b.shape, b[2, 1], b[1, 3])";
    let out = Command::new(python)
        .args(["-c", script])
        .arg(&p)
        .arg(&q)
        .arg(dir.path().join("numpy.npy"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Row 2, column 1 of the 4-wide image is sample 9 (4.5); row 1, column 3 is sample 7 (3.5).
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        "float32 (1, 13) True 1.5 (3, 4) 4.5 3.5"
    );
    // NumPy writing the same array produces the same bytes, header padding included.
    assert_eq!(
        std::fs::read(&q).unwrap(),
        std::fs::read(dir.path().join("numpy.npy")).unwrap()
    );
}
