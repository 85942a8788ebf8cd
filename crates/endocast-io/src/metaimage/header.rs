//! The MetaImage text header: `Key = value` lines ending with `ElementDataFile`.

use crate::error::{ReadError, Result};
use crate::samples::{ElementType, Endian};
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

/// A text header longer than this is not a MetaImage header (real ones are under 1 KiB).
const MAX_HEADER_BYTES: u64 = 1 << 20;

/// The `MET_*` element types and the samples they name. MetaIO sizes `MET_LONG` and
/// `MET_ULONG` as 4 bytes (its type table), whatever `long` is on the writing machine.
pub(super) const ELEMENT_TYPES: [(&str, ElementType); 12] = [
    ("MET_UCHAR", ElementType::U8),
    ("MET_CHAR", ElementType::I8),
    ("MET_USHORT", ElementType::U16),
    ("MET_SHORT", ElementType::I16),
    ("MET_UINT", ElementType::U32),
    ("MET_INT", ElementType::I32),
    ("MET_ULONG", ElementType::U32),
    ("MET_LONG", ElementType::I32),
    ("MET_ULONG_LONG", ElementType::U64),
    ("MET_LONG_LONG", ElementType::I64),
    ("MET_FLOAT", ElementType::F32),
    ("MET_DOUBLE", ElementType::F64),
];

/// Where the voxels are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DataFile {
    /// `ElementDataFile = LOCAL`: right after the header, in the same file (`.mha`).
    Local,
    /// A separate file (`.raw`, `.zraw`), resolved against the header's folder (`.mhd`).
    Detached(PathBuf),
}

/// Where the voxel data starts (`HeaderSize`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DataStart {
    /// This many bytes after the header (LOCAL) or after the start of the data file.
    Skip(u64),
    /// `HeaderSize = -1`: the data are the last bytes of the data file.
    AtEnd,
}

/// A parsed MetaImage header, as a 3-D volume (a 2-D image is one slice).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Header {
    /// `DimSize`: samples along `i`, `j`, `k` (`k` = 1 for a 2-D image).
    pub dims: [u64; 3],
    /// `ElementSpacing` (or `ElementSize` when spacing is absent), mm; default 1.
    pub spacing_mm: [f64; 3],
    /// `Offset` (aliases `Origin`, `Position`): LPS world position of voxel (0,0,0), mm.
    pub origin_mm: [f64; 3],
    /// `TransformMatrix` (aliases `Rotation`, `Orientation`): the nine numbers are three
    /// consecutive triples, each the LPS world unit vector of one index axis (i, then j, then
    /// k), so triple `n` is column `n` of the direction matrix. This is how ITK's MetaImageIO
    /// fills the image direction (`direction[row][n] = matrix[n * NDims + row]`). Default:
    /// identity.
    pub direction_columns: [[f64; 3]; 3],
    /// `AnatomicalOrientation` as written (ITK writes e.g. `RAI` for an identity direction:
    /// each letter names the side an index axis comes *from*).
    pub anatomical_orientation: Option<String>,
    /// `ElementType`.
    pub element: ElementType,
    /// `ElementByteOrderMSB` / `BinaryDataByteOrderMSB`; default little-endian.
    pub endian: Endian,
    /// `CompressedData`: the voxels are one zlib stream.
    pub compressed: bool,
    /// `CompressedDataSize`, when given.
    pub compressed_size: Option<u64>,
    /// `HeaderSize`; default `Skip(0)`.
    pub data_start: DataStart,
    /// `ElementDataFile`.
    pub data_file: DataFile,
    /// Length of the header text in bytes: where LOCAL data start.
    pub text_bytes: u64,
}

/// Reads and parses the header of the MetaImage file at `path` (at most 1 MiB of text).
pub fn read_header(path: &Path) -> Result<Header> {
    let file = File::open(path).map_err(|e| ReadError::io(path, e))?;
    let (lines, text_bytes) = header_lines(path, BufReader::new(file))?;
    Fields { path, lines }.header(text_bytes)
}

