//! Parsers of single NRRD field values: types, counts, encodings, spaces, vectors and the
//! per-axis lists. Each error names the field and quotes what was found.

use super::fields::{ByteSkip, Center, Encoding, Space};
use crate::error::{ReadError, Result};
use crate::samples::{ElementType, Endian};
use std::path::Path;

pub(super) fn parse_type(path: &Path, value: &str) -> Result<ElementType> {
    let words: Vec<&str> = value.split_whitespace().collect();
    let name = words.join(" ").to_ascii_lowercase();
    Ok(match name.as_str() {
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => ElementType::U8,
        "signed char" | "int8" | "int8_t" => ElementType::I8,
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            ElementType::I16
        }
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
            ElementType::U16
        }
        "int" | "signed int" | "int32" | "int32_t" => ElementType::I32,
        "uint" | "unsigned int" | "uint32" | "uint32_t" => ElementType::U32,
        "longlong"
        | "long long"
        | "long long int"
        | "signed long long"
        | "signed long long int"
        | "int64"
        | "int64_t" => ElementType::I64,
        "ulonglong" | "unsigned long long" | "unsigned long long int" | "uint64" | "uint64_t" => {
            ElementType::U64
        }
        "float" => ElementType::F32,
        "double" => ElementType::F64,
        "block" => return Err(ReadError::unsupported(path, "NRRD type \"block\"")),
        _ => {
            return Err(ReadError::format(
                path,
                format!("unknown NRRD type {value:?} (expected e.g. uchar, short, float)"),
            ))
        }
    })
}

pub(super) fn parse_dimension(path: &Path, value: &str) -> Result<usize> {
    let dimension: usize = parse_count(path, "dimension", value)?;
    if !(2..=4).contains(&dimension) {
        return Err(ReadError::unsupported(
            path,
            format!("NRRD dimension {dimension} (expected 2, 3, or 4 with a first axis of size 1)"),
        ));
    }
    Ok(dimension)
}

/// A non-negative integer field.
pub(super) fn parse_count<T: std::str::FromStr>(
    path: &Path,
    field: &str,
    value: &str,
) -> Result<T> {
    value.parse().map_err(|_| {
        ReadError::format(
            path,
            format!("{field}: expected a non-negative integer, found {value:?}"),
        )
    })
}

pub(super) fn parse_encoding(path: &Path, value: &str) -> Result<Encoding> {
    match value.to_ascii_lowercase().as_str() {
        "raw" => Ok(Encoding::Raw),
        "gzip" | "gz" => Ok(Encoding::Gzip),
        "ascii" | "text" | "txt" => Ok(Encoding::Ascii),
        "hex" => Ok(Encoding::Hex),
        "bzip2" | "bz2" | "zstd" => Err(ReadError::unsupported(
            path,
            format!("NRRD encoding {value:?} (read: raw, gzip, ascii, hex)"),
        )),
        _ => Err(ReadError::format(
            path,
            format!("unknown NRRD encoding {value:?} (expected raw, gzip, bzip2, ascii or hex)"),
        )),
    }
}

pub(super) fn parse_byte_skip(
    path: &Path,
    value: Option<&str>,
    encoding: Encoding,
) -> Result<ByteSkip> {
    let Some(value) = value else {
        return Ok(ByteSkip::Bytes(0));
    };
    match value.parse::<i64>() {
        Ok(-1) if encoding == Encoding::Raw => Ok(ByteSkip::ToEnd),
        Ok(-1) => Err(ReadError::format(
            path,
            format!(
                "byte skip -1 (data at the end of the file) needs raw encoding, found {}",
                encoding.name()
            ),
        )),
        Ok(n) => u64::try_from(n).map(ByteSkip::Bytes).map_err(|_| {
            ReadError::format(path, format!("byte skip must be -1 or more, found {n}"))
        }),
        Err(_) => Err(ReadError::format(
            path,
            format!("byte skip: expected an integer, found {value:?}"),
        )),
    }
}

pub(super) fn parse_endian(path: &Path, value: &str) -> Result<Endian> {
    match value.to_ascii_lowercase().as_str() {
        "little" => Ok(Endian::Little),
        "big" => Ok(Endian::Big),
        _ => Err(ReadError::format(
            path,
            format!("endian: expected little or big, found {value:?}"),
        )),
    }
}

pub(super) fn parse_space(path: &Path, value: &str) -> Result<Space> {
    let name = value.to_ascii_lowercase();
    Ok(match name.as_str() {
        "left-posterior-superior" | "lps" => Space::Lps,
        "right-anterior-superior" | "ras" => Space::Ras,
        "left-anterior-superior" | "las" => Space::Las,
        "scanner-xyz" | "3d-right-handed" | "3d-left-handed" => {
            Space::NonAnatomical(value.to_owned())
        }
        _ if name.ends_with("-time") || matches!(name.as_str(), "rast" | "last" | "lpst") => {
            return Err(ReadError::unsupported(
                path,
                format!("NRRD space {value:?} (a space with a time axis)"),
            ))
        }
        _ => {
            return Err(ReadError::format(
                path,
                format!("unknown NRRD space {value:?} (expected e.g. left-posterior-superior)"),
            ))
        }
    })
}

