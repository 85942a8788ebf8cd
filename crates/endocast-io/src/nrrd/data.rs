//! Reading the samples a NRRD header describes, wherever they are: after the header, in one
//! detached file, or spread over many files (a `LIST` or a `%d` pattern), raw, gzip, ascii or
//! hex.
//!
//! Every file becomes one segment of a single stream that [`read_voxels`] consumes, so samples
//! go straight from disk (through the decompressor) into the voxel buffer, and a volume split
//! over files is converted exactly as one in a single file.

use super::fields::{ByteSkip, DataFiles, Encoding};
use super::header::Header;
use crate::compressed;
use crate::detached;
use crate::error::{ReadError, Result};
use crate::limits::Limits;
use crate::loaded::OpenOptions;
use crate::samples::{read_voxels, ElementType, Endian, Rescale};
use endocast_core::ValueMap;
use flate2::read::MultiGzDecoder;
use std::fs::File;
use std::io::{self, BufRead, BufReader, ErrorKind, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Most surplus bytes counted after a segment's samples: enough to warn, never a read to the
/// end of a huge file.
const SURPLUS_PROBE: u64 = 1 << 20;

/// One file's share of the samples.
#[derive(Debug)]
struct Segment {
    path: PathBuf,
    /// Where the encoded data start in the file (the header's length for attached data),
    /// before `line skip` and `byte skip`.
    offset: u64,
    /// Decoded bytes of samples this file must deliver.
    bytes: u64,
}

/// Reads the `count` samples of the volume whose header is at `header_path`.
pub(super) fn read_samples(
    header_path: &Path,
    header: &Header,
    count: usize,
    endian: Endian,
    options: &OpenOptions,
    warnings: &mut Vec<String>,
) -> Result<(Vec<u16>, ValueMap)> {
    let segments = segments(header_path, header, count, &options.limits)?;
    for segment in &segments {
        // Name a missing, misplaced or short slice before allocating or reading anything.
        let len =
            detached::data_file_len_where(header_path, &segment.path, options.allow_outside_data)?;
        check_holds(segment, header, len)?;
    }
    let mut chain = Chain {
        segments: &segments,
        header,
        next: 0,
        current: None,
        failure: None,
        surplus: Vec::new(),
    };
    let result = read_voxels(
        header_path,
        &mut chain,
        header.element,
        endian,
        count,
        Rescale::IDENTITY,
        warnings,
    )
    .and_then(|voxels| {
        // One more read finishes the last segment: a gzip stream is checked to its end.
        chain
            .read(&mut [0u8; 1])
            .map(|_| voxels)
            .map_err(|e| ReadError::format(header_path, e.to_string()))
    });
    match (result, chain.failure) {
        // The chain knows which file failed and why; read_voxels only saw an I/O error.
        (Err(_), Some(failure)) => Err(failure),
        (result, _) => {
            for (path, bytes) in chain.surplus {
                let at_least = if bytes == SURPLUS_PROBE {
                    "at least "
                } else {
                    ""
                };
                warnings.push(format!(
                    "{}: {at_least}{bytes} bytes of data beyond the samples that sizes {:?} \
                     describe were ignored",
                    path.display(),
                    header.sizes
                ));
            }
            result
        }
    }
}

/// The files holding the samples, each with its share, checked against `sizes`.
fn segments(
    header_path: &Path,
    header: &Header,
    count: usize,
    limits: &Limits,
) -> Result<Vec<Segment>> {
    let sample_bytes = header.element.size() as u64;
    let total_bytes = (count as u64).saturating_mul(sample_bytes);
    let folder = header_path.parent().unwrap_or(Path::new(""));
    let (names, subdim) = match &header.data {
        DataFiles::Attached => {
            return Ok(vec![Segment {
                path: header_path.to_path_buf(),
                offset: header.header_bytes,
                bytes: total_bytes,
            }])
        }
        DataFiles::Single(name) => {
            return Ok(vec![Segment {
                path: folder.join(name),
                offset: 0,
                bytes: total_bytes,
            }])
        }
        DataFiles::Many { names, subdim } => (names, subdim.unwrap_or(header.dimension - 1)),
    };
    limits.check_slices(header_path, names.len() as u64)?;
    // Each file holds a slab spanning the first `subdim` axes; the file count covers the rest.
    let per_file: u64 = header.sizes[..subdim].iter().product();
    let expected_files = count as u64 / per_file;
    if names.len() as u64 != expected_files {
        return Err(ReadError::inconsistent(
            header_path,
            format!(
                "sizes {:?} with {subdim}-D slabs of {per_file} samples need {expected_files} \
                 data files, the header names {}",
                header.sizes,
                names.len()
            ),
        ));
    }
    Ok(names
        .iter()
        .map(|name| Segment {
            path: folder.join(name),
            offset: 0,
            bytes: per_file * sample_bytes,
        })
        .collect())
}

/// Refuses a file too small to hold its segment's samples in the header's encoding, before
/// the voxels are allocated: `len` is the file's length. A line skip only adds to what is
/// needed, so this lower bound never refuses a valid file.
fn check_holds(segment: &Segment, header: &Header, len: u64) -> Result<()> {
    let stored = len.saturating_sub(segment.offset);
    let skip = match header.byte_skip {
        ByteSkip::Bytes(n) => n,
        ByteSkip::ToEnd => 0,
    };
    let needed = segment.bytes.saturating_add(skip);
    let holds = match header.encoding {
        Encoding::Raw => needed <= stored,
        Encoding::Gzip => {
            return compressed::check_inflates_to(&segment.path, "gzip", stored, needed)
        }
        // At least one digit a sample; two hex digits a byte.
        Encoding::Ascii => segment.bytes / header.element.size() as u64 <= stored,
        Encoding::Hex => needed <= stored / 2,
    };
    if holds {
        return Ok(());
    }
    Err(ReadError::format(
        &segment.path,
        format!(
            "the header's sizes {:?} need {needed} bytes of samples here, but the file holds \
             only {stored} bytes of {} data: the sizes or the file are wrong",
            header.sizes,
            header.encoding.name()
        ),
    ))
}

/// The segments' decoded bytes, one after the other, as one stream.
struct Chain<'a> {
    segments: &'a [Segment],
    header: &'a Header,
    next: usize,
    /// The open segment's reader and the bytes it has delivered so far.
    current: Option<(Box<dyn Read>, u64)>,
    /// Why the stream stopped, naming the segment's file.
    failure: Option<ReadError>,
    /// Files holding more (uncompressed) data than their share of the samples, and how much.
    surplus: Vec<(PathBuf, u64)>,
}

