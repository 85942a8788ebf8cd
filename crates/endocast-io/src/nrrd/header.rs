//! Parsing a NRRD header into typed fields: the magic, every field this reader uses, and the
//! data file list. Nothing here knows about geometry or reads samples.
//!
//! Field names are matched without case and without spaces, so the NRRD0001 spellings
//! (`datafile`, `lineskip`, `axismins`, `centerings`) and the later ones (`data file`,
//! `line skip`, `axis mins`, `centers`) are the same field.

use super::fields::{ByteSkip, Center, DataFiles, Encoding, Space};
use super::files::parse_data_file;
use super::values::{
    parse_byte_skip, parse_count, parse_dimension, parse_encoding, parse_endian, parse_origin,
    parse_space, parse_type, PerAxis,
};
use crate::error::{ReadError, Result};
use crate::limits::Limits;
use crate::samples::{ElementType, Endian};
use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// A text header longer than this is refused: real ones are a few hundred bytes, a `LIST` of
/// ten thousand slice names is still far below it.
pub(super) const MAX_HEADER_BYTES: u64 = 1 << 20;

/// The fields of a NRRD header that endocast uses, validated one by one. Cross-field rules
/// (which axes are spatial, how the geometry follows) are the caller's.
#[derive(Debug, Clone)]
pub(super) struct Header {
    pub element: ElementType,
    pub dimension: usize,
    /// Samples along each axis, the first fastest; each positive.
    pub sizes: Vec<u64>,
    pub encoding: Encoding,
    pub endian: Option<Endian>,
    pub space: Option<Space>,
    pub space_dimension: Option<usize>,
    /// One entry per axis: its world vector (spacing × direction), or `None` for `none`.
    pub space_directions: Option<Vec<Option<[f64; 3]>>>,
    pub space_origin: Option<[f64; 3]>,
    pub space_units: Option<Vec<String>>,
    /// One entry per axis, NaN where the file says the axis has no spacing.
    pub spacings: Option<Vec<f64>>,
    pub axis_mins: Option<Vec<f64>>,
    pub centers: Option<Vec<Option<Center>>>,
    pub line_skip: u64,
    pub byte_skip: ByteSkip,
    pub data: DataFiles,
    /// Bytes from the start of the file to the first byte after the header.
    pub header_bytes: u64,
}

/// Reads and validates the header of the NRRD file at `path`; unknown fields are warned about.
/// `limits` bounds the number of data files a `%d` pattern may name.
pub(super) fn read_header(
    path: &Path,
    limits: &Limits,
    warnings: &mut Vec<String>,
) -> Result<Header> {
    let file = std::fs::File::open(path).map_err(|e| ReadError::io(path, e))?;
    let text = read_header_lines(path, BufReader::new(file).take(MAX_HEADER_BYTES))?;
    Fields::parse(path, &text.lines)?.into_header(path, &text, limits, warnings)
}

/// The header as lines, before interpretation.
struct HeaderText {
    lines: Vec<String>,
    /// Whether a blank line ended the header (attached data follow) rather than the file's end.
    blank_line: bool,
    bytes: u64,
}

fn read_header_lines(path: &Path, mut reader: impl BufRead) -> Result<HeaderText> {
    let mut text = HeaderText {
        lines: Vec::new(),
        blank_line: false,
        bytes: 0,
    };
    let mut buf = Vec::new();
    loop {
        buf.clear();
        let n = reader
            .read_until(b'\n', &mut buf)
            .map_err(|e| ReadError::io(path, e))?;
        if n == 0 {
            break;
        }
        text.bytes += n as u64;
        if buf.last() != Some(&b'\n') && text.bytes >= MAX_HEADER_BYTES {
            return Err(ReadError::format(
                path,
                format!("the header is longer than {MAX_HEADER_BYTES} bytes (expected a blank line before the data)"),
            ));
        }
        let line = String::from_utf8_lossy(&buf);
        let line = line.trim_end_matches(['\n', '\r']);
        if text.lines.is_empty() {
            check_magic(path, line)?;
        } else if line.is_empty() {
            text.blank_line = true;
            break;
        }
        text.lines.push(line.to_owned());
    }
    if text.lines.is_empty() {
        check_magic(path, "")?;
    }
    Ok(text)
}

fn check_magic(path: &Path, line: &str) -> Result<()> {
    let version_ok =
        line.len() == 8 && line.starts_with("NRRD000") && matches!(line.as_bytes()[7], b'1'..=b'5');
    if version_ok {
        return Ok(());
    }
    let shown: String = line.chars().take(16).collect();
    Err(ReadError::format(
        path,
        format!("expected the magic NRRD0001 … NRRD0005 on the first line, found {shown:?}"),
    ))
}

