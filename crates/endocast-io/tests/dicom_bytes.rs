//! DICOM files built byte by byte for the reader tests (explicit VR little endian unless said
//! otherwise; a one-slice CT whose elements a test can replace), and what a test checks of a
//! read: the file named in a refusal, a warning given.

use endocast_io::{dicom, Loaded, OpenOptions, ReadError};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub(crate) const EXPLICIT_LE: &str = "1.2.840.10008.1.2.1";

/// Writes `bytes` as `name` in a fresh folder.
pub(crate) fn file_with(name: &str, bytes: &[u8]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

/// The error of a read that must fail, checked to name the file and to contain each of `words`.
pub(crate) fn refused(result: Result<Loaded, ReadError>, path: &Path, words: &[&str]) -> String {
    let error = match result {
        Ok(_) => panic!("{} was read", path.display()),
        Err(e) => e.to_string(),
    };
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(error.contains(name), "{error}");
    for word in words {
        assert!(error.contains(word), "{error:?} does not say {word:?}");
    }
    error
}

pub(crate) fn has_warning(loaded: &Loaded, words: &str) -> bool {
    loaded.warnings.iter().any(|w| w.contains(words))
}

// ---------------------------------------------------------------------------------------------
// DICOM files byte by byte (explicit VR little endian unless said otherwise).

/// Value representations with a 2-byte reserved field and a 4-byte length.
pub(crate) fn is_long(vr: &[u8; 2]) -> bool {
    [b"OB", b"OW", b"SQ", b"UN", b"UT"].contains(&vr)
}

/// One explicit-VR little-endian element; an odd value is padded (NUL for UIDs and bytes).
pub(crate) fn element(tag: (u16, u16), vr: &[u8; 2], value: &[u8]) -> Vec<u8> {
    let mut value = value.to_vec();
    if value.len() % 2 == 1 {
        value.push(if matches!(vr, b"UI" | b"OB" | b"UN") {
            0
        } else {
            b' '
        });
    }
    let mut out = header(tag, vr, value.len() as u32);
    out.extend_from_slice(&value);
    out
}

/// An explicit-VR element header declaring `length` bytes.
pub(crate) fn header(tag: (u16, u16), vr: &[u8; 2], length: u32) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&tag.0.to_le_bytes());
    out.extend_from_slice(&tag.1.to_le_bytes());
    out.extend_from_slice(vr);
    if is_long(vr) {
        out.extend_from_slice(&[0, 0]);
        out.extend_from_slice(&length.to_le_bytes());
    } else {
        out.extend_from_slice(&(length as u16).to_le_bytes());
    }
    out
}

/// An item or delimiter tag (group FFFE) with its 4-byte length.
pub(crate) fn item(element: u16, length: u32) -> Vec<u8> {
    let mut out = vec![0xFE, 0xFF];
    out.extend_from_slice(&element.to_le_bytes());
    out.extend_from_slice(&length.to_le_bytes());
    out
}

/// Preamble, magic and a meta group naming `transfer_syntax`.
pub(crate) fn meta(transfer_syntax: &str) -> Vec<u8> {
    let mut group = element((2, 1), b"OB", &[0, 1]);
    group.extend(element((2, 2), b"UI", b"1.2.840.10008.5.1.4.1.1.2"));
    group.extend(element((2, 3), b"UI", b"1.2.3.4.1"));
    group.extend(element((2, 0x10), b"UI", transfer_syntax.as_bytes()));
    let mut out = vec![0u8; 128];
    out.extend_from_slice(b"DICM");
    out.extend(element((2, 0), b"UL", &(group.len() as u32).to_le_bytes()));
    out.extend(group);
    out
}

/// A one-slice CT image as a map of its encoded elements, so that tests can replace any.
pub(crate) struct Image(pub(crate) BTreeMap<(u16, u16), Vec<u8>>);