impl Chain<'_> {
    fn fail(&mut self, error: ReadError) -> io::Error {
        let message = error.to_string();
        self.failure = Some(error);
        io::Error::other(message)
    }
}

impl Read for Chain<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let segments = self.segments;
        if buf.is_empty() {
            return Ok(0);
        }
        loop {
            let Some(segment) = segments.get(self.next) else {
                return Ok(0);
            };
            let (reader, delivered) = match &mut self.current {
                Some(current) => current,
                None => match open_segment(segment, self.header) {
                    Ok(reader) => self.current.insert((reader, 0)),
                    Err(e) => return Err(self.fail(segment_error(segment, e))),
                },
            };
            let remaining = segment.bytes - *delivered;
            if remaining == 0 {
                match finish_segment(segment, self.header.encoding, reader.as_mut()) {
                    Ok(0) => {}
                    Ok(surplus) => self.surplus.push((segment.path.clone(), surplus)),
                    Err(e) => return Err(self.fail(e)),
                }
                self.current = None;
                self.next += 1;
                continue;
            }
            let wanted = buf
                .len()
                .min(usize::try_from(remaining).unwrap_or(usize::MAX));
            match reader.read(&mut buf[..wanted]) {
                Ok(0) => {
                    let message = format!(
                        "the {} data end early: expected {} bytes of samples, found {delivered}",
                        self.header.encoding.name(),
                        segment.bytes
                    );
                    return Err(self.fail(ReadError::format(&segment.path, message)));
                }
                Ok(n) => {
                    *delivered += n as u64;
                    return Ok(n);
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(self.fail(segment_error(segment, e))),
            }
        }
    }
}

/// Reads what a segment holds after its share of the samples: a gzip stream must end there
/// (its CRC and length checked; more inflated data is corruption), other encodings may carry
/// surplus bytes, whose count (up to [`SURPLUS_PROBE`]) is returned (to be warned about).
fn finish_segment(segment: &Segment, encoding: Encoding, reader: &mut dyn Read) -> Result<u64> {
    if encoding == Encoding::Gzip {
        compressed::finish(&segment.path, reader, "gzip", 0)?;
        return Ok(0);
    }
    io::copy(&mut reader.take(SURPLUS_PROBE), &mut io::sink())
        .map_err(|e| segment_error(segment, e))
}

/// Operating-system errors stay I/O errors; anything else (a short file, a corrupt gzip
/// stream) is a format error about that file.
fn segment_error(segment: &Segment, e: io::Error) -> ReadError {
    if e.raw_os_error().is_some() {
        ReadError::io(&segment.path, e)
    } else {
        ReadError::format(&segment.path, format!("cannot read the samples: {e}"))
    }
}

