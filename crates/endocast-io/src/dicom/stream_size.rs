//! The image size that a JPEG or JPEG 2000 stream declares in its own header, to compare with
//! Rows and Columns before decoding: dicom-rs 0.10 sizes the frame from Rows × Columns and
//! copies in what the decoder gives, so a stream smaller than the header says would leave the
//! rest of the frame zero (−1024 HU in a CT: fake air).

/// `(columns, rows)` from the start of frame (SOF) of a JPEG stream or the SIZ segment of a
/// JPEG 2000 codestream (bare, or inside a JP2 file); `None` when `data` is neither or the
/// size is not in the header (a JPEG height of 0, given later by a DNL marker).
pub(super) fn declared_size(data: &[u8]) -> Option<(u32, u32)> {
    if data.starts_with(&[0xFF, 0xD8]) {
        return jpeg_size(data);
    }
    // A JPEG 2000 codestream starts with SOC then SIZ; a JP2 file holds one in its jp2c box.
    const SOC_SIZ: [u8; 4] = [0xFF, 0x4F, 0xFF, 0x51];
    let start = data.windows(4).take(4096).position(|w| w == SOC_SIZ)?;
    jpeg_2000_size(&data[start..])
}

fn be16(data: &[u8], at: usize) -> Option<u32> {
    let b = data.get(at..at + 2)?;
    Some(u32::from(u16::from_be_bytes([b[0], b[1]])))
}

fn be32(data: &[u8], at: usize) -> Option<u32> {
    let b = data.get(at..at + 4)?;
    Some(u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
}

/// The size in the first SOF marker segment, walking the segments before it.
fn jpeg_size(data: &[u8]) -> Option<(u32, u32)> {
    let mut at = 2;
    loop {
        // Fill bytes (0xFF) may precede a marker.
        while data.get(at + 1) == Some(&0xFF) {
            at += 1;
        }
        if *data.get(at)? != 0xFF {
            return None;
        }
        let marker = *data.get(at + 1)?;
        match marker {
            // SOF0–SOF15, except DHT (C4), JPG (C8) and DAC (CC).
            0xC0..=0xCF if !matches!(marker, 0xC4 | 0xC8 | 0xCC) => {
                let (rows, columns) = (be16(data, at + 5)?, be16(data, at + 7)?);
                return (rows > 0).then_some((columns, rows));
            }
            // Start of scan before any frame header: not a stream we can size.
            0xDA => return None,
            // Markers without a length: TEM, RSTn, SOI.
            0x01 | 0xD0..=0xD8 => at += 2,
            _ => at += 2 + be16(data, at + 2)? as usize,
        }
    }
}

/// The size in a SIZ segment (`data` starts at SOC): reference grid minus image offset.
fn jpeg_2000_size(data: &[u8]) -> Option<(u32, u32)> {
    let (width, height) = (be32(data, 8)?, be32(data, 12)?);
    let (x0, y0) = (be32(data, 16)?, be32(data, 20)?);
    Some((width.checked_sub(x0)?, height.checked_sub(y0)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_size_of_jpeg_and_jpeg_2000_headers() {
        // SOI, an APP0 segment of 4 bytes, SOF3 (lossless) of 300 rows × 200 columns.
        let jpeg = [
            0xFF, 0xD8, 0xFF, 0xE0, 0, 4, 1, 2, 0xFF, 0xC3, 0, 11, 16, 0x01, 0x2C, 0, 200, 1,
        ];
        assert_eq!(declared_size(&jpeg), Some((200, 300)));
        // SOC, SIZ: Lsiz, Rsiz, Xsiz 512, Ysiz 400, XOsiz 12, YOsiz 0.
        let mut j2k = vec![0xFF, 0x4F, 0xFF, 0x51, 0, 41, 0, 0];
        for v in [512u32, 400, 12, 0] {
            j2k.extend_from_slice(&v.to_be_bytes());
        }
        assert_eq!(declared_size(&j2k), Some((500, 400)));
        assert_eq!(declared_size(b"not an image"), None);
        assert_eq!(declared_size(&jpeg[..10]), None);
    }
}
