//! A pre-flight walk over a DICOM file's element headers that refuses any element whose declared
//! length runs past the end of the file, and sequences nested deeper than [`MAX_NESTING`].
//!
//! dicom-rs reserves the declared length of an element before reading it, so one flipped byte in
//! a length field makes it ask for gigabytes; and it parses nested sequences recursively, so a
//! small file of thousands of nested sequences overflows the stack. Walking the headers first
//! (iteratively, seeking over values, descending into sequences and items) costs a few hundred
//! small reads per file and keeps every allocation bounded by the file's real size. The walk
//! splits the file where dicom-rs does: the file meta group ends where its group length
//! (0002,0000) says, not at the first element of another group; an implicit-VR element has the
//! standard dictionary's VR; and a binary value whose length is not a multiple of its number's
//! size is read by whole numbers, the next header starting right after them; and an item tag
//! other than an item delimiter among a data set's elements (not among a sequence's items) is
//! an element with a value (the fuzzer found each of these: a walk that splits the file anywhere
//! else checks lengths dicom-rs never reads).
//!
//! A deflated data set (transfer syntax 1.2.840.10008.1.2.1.99) is inflated here first: its
//! deflate stream must reach its final block at the end of the file, give or take a few bytes
//! of padding (raw deflate has no checksum, so its end and length are what can be checked), and
//! the inflated elements are then walked like those of any other file.

use super::open::Body;
use crate::compressed;
use crate::error::{ReadError, Result};
use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry};
use dicom_core::Tag;
use dicom_dictionary_std::StandardDataDictionary;
use flate2::bufread::DeflateDecoder;
use std::fs::File;
use std::io::{self, BufReader, Cursor, Read, Seek, SeekFrom};
use std::path::Path;

/// The "undefined length" marker of sequences, items and encapsulated pixel data.
const UNDEFINED: u32 = 0xFFFF_FFFF;
/// Explicit-VR value representations with a 2-byte reserved field and a 4-byte length.
const LONG_VRS: [&[u8; 2]; 13] = [
    b"OB", b"OD", b"OF", b"OL", b"OV", b"OW", b"SQ", b"SV", b"UC", b"UN", b"UR", b"UT", b"UV",
];

/// Every value representation of the standard; an explicit-VR element with any other is corrupt
/// (and its length field cannot even be located).
const KNOWN_VRS: [&[u8; 2]; 34] = [
    b"AE", b"AS", b"AT", b"CS", b"DA", b"DS", b"DT", b"FL", b"FD", b"IS", b"LO", b"LT", b"OB",
    b"OD", b"OF", b"OL", b"OV", b"OW", b"PN", b"SH", b"SL", b"SQ", b"SS", b"ST", b"SV", b"TM",
    b"UC", b"UI", b"UL", b"UN", b"UR", b"US", b"UT", b"UV",
];

/// Sequences and items open at once beyond which a file is refused (two per level of nesting:
/// the sequence and its item). Real files nest a few levels; dicom-rs recurses once per level.
const MAX_NESTING: usize = 64;

/// How the data set after the file meta group is encoded.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Encoding {
    ExplicitLittle,
    ImplicitLittle,
    ExplicitBig,
}

struct Walker<R> {
    reader: BufReader<R>,
    pos: u64,
    len: u64,
    /// The sequences and items open at `pos`, innermost last.
    open: Vec<Level>,
    /// The nesting depth from which elements are implicit VR little endian whatever the
    /// transfer syntax: inside a sequence stored as UN (PS3.5 6.2.2), until it closes.
    implicit_from: Option<usize>,
}

/// A sequence or an item open during the walk.
#[derive(Clone, Copy)]
struct Level {
    /// Where it ends, `None` for an undefined length (closed by its delimiter).
    end: Option<u64>,
    /// Whether it is a sequence, holding items (else an item, holding elements).
    sequence: bool,
}

/// Where a walk stopped.
enum Walked {
    /// At the end of the file: every length fits, in a data set encoded as given.
    End(Body),
    /// At the start of a deflated data set (byte offset), after the file meta group.
    Deflated(u64),
}