/// The raw `field: value` pairs, keyed by normalised field name, plus a `LIST` of data files.
struct Fields {
    values: HashMap<String, String>,
    list: Vec<String>,
}

/// Lower-case, spaces removed: `Data File` → `datafile`.
fn normalise(field: &str) -> String {
    field
        .chars()
        .filter(|c| !c.is_whitespace())
        .map(|c| c.to_ascii_lowercase())
        .collect()
}

impl Fields {
    fn parse(path: &Path, lines: &[String]) -> Result<Self> {
        let mut fields = Self {
            values: HashMap::new(),
            list: Vec::new(),
        };
        let mut listing = false;
        for (index, line) in lines.iter().enumerate().skip(1) {
            if listing {
                // After `data file: LIST`, every remaining header line names one file.
                fields.list.push(line.trim().to_owned());
                continue;
            }
            if line.starts_with('#') {
                continue;
            }
            let Some(colon) = line.find(':') else {
                return Err(ReadError::format(
                    path,
                    format!(
                        "line {}: expected \"field: value\", found {line:?}",
                        index + 1
                    ),
                ));
            };
            if line[colon + 1..].starts_with('=') {
                continue; // key:=value pairs carry nothing endocast uses
            }
            let name = normalise(&line[..colon]);
            let value = line[colon + 1..].trim().to_owned();
            listing = name == "datafile" && value.split_whitespace().next() == Some("LIST");
            if fields.values.insert(name, value).is_some() {
                return Err(ReadError::format(
                    path,
                    format!("field {:?} appears twice", line[..colon].trim()),
                ));
            }
        }
        Ok(fields)
    }

    fn get(&self, name: &str) -> Option<&str> {
        self.values.get(name).map(String::as_str)
    }

    fn required(&self, path: &Path, name: &str) -> Result<&str> {
        self.get(name)
            .ok_or_else(|| ReadError::format(path, format!("the header has no {name:?} field")))
    }

    fn into_header(
        self,
        path: &Path,
        text: &HeaderText,
        limits: &Limits,
        warnings: &mut Vec<String>,
    ) -> Result<Header> {
        self.warn_unknown(path, warnings);
        let element = parse_type(path, self.required(path, "type")?)?;
        let dimension = parse_dimension(path, self.required(path, "dimension")?)?;
        let axes = PerAxis { path, dimension };
        let sizes = axes.sizes(self.required(path, "sizes")?)?;
        let encoding = parse_encoding(path, self.get("encoding").unwrap_or("raw"))?;
        let byte_skip = parse_byte_skip(path, self.get("byteskip"), encoding)?;
        let data = match self.get("datafile") {
            Some(value) => parse_data_file(path, value, &self.list, dimension, limits)?,
            None if text.blank_line => DataFiles::Attached,
            None => {
                return Err(ReadError::format(
                    path,
                    "the header ends without the blank line that starts the data, \
                     and names no data file",
                ))
            }
        };
        let space_dimension = match self.get("spacedimension") {
            Some(v) => Some(parse_count(path, "space dimension", v)?),
            None => None,
        };
        Ok(Header {
            element,
            dimension,
            sizes,
            encoding,
            endian: self
                .get("endian")
                .map(|v| parse_endian(path, v))
                .transpose()?,
            space: self
                .get("space")
                .map(|v| parse_space(path, v))
                .transpose()?,
            space_dimension,
            space_directions: self
                .get("spacedirections")
                .map(|v| axes.directions(v))
                .transpose()?,
            space_origin: self
                .get("spaceorigin")
                .map(|v| parse_origin(path, v))
                .transpose()?,
            space_units: self.get("spaceunits").map(|v| axes.strings(v)),
            spacings: self
                .get("spacings")
                .map(|v| axes.numbers("spacings", v))
                .transpose()?,
            axis_mins: self
                .get("axismins")
                .map(|v| axes.numbers("axis mins", v))
                .transpose()?,
            centers: self
                .get("centers")
                .or(self.get("centerings"))
                .map(|v| axes.centers(v))
                .transpose()?,
            line_skip: match self.get("lineskip") {
                Some(v) => parse_count(path, "line skip", v)?,
                None => 0,
            },
            byte_skip,
            data,
            header_bytes: text.bytes,
        })
    }