/// Splits `(1,0,0) none (0, 1, 0)` into vectors and `none`s; `None` when malformed.
fn parse_vector_list(text: &str) -> Option<Vec<Option<Vec<f64>>>> {
    let mut out = Vec::new();
    let mut rest = text.trim_start();
    while !rest.is_empty() {
        if let Some(inner) = rest.strip_prefix('(') {
            let end = inner.find(')')?;
            let numbers = inner[..end]
                .split(',')
                .map(|c| c.trim().parse::<f64>().ok())
                .collect::<Option<Vec<f64>>>()?;
            out.push(Some(numbers));
            rest = inner[end + 1..].trim_start();
        } else {
            let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
            if !rest[..end].eq_ignore_ascii_case("none") {
                return None;
            }
            out.push(None);
            rest = rest[end..].trim_start();
        }
    }
    Some(out)
}

/// A 3-vector of finite numbers, or a message saying what was found.
fn finite_vector3(numbers: &[f64]) -> std::result::Result<[f64; 3], String> {
    match numbers {
        [x, y, z] if numbers.iter().all(|v| v.is_finite()) => Ok([*x, *y, *z]),
        [_, _, _] => Err(format!("{numbers:?} is not finite")),
        _ => Err(format!(
            "expected 3 components (space dimension 3), found {}",
            numbers.len()
        )),
    }
}

pub(super) fn parse_origin(path: &Path, value: &str) -> Result<[f64; 3]> {
    let bad = |why: String| ReadError::format(path, format!("space origin {value:?}: {why}"));
    match parse_vector_list(value).as_deref() {
        Some([Some(numbers)]) => finite_vector3(numbers).map_err(bad),
        _ => Err(bad("expected one vector such as (0,0,0)".into())),
    }
}

/// Parsers of the per-axis fields, which hold one entry per axis.
pub(super) struct PerAxis<'a> {
    pub path: &'a Path,
    pub dimension: usize,
}

impl PerAxis<'_> {
    fn wrong_count(&self, field: &str, value: &str, what: &str) -> ReadError {
        ReadError::format(
            self.path,
            format!(
                "{field}: expected {} {what} (one per axis), found {value:?}",
                self.dimension
            ),
        )
    }

    pub(super) fn sizes(&self, value: &str) -> Result<Vec<u64>> {
        let sizes: Option<Vec<u64>> = value
            .split_whitespace()
            .map(|s| s.parse::<u64>().ok().filter(|&n| n > 0))
            .collect();
        sizes
            .filter(|s| s.len() == self.dimension)
            .ok_or_else(|| self.wrong_count("sizes", value, "positive integers"))
    }

    pub(super) fn numbers(&self, field: &str, value: &str) -> Result<Vec<f64>> {
        let numbers: Option<Vec<f64>> = value
            .split_whitespace()
            .map(|s| s.parse::<f64>().ok())
            .collect();
        numbers
            .filter(|n| n.len() == self.dimension)
            .ok_or_else(|| self.wrong_count(field, value, "numbers"))
    }

    pub(super) fn strings(&self, value: &str) -> Vec<String> {
        value
            .split_whitespace()
            .map(|s| s.trim_matches('"').to_owned())
            .collect()
    }

    pub(super) fn centers(&self, value: &str) -> Result<Vec<Option<Center>>> {
        let centers: Option<Vec<Option<Center>>> = value
            .split_whitespace()
            .map(|s| match s.to_ascii_lowercase().as_str() {
                "cell" => Some(Some(Center::Cell)),
                "node" => Some(Some(Center::Node)),
                "???" | "none" => Some(None),
                _ => None,
            })
            .collect();
        centers
            .filter(|c| c.len() == self.dimension)
            .ok_or_else(|| self.wrong_count("centers", value, "of cell, node or ???"))
    }

    pub(super) fn directions(&self, value: &str) -> Result<Vec<Option<[f64; 3]>>> {
        let vectors = parse_vector_list(value)
            .filter(|v| v.len() == self.dimension)
            .ok_or_else(|| self.wrong_count("space directions", value, "vectors or none"))?;
        vectors
            .iter()
            .enumerate()
            .map(|(axis, v)| {
                v.as_deref()
                    .map(|numbers| {
                        finite_vector3(numbers).map_err(|why| {
                            ReadError::format(
                                self.path,
                                format!("space directions, axis {axis}: {why}"),
                            )
                        })
                    })
                    .transpose()
            })
            .collect()
    }
}