/// Checks that every defined element, item and fragment length in the file at `path` fits in the
/// bytes that follow it; a deflated data set is inflated (at most `max_inflated` bytes), its
/// stream checked to its end, and its lengths checked against the inflated bytes. Returns how
/// the data set is encoded: [`Body::Implicit`] when its meta group says explicit VR little
/// endian but its first element has no valid VR (then only the adaptive decoder may read it).
pub(super) fn check_element_lengths(path: &Path, max_inflated: u64) -> Result<Body> {
    let file = File::open(path).map_err(|e| ReadError::io(path, e))?;
    let len = file.metadata().map_err(|e| ReadError::io(path, e))?.len();
    let mut w = Walker {
        reader: BufReader::with_capacity(4096, file),
        pos: 0,
        len,
        open: Vec::new(),
        implicit_from: None,
    };
    let io = |e| ReadError::io(path, e);
    let mut magic = [0u8; 4];
    w.seek_to(128).map_err(io)?;
    w.read_exact(&mut magic).map_err(io)?;
    if &magic != b"DICM" {
        w.seek_to(0).map_err(io)?;
        w.read_exact(&mut magic).map_err(io)?;
        if &magic != b"DICM" {
            w.seek_to(0).map_err(io)?;
        }
    }
    match w
        .walk()
        .map_err(|message| ReadError::format(path, message))?
    {
        Walked::End(body) => Ok(body),
        Walked::Deflated(start) => {
            check_deflated(path, w.reader.into_inner(), start, max_inflated)?;
            Ok(Body::AsDeclared)
        }
    }
}

/// Bytes that may follow a complete deflate stream: some writers pad it to an even length or
/// append a checksum (dicom-rs ignores them). More is a second stream or junk: corruption.
const MAX_TRAILING: u64 = 8;

/// Inflates the data set that starts at byte `start` of `file`, requires its stream to end with
/// the file (but for [`MAX_TRAILING`] bytes), and walks the inflated elements.
fn check_deflated(path: &Path, mut file: File, start: u64, max_inflated: u64) -> Result<()> {
    file.seek(SeekFrom::Start(start))
        .map_err(|e| ReadError::io(path, e))?;
    let mut decoder = DeflateDecoder::new(BufReader::new(file));
    let mut data = Vec::new();
    (&mut decoder)
        .take(max_inflated.saturating_add(1))
        .read_to_end(&mut data)
        .map_err(|e| compressed::corrupt(path, "deflate", e))?;
    if data.len() as u64 > max_inflated {
        return Err(ReadError::Limit {
            path: path.to_path_buf(),
            what: "the inflated data set (bytes)".into(),
            requested: data.len() as u64,
            limit: max_inflated,
        });
    }
    let trailing =
        io::copy(decoder.get_mut(), &mut io::sink()).map_err(|e| ReadError::io(path, e))?;
    if trailing > MAX_TRAILING {
        return Err(ReadError::format(
            path,
            format!("the deflate data are corrupt: {trailing} bytes follow the end of the stream"),
        ));
    }
    let len = data.len() as u64;
    let mut w = Walker {
        reader: BufReader::with_capacity(4096, Cursor::new(data)),
        pos: 0,
        len,
        open: Vec::new(),
        implicit_from: None,
    };
    match w.walk() {
        Ok(Walked::End(Body::AsDeclared)) => Ok(()),
        // dicom-rs's deflate reader has no adaptive decoder: it would take the first element's
        // missing VR as UN and the next bytes as a length of any size.
        Ok(_) => Err(ReadError::format(
            path,
            "the inflated data set's first element has no valid VR: the file is corrupt",
        )),
        Err(message) => Err(ReadError::format(
            path,
            format!("in the inflated data set: {message}"),
        )),
    }
}

/// The data set's encoding from its first element's VR bytes `vr`: a meta group saying
/// explicit VR little endian over a data set without a valid VR is implicit VR (as pydicom
/// and dicom-rs's adaptive decoder read it; see `open`).
fn body_encoding(declared: Option<Encoding>, vr: [u8; 2]) -> Option<Encoding> {
    match declared {
        Some(Encoding::ExplicitLittle) if !KNOWN_VRS.contains(&&vr) => {
            Some(Encoding::ImplicitLittle)
        }
        other => other,
    }
}