impl Image {
    /// Rows × columns of 16-bit samples (12 stored), placed, spaced, rescaled to HU.
    pub(crate) fn ct(rows: u16, columns: u16) -> Self {
        let pixels: Vec<u8> = (0..u32::from(rows) * u32::from(columns))
            .flat_map(|i| (i as u16 * 37 % 4000).to_le_bytes())
            .collect();
        let mut image = Self(BTreeMap::new());
        image
            .text((8, 0x16), b"UI", "1.2.840.10008.5.1.4.1.1.2")
            .text((8, 0x18), b"UI", "1.2.3.4.1")
            .text((8, 0x60), b"CS", "CT")
            .text((0x20, 0xE), b"UI", "1.2.3.4.5")
            .text((0x20, 0x32), b"DS", "0\\0\\0")
            .text((0x20, 0x37), b"DS", "1\\0\\0\\0\\1\\0")
            .short((0x28, 2), 1)
            .text((0x28, 4), b"CS", "MONOCHROME2")
            .short((0x28, 0x10), rows)
            .short((0x28, 0x11), columns)
            .text((0x28, 0x30), b"DS", "0.5\\0.5")
            .short((0x28, 0x100), 16)
            .short((0x28, 0x101), 12)
            .short((0x28, 0x102), 11)
            .short((0x28, 0x103), 0)
            .text((0x28, 0x1052), b"DS", "-1024")
            .text((0x28, 0x1053), b"DS", "1")
            .set((0x7FE0, 0x10), element((0x7FE0, 0x10), b"OW", &pixels));
        image
    }

    pub(crate) fn set(&mut self, tag: (u16, u16), encoded: Vec<u8>) -> &mut Self {
        self.0.insert(tag, encoded);
        self
    }

    pub(crate) fn text(&mut self, tag: (u16, u16), vr: &[u8; 2], value: &str) -> &mut Self {
        self.set(tag, element(tag, vr, value.as_bytes()))
    }

    pub(crate) fn short(&mut self, tag: (u16, u16), value: u16) -> &mut Self {
        self.set(tag, element(tag, b"US", &value.to_le_bytes()))
    }

    /// Encapsulated pixel data: an empty offset table, then one fragment per frame.
    pub(crate) fn fragments(&mut self, frames: &[Vec<u8>]) -> &mut Self {
        let mut encoded = header((0x7FE0, 0x10), b"OB", u32::MAX);
        encoded.extend(item(0xE000, 0));
        for frame in frames {
            let mut frame = frame.clone();
            frame.resize(frame.len().next_multiple_of(2), 0);
            encoded.extend(item(0xE000, frame.len() as u32));
            encoded.extend(frame);
        }
        encoded.extend(item(0xE0DD, 0));
        self.set((0x7FE0, 0x10), encoded)
    }

    /// The elements after the meta group.
    pub(crate) fn data_set(&self) -> Vec<u8> {
        self.0.values().flatten().copied().collect()
    }

    /// The file, in `transfer_syntax` (whose pixel data the test has set).
    pub(crate) fn bytes(&self, transfer_syntax: &str) -> Vec<u8> {
        let mut out = meta(transfer_syntax);
        out.extend(self.data_set());
        out
    }
}

pub(crate) fn read_dicom(path: &Path) -> Result<Loaded, ReadError> {
    dicom::read(path, &OpenOptions::default())
}

/// 16-bit little-endian words as bytes.
pub(crate) fn words(values: &[u16]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A sequence of one defined-length item holding the encoded `elements`, stored as `vr`.
pub(crate) fn sequence(tag: (u16, u16), vr: &[u8; 2], elements: &[u8]) -> Vec<u8> {
    let mut value = item(0xE000, elements.len() as u32);
    value.extend_from_slice(elements);
    let mut out = header(tag, vr, value.len() as u32);
    out.extend(value);
    out
}

/// One implicit-VR little-endian element (tag, 4-byte length, value).
pub(crate) fn implicit(tag: (u16, u16), value: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&tag.0.to_le_bytes());
    out.extend_from_slice(&tag.1.to_le_bytes());
    out.extend_from_slice(&(value.len() as u32).to_le_bytes());
    out.extend_from_slice(value);
    out
}