/// Opens a segment positioned on its first sample, decoding as the header says (the chain
/// stops reading after the segment's bytes).
fn open_segment(segment: &Segment, header: &Header) -> io::Result<Box<dyn Read>> {
    let mut file = File::open(&segment.path)?;
    if header.byte_skip == ByteSkip::ToEnd {
        // Raw data as the last bytes of the file (the header parser allows -1 only with raw).
        let len = file.metadata()?.len();
        let start = len
            .checked_sub(segment.bytes)
            .filter(|&start| start >= segment.offset)
            .ok_or_else(|| {
                io::Error::new(
                    ErrorKind::UnexpectedEof,
                    format!(
                        "{len} bytes cannot end with {} bytes of samples",
                        segment.bytes
                    ),
                )
            })?;
        file.seek(SeekFrom::Start(start))?;
        return Ok(Box::new(BufReader::new(file)));
    }
    file.seek(SeekFrom::Start(segment.offset))?;
    let mut reader = BufReader::new(file);
    skip_lines(&mut reader, header.line_skip)?;
    let mut decoded: Box<dyn Read> = match header.encoding {
        Encoding::Raw => Box::new(reader),
        Encoding::Gzip => Box::new(MultiGzDecoder::new(reader)),
        Encoding::Ascii | Encoding::Hex => Box::new(io::Cursor::new(decode_text(
            reader,
            header.encoding,
            header.element,
            segment.bytes,
        )?)),
    };
    // The spec applies the line skip to the file and the byte skip to the decoded data.
    if let ByteSkip::Bytes(skip) = header.byte_skip {
        let skipped = io::copy(&mut (&mut decoded).take(skip), &mut io::sink())?;
        if skipped < skip {
            return Err(io::Error::new(
                ErrorKind::UnexpectedEof,
                format!("byte skip {skip} passes the end of the data ({skipped} bytes)"),
            ));
        }
    }
    Ok(decoded)
}

/// Decodes a text encoding into the bytes of `bytes` bytes of samples (plus whatever a byte
/// skip needs): hex digits into the bytes they spell, in the file's byte order; ascii numbers
/// into little-endian samples of `element` (the caller reads ascii data as little-endian).
fn decode_text(
    reader: impl Read,
    encoding: Encoding,
    element: ElementType,
    bytes: u64,
) -> io::Result<Vec<u8>> {
    // No number needs 64 characters per byte; the bound stops a runaway file, not real data.
    let limit = bytes.saturating_mul(64).saturating_add(1 << 20);
    let mut text = Vec::new();
    reader.take(limit).read_to_end(&mut text)?;
    let mut out = Vec::new();
    if encoding == Encoding::Hex {
        let digits: Vec<u8> = text
            .iter()
            .copied()
            .filter(|b| !b.is_ascii_whitespace())
            .collect();
        for pair in digits.chunks(2) {
            let byte = std::str::from_utf8(pair)
                .ok()
                .filter(|p| p.len() == 2)
                .and_then(|p| u8::from_str_radix(p, 16).ok());
            out.push(byte.ok_or_else(|| {
                let found = String::from_utf8_lossy(pair);
                io::Error::new(
                    ErrorKind::InvalidData,
                    format!("{found:?} is not a pair of hex digits"),
                )
            })?);
        }
        return Ok(out);
    }
    let tokens = text
        .split(|b| b.is_ascii_whitespace() || *b == b',')
        .filter(|t| !t.is_empty());
    for token in tokens {
        push_ascii_sample(token, element, &mut out)?;
    }
    Ok(out)
}

/// Appends the little-endian bytes of one ascii sample.
fn push_ascii_sample(token: &[u8], element: ElementType, out: &mut Vec<u8>) -> io::Result<()> {
    let text = String::from_utf8_lossy(token);
    let bad = || {
        io::Error::new(
            ErrorKind::InvalidData,
            format!("{text:?} is not a {} value", element.name()),
        )
    };
    macro_rules! push {
        ($t:ty) => {
            out.extend_from_slice(&text.parse::<$t>().map_err(|_| bad())?.to_le_bytes())
        };
    }
    match element {
        ElementType::U8 => push!(u8),
        ElementType::I8 => push!(i8),
        ElementType::U16 => push!(u16),
        ElementType::I16 => push!(i16),
        ElementType::U32 => push!(u32),
        ElementType::I32 => push!(i32),
        ElementType::U64 => push!(u64),
        ElementType::I64 => push!(i64),
        ElementType::F32 => push!(f32),
        ElementType::F64 => push!(f64),
    }
    Ok(())
}

/// Skips `lines` newline-terminated lines without holding them in memory.
fn skip_lines(reader: &mut impl BufRead, lines: u64) -> io::Result<()> {
    for skipped in 0..lines {
        let mut found = false;
        while !found {
            let buf = reader.fill_buf()?;
            if buf.is_empty() {
                return Err(io::Error::new(
                    ErrorKind::UnexpectedEof,
                    format!("line skip {lines} passes the end of the file after {skipped} lines"),
                ));
            }
            let used = match buf.iter().position(|&b| b == b'\n') {
                Some(end) => {
                    found = true;
                    end + 1
                }
                None => buf.len(),
            };
            reader.consume(used);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skips_lines_across_buffer_refills() {
        let text = b"first line\nsecond\nrest";
        let mut reader = BufReader::with_capacity(4, &text[..]);
        skip_lines(&mut reader, 2).unwrap();
        let mut rest = String::new();
        reader.read_to_string(&mut rest).unwrap();
        assert_eq!(rest, "rest");
        assert!(skip_lines(&mut BufReader::new(&b"one\n"[..]), 2).is_err());
    }
}