/// `(key, value)` pairs up to and including `ElementDataFile`, and the bytes they took.
fn header_lines(path: &Path, reader: impl BufRead) -> Result<(Vec<(String, String)>, u64)> {
    let mut limited = reader.take(MAX_HEADER_BYTES);
    let (mut lines, mut consumed, mut raw) = (Vec::new(), 0u64, Vec::new());
    loop {
        raw.clear();
        let n = limited
            .read_until(b'\n', &mut raw)
            .map_err(|e| ReadError::io(path, e))?;
        if n == 0 || !raw.ends_with(b"\n") && consumed + n as u64 >= MAX_HEADER_BYTES {
            return Err(ReadError::format(
                path,
                "not a MetaImage header: no `ElementDataFile = ...` line in the first 1 MiB",
            ));
        }
        consumed += n as u64;
        let line = std::str::from_utf8(&raw).map_err(|_| {
            ReadError::format(
                path,
                format!(
                    "header line {} is not text: the header must end with an ElementDataFile \
                     line before any binary data",
                    lines.len() + 1
                ),
            )
        })?;
        if line.trim().is_empty() {
            continue;
        }
        let (key, value) = line.split_once('=').ok_or_else(|| {
            ReadError::format(
                path,
                format!("expected `Key = value`, found {:?}", line.trim()),
            )
        })?;
        let (key, value) = (key.trim().to_string(), value.trim().to_string());
        let last = key.eq_ignore_ascii_case("ElementDataFile");
        lines.push((key, value));
        if last {
            return Ok((lines, consumed));
        }
    }
}

/// Typed access to the header's fields; keys match case-insensitively, the last one wins.
struct Fields<'a> {
    path: &'a Path,
    lines: Vec<(String, String)>,
}

