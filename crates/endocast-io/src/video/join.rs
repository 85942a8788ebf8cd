//! The frames of a flight written in parts (`fly --frames`, one folder of PNGs a part) read
//! back in order, to be joined into one film by the same sinks a whole flight uses.

use super::frame_number;
use crate::error::{ReadError, Result};
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// The longest edge of a frame read back (a PNG header is checked before its pixels are).
const MAX_FRAME_EDGE: u32 = 16_384;

/// The frame files (`frame_NNNNN.png`) of `folders`, in frame order; an error unless they are
/// the frames 0, 1, 2, … each once (a part missing, or two parts overlapping), or when there
/// are none.
pub fn frame_files(folders: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut numbered = Vec::new();
    for folder in folders {
        let entries = std::fs::read_dir(folder).map_err(|e| ReadError::io(folder, e))?;
        for entry in entries {
            let entry = entry.map_err(|e| ReadError::io(folder, e))?;
            let name = entry.file_name();
            if let Some(number) = name.to_str().and_then(frame_number) {
                numbered.push((number, entry.path()));
            }
        }
    }
    numbered.sort();
    let Some(first) = folders.first() else {
        return Err(ReadError::format(
            Path::new("."),
            "no folder of frames given",
        ));
    };
    if numbered.is_empty() {
        return Err(ReadError::format(
            first,
            "no frame_NNNNN.png in the folders",
        ));
    }
    for (expected, (number, path)) in numbered.iter().enumerate() {
        if *number != expected {
            let what = if *number < expected {
                "twice"
            } else {
                "missing"
            };
            let message = format!(
                "frame {} is {what} (the frames must be 0, 1, 2, … once each)",
                expected.min(*number)
            );
            return Err(ReadError::inconsistent(path, message));
        }
    }
    Ok(numbered.into_iter().map(|(_, path)| path).collect())
}

/// A frame as `fly` writes it: an 8-bit RGB PNG; its width, height and pixels.
pub fn read_frame(path: &Path) -> Result<(usize, usize, Vec<u8>)> {
    let file = std::fs::File::open(path).map_err(|e| ReadError::io(path, e))?;
    let bad = |e: png::DecodingError| ReadError::format(path, format!("not a readable PNG: {e}"));
    let mut reader = png::Decoder::new(BufReader::new(file))
        .read_info()
        .map_err(bad)?;
    let info = reader.info();
    let (width, height) = (info.width, info.height);
    if width > MAX_FRAME_EDGE || height > MAX_FRAME_EDGE {
        let message = format!("a {width}×{height} frame: edges must be at most {MAX_FRAME_EDGE}");
        return Err(ReadError::format(path, message));
    }
    if (info.color_type, info.bit_depth) != (png::ColorType::Rgb, png::BitDepth::Eight) {
        return Err(ReadError::format(
            path,
            "not a frame of `endocast fly` (an 8-bit RGB PNG)",
        ));
    }
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| ReadError::format(path, "a PNG too large to decode"))?;
    let mut rgb = vec![0; size];
    let frame = reader.next_frame(&mut rgb).map_err(bad)?;
    rgb.truncate(frame.buffer_size());
    Ok((width as usize, height as usize, rgb))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn touch(dir: &Path, names: &[&str]) {
        for name in names {
            std::fs::write(dir.join(name), b"").unwrap();
        }
    }

    #[test]
    fn parts_join_in_frame_order_only_when_each_frame_is_there_once() {
        let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        touch(
            a.path(),
            &["frame_00002.png", "frame_00000.png", "notes.txt"],
        );
        touch(b.path(), &["frame_00001.png", "frame_00003.png"]);
        let folders = [b.path().to_path_buf(), a.path().to_path_buf()];
        let files = frame_files(&folders).unwrap();
        let names: Vec<_> = files.iter().map(|f| f.file_name().unwrap()).collect();
        assert_eq!(
            names,
            [
                "frame_00000.png",
                "frame_00001.png",
                "frame_00002.png",
                "frame_00003.png"
            ]
        );
        touch(b.path(), &["frame_00005.png"]);
        let said = frame_files(&folders).unwrap_err().to_string();
        assert!(said.contains("frame 4 is missing"), "{said}");
        let said = frame_files(&[a.path().to_path_buf(), a.path().to_path_buf()])
            .unwrap_err()
            .to_string();
        assert!(said.contains("frame 0 is twice"), "{said}");
        assert!(frame_files(&[]).is_err());
    }
}