    fn warn_unknown(&self, path: &Path, warnings: &mut Vec<String>) {
        // Fields of the format that carry nothing a scalar volume needs.
        const IGNORED: &[&str] = &[
            "content",
            "kinds",
            "labels",
            "units",
            "thicknesses",
            "axismaxs",
            "min",
            "max",
            "oldmin",
            "oldmax",
            "measurementframe",
            "sampleunits",
            "number",
            "blocksize",
        ];
        const USED: &[&str] = &[
            "type",
            "dimension",
            "sizes",
            "encoding",
            "endian",
            "byteskip",
            "lineskip",
            "space",
            "spacedimension",
            "spacedirections",
            "spaceorigin",
            "spaceunits",
            "spacings",
            "axismins",
            "centers",
            "centerings",
            "datafile",
        ];
        let mut unknown: Vec<&String> = self
            .values
            .keys()
            .filter(|k| !IGNORED.contains(&k.as_str()) && !USED.contains(&k.as_str()))
            .collect();
        unknown.sort();
        for name in unknown {
            warnings.push(format!(
                "{}: unknown NRRD field {name:?} ignored",
                path.display()
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(text: &str) -> Result<Header> {
        let lines = read_header_lines(Path::new("t.nhdr"), text.as_bytes())?;
        let mut warnings = Vec::new();
        Fields::parse(Path::new("t.nhdr"), &lines.lines)?.into_header(
            Path::new("t.nhdr"),
            &lines,
            &Limits::default(),
            &mut warnings,
        )
    }

    #[test]
    fn parses_spellings_and_vectors() {
        let text = "NRRD0004\n# c\ntype: unsigned short int\nDimension: 3\nsizes: 2 3 4\n\
             space: RAS\nspace directions: ( 1, 0,0) (0,2,0) (0,0,3)\nspace origin: (1,2,3)\n\
             encoding: gz\nendian: big\nbyteskip: 5\nfoo:=bar\n\nDATA";
        let h = header(text).unwrap();
        assert_eq!(h.element, ElementType::U16);
        assert_eq!(h.sizes, vec![2, 3, 4]);
        assert_eq!(h.space, Some(Space::Ras));
        assert_eq!(h.space_directions.unwrap()[1], Some([0.0, 2.0, 0.0]));
        assert_eq!(h.space_origin, Some([1.0, 2.0, 3.0]));
        assert_eq!(h.encoding, Encoding::Gzip);
        assert_eq!(h.byte_skip, ByteSkip::Bytes(5));
        assert_eq!(h.data, DataFiles::Attached);
        assert_eq!(h.header_bytes, text.len() as u64 - 4);
    }

    #[test]
    fn expands_patterns_and_lists() {
        let h = header(
            "NRRD0004\ntype: short\ndimension: 3\nsizes: 1 1 3\ndata file: s%03d.raw 5 1 -2\n",
        )
        .unwrap();
        let names = vec!["s005.raw".to_owned(), "s003.raw".into(), "s001.raw".into()];
        assert_eq!(
            h.data,
            DataFiles::Many {
                names,
                subdim: None
            }
        );
        let h =
            header("NRRD0005\ntype: short\ndimension: 3\nsizes: 1 1 2\ndatafile: LIST 2\na b\nc\n")
                .unwrap();
        let names = vec!["a b".to_owned(), "c".into()];
        assert_eq!(
            h.data,
            DataFiles::Many {
                names,
                subdim: Some(2)
            }
        );
    }

    #[test]
    fn rejects_bad_fields() {
        let base = "NRRD0004\ntype: short\ndimension: 3\n";
        for bad in [
            "sizes: 1 0 1\n\n",
            "sizes: 1 -1 1\n\n",
            "sizes: 1 1\n\n",
            "sizes: 1 1 1\nspace directions: (nan,0,0) (0,1,0) (0,0,1)\n\n",
            "sizes: 1 1 1\nspace origin: (0,0)\n\n",
            "sizes: 1 1 1\nencoding: gzip\nbyte skip: -1\n\n",
            "sizes: 1 1 1\ndata file: a%d 1 3 0\n",
            "sizes: 1 1 1\ndata file: a%d 3 1 1\n",
            "sizes: 1 1 1\n", // no blank line, no data file
        ] {
            assert!(header(&format!("{base}{bad}")).is_err(), "{bad}");
        }
        assert!(header("NRRD0009\n").is_err());
        assert!(matches!(
            header("NRRD0004\ntype: block\ndimension: 3\nsizes: 1 1 1\n\n"),
            Err(ReadError::Unsupported { .. })
        ));
        assert!(matches!(
            header("NRRD0004\ntype: short\ndimension: 7\nsizes: 1 1 1 1 1 1 1\n\n"),
            Err(ReadError::Unsupported { .. })
        ));
    }
}
