//! Running the binary and finding the shared data.

use std::process::{Command, Output};

/// Runs `endocast` with `args`.
pub fn endocast(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_endocast"))
        .args(args)
        .output()
        .expect("the endocast binary runs")
}

/// Runs `endocast` with `args` and asserts that it fails cleanly: a non-zero exit, no panic, and
/// `needle` in the error output.
pub fn fails_with(args: &[&str], needle: &str) {
    let out = endocast(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
    assert!(
        stderr.contains(needle),
        "{args:?}: {stderr:?} lacks {needle:?}"
    );
}

/// Runs `endocast info --json PATH [extra]` and parses the report; panics with stderr on failure.
pub fn info_json(path: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["info", "--json", path];
    args.extend_from_slice(extra);
    let out = endocast(&args);
    assert!(
        out.status.success(),
        "endocast info {path} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("info --json prints JSON")
}

/// The numbers of a JSON array.
pub fn numbers(value: &serde_json::Value) -> Vec<f64> {
    value
        .as_array()
        .expect("an array")
        .iter()
        .map(|v| v.as_f64().expect("a number"))
        .collect()
}

/// Reads a little-endian float32 .npy written by `--depth-out`: (shape, values).
pub fn read_npy(path: &std::path::Path) -> ((usize, usize), Vec<f32>) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(header.contains("'descr': '<f4'"), "{header}");
    let shape = header.split("'shape': (").nth(1).unwrap();
    let dims: Vec<usize> = shape
        .split(')')
        .next()
        .unwrap()
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let values = bytes[10 + header_len..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    ((dims[0], dims[1]), values)
}

/// The share of the pixels of a `--depth-out` image whose ray met the wall.
pub fn hit_share(depth: &std::path::Path) -> f64 {
    let (_, values) = read_npy(depth);
    let hits = values.iter().filter(|d| d.is_finite()).count();
    hits as f64 / values.len() as f64
}

/// The width and height of a PNG and its pixels as RGB rows.
pub fn read_png_rgb(path: &std::path::Path) -> ([usize; 2], Vec<u8>) {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut reader = png::Decoder::new(file).read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "{}", path.display());
    pixels.truncate(info.buffer_size());
    ([info.width as usize, info.height as usize], pixels)
}

/// Pixels of `rgb` in a PNG.
pub fn count_color(png: &std::path::Path, rgb: [u8; 3]) -> usize {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    let channels = info.line_size / info.width as usize;
    pixels[..info.buffer_size()]
        .chunks(channels)
        .filter(|p| p[..3] == rgb)
        .count()
}