/// The VR dicom-rs reads an element as: its explicit VR, else (implicit VR) the standard
/// dictionary's, with Pixel Data and Overlay Data as OW (PS3.5 A.1), as dicom-rs resolves it.
fn read_as(tag: (u16, u16), explicit: Option<[u8; 2]>) -> Option<[u8; 2]> {
    if explicit.is_some() {
        return explicit;
    }
    if tag == (0x7FE0, 0x0010) || (tag.0 >> 8 == 0x60 && tag.1 == 0x3000) {
        return Some(*b"OW");
    }
    StandardDataDictionary
        .by_tag(Tag(tag.0, tag.1))
        .map(|entry| entry.vr().relaxed().to_bytes())
}

/// The bytes dicom-rs consumes of a defined `length` read as `vr`: whole numbers only, so a
/// binary value whose length is not a multiple of its number's size leaves the rest unread (and
/// the next element header starts there, as dicom-rs reads it).
fn bytes_read(length: u32, vr: Option<[u8; 2]>) -> u64 {
    let size: u32 = match vr.as_ref().map(|v| &v[..]) {
        Some(b"US" | b"SS" | b"OW") => 2,
        Some(b"AT" | b"FL" | b"OF" | b"SL" | b"UL" | b"OL") => 4,
        Some(b"FD" | b"OD" | b"SV" | b"UV" | b"OV") => 8,
        _ => 1,
    };
    u64::from(length - length % size)
}

impl<R: Read + Seek> Walker<R> {
    fn seek_to(&mut self, pos: u64) -> io::Result<()> {
        self.reader.seek(SeekFrom::Start(pos))?;
        self.pos = pos;
        Ok(())
    }

    fn read_exact(&mut self, buf: &mut [u8]) -> io::Result<()> {
        self.reader.read_exact(buf)?;
        self.pos += buf.len() as u64;
        Ok(())
    }