impl Fields<'_> {
    /// The value of the first of `keys` that is present.
    fn get(&self, keys: &[&str]) -> Option<(&str, &str)> {
        keys.iter().find_map(|want| {
            self.lines
                .iter()
                .rev()
                .find(|(key, _)| key.eq_ignore_ascii_case(want))
                .map(|(key, value)| (key.as_str(), value.as_str()))
        })
    }

    fn bad(&self, key: &str, value: &str, expected: &str) -> ReadError {
        ReadError::format(self.path, format!("{key} = {value:?}: expected {expected}"))
    }

    fn numbers<T: std::str::FromStr>(
        &self,
        keys: &[&str],
        n: usize,
        what: &str,
    ) -> Result<Option<Vec<T>>> {
        let Some((key, value)) = self.get(keys) else {
            return Ok(None);
        };
        let parsed: Option<Vec<T>> = value.split_whitespace().map(|t| t.parse().ok()).collect();
        match parsed {
            Some(v) if v.len() == n => Ok(Some(v)),
            _ => Err(self.bad(key, value, &format!("{n} {what}"))),
        }
    }

    fn reals(&self, keys: &[&str], n: usize) -> Result<Option<Vec<f64>>> {
        let v = self.numbers::<f64>(keys, n, "finite numbers")?;
        match (v, self.get(keys)) {
            (Some(v), Some((key, value))) if v.iter().any(|x| !x.is_finite()) => {
                Err(self.bad(key, value, &format!("{n} finite numbers")))
            }
            (v, _) => Ok(v),
        }
    }

    fn flag(&self, keys: &[&str]) -> Result<Option<bool>> {
        let Some((key, value)) = self.get(keys) else {
            return Ok(None);
        };
        match value.to_ascii_lowercase().as_str() {
            "true" | "1" => Ok(Some(true)),
            "false" | "0" => Ok(Some(false)),
            _ => Err(self.bad(key, value, "True or False")),
        }
    }

    fn header(&self, text_bytes: u64) -> Result<Header> {
        self.check_supported()?;
        let ndims = self.ndims()?;
        let mut dims = [1u64; 3];
        let sizes = self
            .numbers::<u64>(&["DimSize"], ndims, "positive integers")?
            .ok_or_else(|| ReadError::format(self.path, "the header has no DimSize"))?;
        if let Some((key, value)) = self.get(&["DimSize"]).filter(|_| sizes.contains(&0)) {
            return Err(self.bad(key, value, &format!("{ndims} positive integers")));
        }
        dims[..ndims].copy_from_slice(&sizes);
        let spacing = match self.reals(&["ElementSpacing"], ndims)? {
            Some(spacing) => Some(spacing),
            None => self.reals(&["ElementSize"], ndims)?,
        };
        let origin = self.reals(&["Offset", "Origin", "Position"], ndims)?;
        let matrix = self.reals(
            &["TransformMatrix", "Rotation", "Orientation"],
            ndims * ndims,
        )?;
        let mut direction_columns = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        if let Some(m) = matrix {
            for (n, column) in m.chunks_exact(ndims).enumerate() {
                direction_columns[n][..ndims].copy_from_slice(column);
            }
        }
        Ok(Header {
            dims,
            spacing_mm: pad(spacing, ndims, 1.0),
            origin_mm: pad(origin, ndims, 0.0),
            direction_columns,
            anatomical_orientation: self
                .get(&["AnatomicalOrientation"])
                .map(|(_, v)| v.to_string()),
            element: self.element()?,
            endian: match self.flag(&["ElementByteOrderMSB", "BinaryDataByteOrderMSB"])? {
                Some(true) => Endian::Big,
                _ => Endian::Little,
            },
            compressed: self.flag(&["CompressedData"])?.unwrap_or(false),
            compressed_size: self
                .numbers::<u64>(&["CompressedDataSize"], 1, "a byte count")?
                .map(|v| v[0]),
            data_start: self.data_start()?,
            data_file: self.data_file()?,
            text_bytes,
        })
    }

    /// Refuses what we do not read: other object types, text voxels, several channels.
    fn check_supported(&self) -> Result<()> {
        let unsupported = |what: String| Err(ReadError::unsupported(self.path, what));
        if let Some((_, kind)) = self
            .get(&["ObjectType"])
            .filter(|(_, v)| !v.eq_ignore_ascii_case("Image"))
        {
            return unsupported(format!(
                "MetaImage ObjectType {kind:?} (only Image is read)"
            ));
        }
        if self.flag(&["BinaryData"])? == Some(false) {
            return unsupported("MetaImage text voxels (BinaryData = False)".into());
        }
        if let Some(v) = self.numbers::<u64>(&["ElementNumberOfChannels"], 1, "a channel count")? {
            if v[0] != 1 {
                return unsupported(format!(
                    "{} channels per voxel (only scalar images are read)",
                    v[0]
                ));
            }
        }
        Ok(())
    }

    fn ndims(&self) -> Result<usize> {
        let n = self
            .numbers::<usize>(&["NDims"], 1, "an integer")?
            .ok_or_else(|| ReadError::format(self.path, "the header has no NDims"))?[0];
        if n == 2 || n == 3 {
            Ok(n)
        } else {
            Err(ReadError::unsupported(
                self.path,
                format!("NDims = {n} (2 or 3 are read)"),
            ))
        }
    }

    fn element(&self) -> Result<ElementType> {
        let (_, name) = self
            .get(&["ElementType"])
            .ok_or_else(|| ReadError::format(self.path, "the header has no ElementType"))?;
        ELEMENT_TYPES
            .iter()
            .find(|(met, _)| met.eq_ignore_ascii_case(name))
            .map(|&(_, ty)| ty)
            .ok_or_else(|| {
                ReadError::unsupported(self.path, format!("MetaImage ElementType {name:?}"))
            })
    }

    fn data_start(&self) -> Result<DataStart> {
        let Some(v) = self.numbers::<i64>(&["HeaderSize"], 1, "an integer")? else {
            return Ok(DataStart::Skip(0));
        };
        match v[0] {
            -1 => Ok(DataStart::AtEnd),
            n => u64::try_from(n).map(DataStart::Skip).map_err(|_| {
                ReadError::format(
                    self.path,
                    format!("HeaderSize = {n}: expected -1 or a byte count"),
                )
            }),
        }
    }

    fn data_file(&self) -> Result<DataFile> {
        let (_, name) = self
            .get(&["ElementDataFile"])
            .ok_or_else(|| ReadError::format(self.path, "the header has no ElementDataFile"))?;
        if name.eq_ignore_ascii_case("LOCAL") {
            Ok(DataFile::Local)
        } else if name.is_empty() {
            Err(ReadError::format(self.path, "ElementDataFile is empty"))
        } else if name.eq_ignore_ascii_case("LIST") || name.contains('%') {
            Err(ReadError::unsupported(
                self.path,
                format!("ElementDataFile = {name} (one file per slice): join the slices into one data file"),
            ))
        } else {
            let folder = self.path.parent().unwrap_or(Path::new(""));
            Ok(DataFile::Detached(folder.join(name)))
        }
    }
}

