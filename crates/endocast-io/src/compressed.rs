//! The end of a compressed stream. A reader takes the voxels it needs from the inflated bytes;
//! the rest of the stream is then read to its very end, so that the decoder checks the
//! stream's checksum and length (gzip's CRC-32 and ISIZE, zlib's Adler-32, the final block of a
//! deflate stream) and a corrupt or truncated file is refused instead of loading with wrong
//! voxels. Inflated bytes beyond what the header describes are corruption too.

use crate::error::{ReadError, Result};
use std::io::{self, Read};
use std::path::Path;

/// Reads `reader` (a decompressor positioned after the voxels) to its end, where exactly
/// `expected_rest` more bytes must come (the other volumes of a 4-D image; usually 0).
/// `kind` names the compression in messages (`gzip`, `zlib`, `deflate`).
pub(crate) fn finish(
    path: &Path,
    reader: &mut dyn Read,
    kind: &str,
    expected_rest: u64,
) -> Result<()> {
    let mut rest = reader.take(expected_rest.saturating_add(1));
    // The last read returns 0 only once the decoder has checked the stream's trailer.
    let found = io::copy(&mut rest, &mut io::sink()).map_err(|e| corrupt(path, kind, e))?;
    if found > expected_rest {
        return Err(ReadError::format(
            path,
            format!(
                "the {kind} data are corrupt: they inflate to more bytes than the header \
                 describes (more than {expected_rest} after the voxels read)"
            ),
        ));
    }
    if found < expected_rest {
        return Err(ReadError::format(
            path,
            format!(
                "the {kind} data end early: {expected_rest} more bytes expected after the \
                 voxels read, the stream holds {found}"
            ),
        ));
    }
    Ok(())
}

/// The most one stored byte of a deflate stream (gzip, zlib, raw deflate) inflates to: 1032,
/// the format's best case (a long run of one byte).
const MAX_INFLATION: u64 = 1032;

/// Refuses `stored` bytes of `kind` data (`gzip`, `zlib`) that could not inflate to the `needed`
/// bytes a header describes, before anything that size is allocated.
pub(crate) fn check_inflates_to(path: &Path, kind: &str, stored: u64, needed: u64) -> Result<()> {
    let most = stored.saturating_mul(MAX_INFLATION);
    if needed > most {
        return Err(ReadError::format(
            path,
            format!(
                "the header describes {needed} bytes of samples, but the {stored} bytes of \
                 {kind} data inflate to at most {most}: the sizes or the file are wrong"
            ),
        ));
    }
    Ok(())
}

/// A decompressor's error: an operating-system failure stays an I/O error, anything else
/// (bad checksum, invalid code, a stream cut short) is a fault of the file.
pub(crate) fn corrupt(path: &Path, kind: &str, e: io::Error) -> ReadError {
    if e.raw_os_error().is_some() {
        ReadError::io(path, e)
    } else {
        ReadError::format(
            path,
            format!("the {kind} data are corrupt or truncated: {e}"),
        )
    }
}

/// [`corrupt`] for an error a sample reader already wrapped as [`ReadError::Io`].
pub(crate) fn io_as_corrupt(error: ReadError, kind: &str) -> ReadError {
    match error {
        ReadError::Io { path, cause } => corrupt(&path, kind, cause),
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::write::GzEncoder;
    use flate2::Compression;
    use std::io::Write;

    fn gzip(data: &[u8]) -> Vec<u8> {
        let mut gz = GzEncoder::new(Vec::new(), Compression::fast());
        gz.write_all(data).unwrap();
        gz.finish().unwrap()
    }

    fn finish_after(stream: &[u8], take: usize, rest: u64) -> Result<()> {
        let mut reader = flate2::read::MultiGzDecoder::new(stream);
        let mut voxels = vec![0u8; take];
        reader.read_exact(&mut voxels).unwrap();
        finish(Path::new("x.gz"), &mut reader, "gzip", rest)
    }

    #[test]
    fn checks_the_length_after_the_voxels() {
        let data: Vec<u8> = (0..1000u32).map(|i| (i * 7 % 251) as u8).collect();
        let stream = gzip(&data);
        finish_after(&stream, 1000, 0).unwrap();
        finish_after(&stream, 600, 400).unwrap();
        let longer = finish_after(&stream, 600, 0).unwrap_err().to_string();
        assert!(
            longer.contains("x.gz") && longer.contains("more bytes"),
            "{longer}"
        );
        let shorter = finish_after(&stream, 600, 500).unwrap_err().to_string();
        assert!(shorter.contains("end early"), "{shorter}");
    }

    #[test]
    fn a_bad_crc_is_refused() {
        let data = vec![5u8; 1000];
        let mut stream = gzip(&data);
        let crc_at = stream.len() - 8;
        stream[crc_at] ^= 1;
        let err = finish_after(&stream, 1000, 0).unwrap_err().to_string();
        assert!(err.contains("corrupt"), "{err}");
    }
}