    /// Reads `N` bytes, or `None` at the end of the file.
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let mut buf = [0u8; N];
        self.read_exact(&mut buf).ok()?;
        Some(buf)
    }

    fn skip(&mut self, length: u64) -> Result<(), String> {
        self.reader
            .seek_relative(length as i64)
            .map_err(|e| e.to_string())?;
        self.pos += length;
        Ok(())
    }

    fn check(&self, tag: (u16, u16), length: u32) -> Result<(), String> {
        let remaining = self.len - self.pos.min(self.len);
        if u64::from(length) > remaining {
            return Err(format!(
                "element ({:04X},{:04X}) claims {length} bytes but only {remaining} remain in the file",
                tag.0, tag.1
            ));
        }
        Ok(())
    }

    /// Walks the meta group (always explicit little endian), then the data set, unless it is
    /// deflated.
    fn walk(&mut self) -> Result<Walked, String> {
        // `None` once the meta group has named the deflated transfer syntax.
        let mut encoding = Some(Encoding::ExplicitLittle);
        let mut in_meta = true;
        // Where the meta group ends by its group length (dicom-rs stops there).
        let mut meta_end = u64::MAX;
        let mut in_fragments = false;
        // Whether the first element of the data set is still to come.
        let mut first_of_body = true;
        let mut body = Body::AsDeclared;
        while self.pos + 8 <= self.len {
            self.close_ended();
            let start = self.pos;
            let Some(head) = self.take::<8>() else { break };
            let group_le = u16::from_le_bytes([head[0], head[1]]);
            // dicom-rs reads every element within the group length as meta, whatever its group
            // (a corrupt tag inside it does not end it); without a group length, the meta
            // group ends at the first element of another group.
            in_meta = if meta_end == u64::MAX {
                in_meta && group_le == 0x0002
            } else {
                start < meta_end
            };
            if !in_meta && std::mem::take(&mut first_of_body) {
                let found = body_encoding(encoding, [head[4], head[5]]);
                if found != encoding {
                    body = Body::Implicit;
                }
                encoding = found;
            }
            let current = match (in_meta, encoding) {
                (true, _) => Encoding::ExplicitLittle,
                (false, _) if self.in_un_sequence() => Encoding::ImplicitLittle,
                (false, Some(encoding)) => encoding,
                (false, None) => return Ok(Walked::Deflated(start)),
            };
            let (tag, length, vr) = self.element_header(head, current)?;
            // A sequence stored as UN holds implicit VR little endian items.
            let inner = if vr == Some(*b"UN") {
                Encoding::ImplicitLittle
            } else {
                current
            };
            if tag.0 == 0xFFFE && (in_fragments || self.among_items()) {
                in_fragments = self.item(tag, length, in_fragments)?;
                continue;
            }
            if tag == (0xFFFE, 0xE00D) {
                // Among elements, an item delimiter ends the item (and is ignored outside any,
                // as dicom-rs does); any other (FFFE,xxxx) there is an element like any other.
                self.close_item();
                continue;
            }
            if length == UNDEFINED {
                // A sequence (or encapsulated pixel data): its items follow inline.
                in_fragments |= tag == (0x7FE0, 0x0010);
                self.open_sequence(None, vr == Some(*b"UN"))?;
                continue;
            }
            self.check(tag, length)?;
            let end = self.pos + u64::from(length);
            // Only the first group length counts: dicom-rs reads a later (0002,0000) as an
            // ordinary element and still ends the meta group where the first one said.
            if tag == (0x0002, 0x0000) && in_meta && meta_end == u64::MAX {
                meta_end = self
                    .group_length(length)?
                    .map_or(u64::MAX, |n| self.pos + n);
            } else if tag == (0x0002, 0x0010) && in_meta {
                encoding = self.transfer_syntax(length)?;
            } else if read_as(tag, vr) == Some(*b"SQ") || self.starts_with_item(length, inner)? {
                self.open_sequence(Some(end), vr == Some(*b"UN"))?;
            } else {
                self.skip(bytes_read(length, read_as(tag, vr)))?;
            }
        }
        Ok(match encoding {
            Some(_) => Walked::End(body),
            // A deflated data set that is empty (or a meta group cut short): inflating it fails.
            None => Walked::Deflated(self.pos),
        })
    }

    /// Opens a sequence (`sequence`) or an item ending at `end` (`None`: at its delimiter);
    /// refuses one nested deeper than [`MAX_NESTING`].
    fn open(&mut self, end: Option<u64>, sequence: bool) -> Result<(), String> {
        if self.open.len() >= MAX_NESTING {
            return Err(format!(
                "sequences are nested more than {} levels deep (at byte {}); real files nest a \
                 few, so the file is corrupt or hostile",
                MAX_NESTING / 2,
                self.pos
            ));
        }
        self.open.push(Level { end, sequence });
        Ok(())
    }

    /// Opens a sequence ending at `end`; one stored as UN (`un`) holds implicit VR items.
    fn open_sequence(&mut self, end: Option<u64>, un: bool) -> Result<(), String> {
        self.open(end, true)?;
        if un && self.implicit_from.is_none() {
            self.implicit_from = Some(self.open.len());
        }
        Ok(())
    }

    /// Whether `pos` lies inside a sequence stored as UN (forgotten once it has closed).
    fn in_un_sequence(&mut self) -> bool {
        match self.implicit_from {
            Some(depth) if self.open.len() >= depth => true,
            _ => {
                self.implicit_from = None;
                false
            }
        }
    }

    /// Closes the defined-length sequences and items that end at or before `pos`.
    fn close_ended(&mut self) {
        while let Some(Level { end: Some(end), .. }) = self.open.last() {
            if *end > self.pos {
                break;
            }
            self.open.pop();
        }
    }

    /// Closes the innermost sequence or item of undefined length, at its delimiter.
    fn close_delimited(&mut self) {
        if let Some(Level { end: None, .. }) = self.open.last() {
            self.open.pop();
        }
    }

    /// Closes the innermost item, at an item delimiter among its elements.
    fn close_item(&mut self) {
        if self.open.last().is_some_and(|level| !level.sequence) {
            self.open.pop();
        }
    }

    /// Whether the walk is among a sequence's items (else among a data set's elements, at the
    /// top or in an item).
    fn among_items(&self) -> bool {
        self.open.last().is_some_and(|level| level.sequence)
    }

    /// Tag, length and (explicit VR only) the VR of the element whose first 8 bytes are `head`.
    #[allow(clippy::type_complexity)]
    fn element_header(
        &mut self,
        head: [u8; 8],
        encoding: Encoding,
    ) -> Result<((u16, u16), u32, Option<[u8; 2]>), String> {
        let big = encoding == Encoding::ExplicitBig;
        let u16_at = |i: usize| {
            let b = [head[i], head[i + 1]];
            if big {
                u16::from_be_bytes(b)
            } else {
                u16::from_le_bytes(b)
            }
        };
        let tag = (u16_at(0), u16_at(2));
        let u32_of = |b: [u8; 4]| {
            if big {
                u32::from_be_bytes(b)
            } else {
                u32::from_le_bytes(b)
            }
        };
        if tag.0 == 0xFFFE || encoding == Encoding::ImplicitLittle {
            return Ok((tag, u32_of([head[4], head[5], head[6], head[7]]), None));
        }
        let vr = [head[4], head[5]];
        if !KNOWN_VRS.contains(&&vr) {
            return Err(format!(
                "element ({:04X},{:04X}) has an unknown value representation {:?}",
                tag.0,
                tag.1,
                String::from_utf8_lossy(&vr)
            ));
        }
        if LONG_VRS.contains(&&vr) {
            let long = self
                .take::<4>()
                .ok_or("the file ends inside an element header")?;
            Ok((tag, u32_of(long), Some(vr)))
        } else {
            Ok((tag, u32::from(u16_at(6)), Some(vr)))
        }
    }

    /// Handles an item or delimiter; returns whether we are still among pixel-data fragments.
    fn item(&mut self, tag: (u16, u16), length: u32, in_fragments: bool) -> Result<bool, String> {
        match tag.1 {
            0xE000 if in_fragments => {
                if length == UNDEFINED {
                    return Err("a pixel-data fragment has an undefined length".into());
                }
                self.check(tag, length)?;
                self.skip(u64::from(length))?;
                Ok(true)
            }
            0xE000 if length == UNDEFINED => {
                self.open(None, false)?;
                Ok(false) // the item's elements follow inline
            }
            0xE000 => {
                self.check(tag, length)?;
                self.open(Some(self.pos + u64::from(length)), false)?;
                Ok(false)
            }
            0xE00D => {
                self.close_delimited();
                Ok(in_fragments)
            }
            0xE0DD => {
                self.close_delimited();
                Ok(false)
            }
            _ => Ok(in_fragments),
        }
    }

    /// Whether a defined-length value begins with an item tag (a sequence whose VR we cannot see,
    /// in implicit VR or as UN): then we descend into it instead of skipping it.
    fn starts_with_item(&mut self, length: u32, encoding: Encoding) -> Result<bool, String> {
        if length < 8 {
            return Ok(false);
        }
        let start = self.pos;
        let Some(head) = self.take::<4>() else {
            return Ok(false);
        };
        self.seek_to(start).map_err(|e| e.to_string())?;
        let item = if encoding == Encoding::ExplicitBig {
            [0xFF, 0xFE, 0xE0, 0x00]
        } else {
            [0xFE, 0xFF, 0x00, 0xE0]
        };
        Ok(head == item)
    }

    /// Reads the value of the meta group length (0002,0000): `None` unless it is 4 bytes long
    /// (dicom-rs refuses such a file anyway).
    fn group_length(&mut self, length: u32) -> Result<Option<u64>, String> {
        if length != 4 {
            self.skip(u64::from(length))?;
            return Ok(None);
        }
        let value = self
            .take::<4>()
            .ok_or("the file ends inside the meta group length")?;
        Ok(Some(u64::from(u32::from_le_bytes(value))))
    }

    /// Reads the transfer syntax UID value; `None` for a deflated data set (walked once
    /// inflated).
    fn transfer_syntax(&mut self, length: u32) -> Result<Option<Encoding>, String> {
        let mut value = vec![0u8; length as usize];
        self.read_exact(&mut value).map_err(|e| e.to_string())?;
        let uid = String::from_utf8_lossy(&value);
        Ok(match uid.trim_end_matches(['\0', ' ']) {
            "1.2.840.10008.1.2" => Some(Encoding::ImplicitLittle),
            "1.2.840.10008.1.2.2" => Some(Encoding::ExplicitBig),
            "1.2.840.10008.1.2.1.99" => None,
            _ => Some(Encoding::ExplicitLittle),
        })
    }
}