/// The first `n` values of `given` (or `default`), padded with `default` to three.
fn pad(given: Option<Vec<f64>>, n: usize, default: f64) -> [f64; 3] {
    let mut out = [default; 3];
    if let Some(v) = given {
        out[..n].copy_from_slice(&v);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Header> {
        let path = Path::new("dir/t.mhd");
        let (lines, n) = header_lines(path, text.as_bytes())?;
        Fields { path, lines }.header(n)
    }

    #[test]
    fn two_d_header_with_aliases_and_any_case() {
        let text = "ndims = 2\r\nDimSize = 4 3\nElementSize = 0.5 0.25\nposition = 1 2\n\
                    Rotation = 0 1 -1 0\nElementType = MET_SHORT\nElementByteOrderMSB = True\n\
                    HeaderSize = -1\nElementDataFile = slice.raw\nrest";
        let h = parse(text).unwrap();
        assert_eq!(h.dims, [4, 3, 1]);
        assert_eq!(h.spacing_mm, [0.5, 0.25, 1.0]);
        assert_eq!(h.origin_mm, [1.0, 2.0, 0.0]);
        assert_eq!(
            h.direction_columns,
            [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
        );
        assert_eq!(h.endian, Endian::Big);
        assert_eq!(h.data_start, DataStart::AtEnd);
        assert_eq!(
            h.data_file,
            DataFile::Detached(PathBuf::from("dir/slice.raw"))
        );
        assert_eq!(h.text_bytes, text.len() as u64 - 4);
    }

    #[test]
    fn bad_headers_are_errors() {
        let base = "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n";
        for extra in [
            "",
            "DimSize = 2 2 x\nElementDataFile = LOCAL\n",
            "DimSize = 2 0 2\nElementDataFile = LOCAL\n",
            "ElementSpacing = 1 nan 1\nElementDataFile = LOCAL\n",
            "ElementSpacing = 1 1\nElementDataFile = LOCAL\n",
            "ElementType = MET_FLOAT_ARRAY\nElementDataFile = LOCAL\n",
            "ElementNumberOfChannels = 3\nElementDataFile = LOCAL\n",
            "HeaderSize = -2\nElementDataFile = LOCAL\n",
            "ElementDataFile = LIST\n",
            "ElementDataFile = s%03d.raw 1 10 1\n",
            "no equals sign\nElementDataFile = LOCAL\n",
        ] {
            assert!(parse(&format!("{base}{extra}")).is_err(), "{extra}");
        }
        assert!(parse("NDims = 4\nElementDataFile = LOCAL\n").is_err());
    }
}
