//! The values of one field of a Siemens CSA header (the private element (0029,1010) of a
//! Siemens image), in its second format ("SV10"), as nibabel's `csareader` reads it.
//!
//! Layout (little endian): `SV10`, 4 unused bytes, the tag count, 4 unused bytes; then per tag
//! its name (64 bytes, NUL-terminated), VM, VR (4 bytes), SyngoDT, the item count and 4 unused
//! bytes; then per item four 32-bit lengths (the second is the item's) and the item's bytes,
//! padded to 4. Every length is checked against the bytes there are: a damaged header gives
//! `None`, never a read past its end.

/// The items of field `name` (their text up to the first NUL, trimmed), or `None` when the
/// header is not CSA2, is damaged before the field, or lacks it.
pub(super) fn field(bytes: &[u8], name: &str) -> Option<Vec<String>> {
    let mut reader = Reader { bytes, at: 0 };
    if reader.take(4)? != b"SV10" {
        return None;
    }
    reader.take(4)?;
    let tags = reader.u32()?;
    reader.take(4)?;
    for _ in 0..tags {
        let tag_name = text(reader.take(64)?);
        reader.take(4 + 4 + 4)?; // VM, VR, SyngoDT
        let items = reader.u32()?;
        reader.take(4)?;
        let mut values = Vec::new();
        for _ in 0..items {
            let lengths = reader.take(16)?;
            let length = u32::from_le_bytes(lengths[4..8].try_into().ok()?);
            let length = usize::try_from(length).ok()?;
            let value = reader.take(length)?;
            reader.take((4 - length % 4) % 4)?;
            if length > 0 {
                values.push(text(value));
            }
        }
        if tag_name == name {
            return Some(values);
        }
    }
    None
}

/// A cursor over the header's bytes whose every read is bounded by them.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    /// The next `count` bytes, or `None` past the end.
    fn take(&mut self, count: usize) -> Option<&'a [u8]> {
        let end = self.at.checked_add(count)?;
        let taken = self.bytes.get(self.at..end)?;
        self.at = end;
        Some(taken)
    }

    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
}

/// The text of `bytes` up to the first NUL, without surrounding spaces.
fn text(bytes: &[u8]) -> String {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).trim().to_string()
}

#[cfg(test)]
mod tests {
    use super::field;

    /// A CSA2 header of `(name, items)` tags.
    fn header(tags: &[(&str, &[&str])]) -> Vec<u8> {
        let mut out = b"SV10\x04\x03\x02\x01".to_vec();
        out.extend((tags.len() as u32).to_le_bytes());
        out.extend(77u32.to_le_bytes());
        for (name, items) in tags {
            let mut padded = name.as_bytes().to_vec();
            padded.resize(64, 0);
            out.extend(padded);
            out.extend(1i32.to_le_bytes());
            out.extend(b"IS\0\0");
            out.extend(6i32.to_le_bytes());
            out.extend((items.len() as u32).to_le_bytes());
            out.extend(77u32.to_le_bytes());
            for item in *items {
                let mut value = item.as_bytes().to_vec();
                value.push(0);
                let length = value.len() as u32;
                for word in [length, length, 77, length] {
                    out.extend(word.to_le_bytes());
                }
                value.resize(value.len().next_multiple_of(4), 0);
                out.extend(value);
            }
        }
        out
    }

    #[test]
    fn finds_a_field_after_others() {
        let bytes = header(&[
            ("EchoLinePosition", &["32"]),
            ("SliceNormalVector", &["0.0", "0.1", "0.99"]),
            ("NumberOfImagesInMosaic", &["35"]),
        ]);
        assert_eq!(field(&bytes, "NumberOfImagesInMosaic").unwrap(), ["35"]);
        assert_eq!(
            field(&bytes, "SliceNormalVector").unwrap(),
            ["0.0", "0.1", "0.99"]
        );
        assert_eq!(field(&bytes, "Missing"), None);
    }

    #[test]
    fn damaged_headers_give_nothing() {
        let bytes = header(&[("NumberOfImagesInMosaic", &["35"])]);
        for cut in 0..bytes.len() - 4 {
            assert_eq!(
                field(&bytes[..cut], "NumberOfImagesInMosaic"),
                None,
                "{cut}"
            );
        }
        let mut lying = bytes.clone();
        // The item's length (the second of its four) beyond the header.
        let at = 16 + 64 + 16 + 4 + 4;
        lying[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(field(&lying, "NumberOfImagesInMosaic"), None);
        assert_eq!(field(b"SV09\0\0\0\0", "NumberOfImagesInMosaic"), None);
    }
}
