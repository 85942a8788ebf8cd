//! PLY: a text header (`ply`, `format ascii|binary_little_endian|binary_big_endian 1.0`,
//! `element NAME COUNT` with its `property TYPE NAME` or `property list COUNT_TYPE TYPE NAME`
//! lines, `end_header`), then the elements in order. The `vertex` element's `x`, `y`, `z` and
//! the `face` element's `vertex_indices` (or `vertex_index`) list are read; other properties
//! and elements are skipped. Every count is checked against what the rest of the file can hold.

use super::{check_count, write_f32s, Parts};
use crate::error::{ReadError, Result};
use endocast_core::scene::TriangleMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// A scalar property type: its size in bytes and whether it is a float.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Scalar {
    bytes: usize,
    float: bool,
    signed: bool,
}

fn scalar(name: &str) -> Option<Scalar> {
    let s = |bytes, float, signed| {
        Some(Scalar {
            bytes,
            float,
            signed,
        })
    };
    match name {
        "char" | "int8" => s(1, false, true),
        "uchar" | "uint8" => s(1, false, false),
        "short" | "int16" => s(2, false, true),
        "ushort" | "uint16" => s(2, false, false),
        "int" | "int32" => s(4, false, true),
        "uint" | "uint32" => s(4, false, false),
        "float" | "float32" => s(4, true, true),
        "double" | "float64" => s(8, true, true),
        _ => None,
    }
}

#[derive(Debug, Clone)]
struct Property {
    name: String,
    /// For a list: the count's type.
    list: Option<Scalar>,
    kind: Scalar,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Parts> {
    let bad = |m: &str| ReadError::format(path, m.to_string());
    let end = find(bytes, b"end_header").ok_or_else(|| bad("no PLY end_header"))?;
    let header = std::str::from_utf8(&bytes[..end]).map_err(|_| bad("PLY header is not text"))?;
    let mut body_start = end + b"end_header".len();
    // The header's last line ends with \n (or \r\n).
    while body_start < bytes.len() && bytes[body_start] != b'\n' {
        body_start += 1;
    }
    body_start += 1;
    let (encoding, elements) = header_lines(path, header)?;
    let body = bytes.get(body_start..).unwrap_or(&[]);
    let mut reader = Reader {
        path,
        encoding,
        body,
        at: 0,
        words: None,
    };
    if encoding == Encoding::Ascii {
        let text = std::str::from_utf8(body).map_err(|_| bad("ASCII PLY body is not text"))?;
        reader.words = Some(text.split_ascii_whitespace());
    }
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for element in &elements {
        // Each element takes at least a byte (binary) or a character per item.
        let least: usize = element.properties.len().max(1);
        let remaining = (body.len() - reader.at.min(body.len())) as u64;
        if element.count.saturating_mul(least as u64) > remaining {
            return Err(bad(&format!(
                "PLY header claims {} {} elements but the file is too short for them",
                element.count, element.name
            )));
        }
        match element.name.as_str() {
            "vertex" => {
                let n = check_count(path, "vertices", element.count)?;
                vertices.reserve(n);
                for _ in 0..n {
                    vertices.push(reader.vertex(element)?);
                }
            }
            "face" => {
                let n = check_count(path, "faces", element.count)?;
                triangles.reserve(n);
                for _ in 0..n {
                    reader.face(element, &mut triangles)?;
                    check_count(path, "triangles", triangles.len() as u64)?;
                }
            }
            _ => {
                for _ in 0..element.count {
                    reader.skip(element)?;
                }
            }
        }
    }
    Ok((vertices, triangles))
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

fn header_lines(path: &Path, header: &str) -> Result<(Encoding, Vec<Element>)> {
    let bad = |m: String| ReadError::format(path, m);
    let mut lines = header.lines();
    if lines.next().map(str::trim) != Some("ply") {
        return Err(bad("not a PLY file (no 'ply' line)".into()));
    }
    let (mut encoding, mut elements) = (None, Vec::<Element>::new());
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", f, _] => {
                encoding = Some(match *f {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    other => return Err(bad(format!("unknown PLY format {other:?}"))),
                });
            }
            ["element", name, count] => elements.push(Element {
                name: (*name).into(),
                count: count
                    .parse()
                    .map_err(|_| bad(format!("PLY element count {count:?}")))?,
                properties: Vec::new(),
            }),
            ["property", "list", count, item, name] => {
                let (Some(c), Some(k)) = (scalar(count), scalar(item)) else {
                    return Err(bad(format!("unknown PLY list types in {line:?}")));
                };
                let element = elements
                    .last_mut()
                    .ok_or_else(|| bad("property before element".into()))?;
                element.properties.push(Property {
                    name: (*name).into(),
                    list: Some(c),
                    kind: k,
                });
            }
            ["property", kind, name] => {
                let kind =
                    scalar(kind).ok_or_else(|| bad(format!("unknown PLY type in {line:?}")))?;
                let element = elements
                    .last_mut()
                    .ok_or_else(|| bad("property before element".into()))?;
                element.properties.push(Property {
                    name: (*name).into(),
                    list: None,
                    kind,
                });
            }
            _ => {}
        }
    }
    let encoding = encoding.ok_or_else(|| bad("PLY header has no format line".into()))?;
    Ok((encoding, elements))
}

/// Reads values from the body, text or binary.
struct Reader<'a> {
    path: &'a Path,
    encoding: Encoding,
    body: &'a [u8],
    at: usize,
    words: Option<std::str::SplitAsciiWhitespace<'a>>,
}

impl Reader<'_> {
    fn truncated(&self) -> ReadError {
        ReadError::format(self.path, "PLY body ends early (truncated file)")
    }

    fn value(&mut self, kind: Scalar) -> Result<f64> {
        if let Some(words) = &mut self.words {
            let word = words.next().ok_or_else(|| self.truncated())?;
            return word
                .parse()
                .map_err(|_| ReadError::format(self.path, format!("PLY value {word:?}")));
        }
        let end = self.at + kind.bytes;
        let raw = self
            .body
            .get(self.at..end)
            .ok_or_else(|| self.truncated())?;
        self.at = end;
        let mut b = [0u8; 8];
        b[..kind.bytes].copy_from_slice(raw);
        if self.encoding == Encoding::Big {
            b[..kind.bytes].reverse();
        }
        Ok(match (kind.bytes, kind.float, kind.signed) {
            (4, true, _) => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            (8, true, _) => f64::from_le_bytes(b),
            (1, _, true) => f64::from(b[0] as i8),
            (1, _, false) => f64::from(b[0]),
            (2, _, true) => f64::from(i16::from_le_bytes([b[0], b[1]])),
            (2, _, false) => f64::from(u16::from_le_bytes([b[0], b[1]])),
            (_, _, true) => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            _ => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        })
    }

    /// The values of one property (one, or a list's).
    fn property(&mut self, p: &Property, out: &mut Vec<f64>) -> Result<()> {
        out.clear();
        let Some(count_kind) = p.list else {
            out.push(self.value(p.kind)?);
            return Ok(());
        };
        let n = self.value(count_kind)?;
        if !(0.0..=1e6).contains(&n) {
            return Err(ReadError::format(
                self.path,
                format!("PLY list of {n} items"),
            ));
        }
        for _ in 0..n as usize {
            out.push(self.value(p.kind)?);
        }
        Ok(())
    }

    fn vertex(&mut self, element: &Element) -> Result<DVec3> {
        let mut xyz = [f64::NAN; 3];
        let mut values = Vec::new();
        for p in &element.properties {
            self.property(p, &mut values)?;
            let axis = ["x", "y", "z"].iter().position(|n| *n == p.name);
            if let (Some(a), Some(&v)) = (axis, values.first()) {
                xyz[a] = v;
            }
        }
        Ok(DVec3::from(xyz))
    }

    fn face(&mut self, element: &Element, triangles: &mut Vec<[u32; 3]>) -> Result<()> {
        let mut values = Vec::new();
        for p in &element.properties {
            self.property(p, &mut values)?;
            if p.list.is_none() || !matches!(p.name.as_str(), "vertex_indices" | "vertex_index") {
                continue;
            }
            if values.len() < 3 {
                return Err(ReadError::format(
                    self.path,
                    format!("a face with {} vertices (at least 3)", values.len()),
                ));
            }
            let index = |v: f64| {
                (v >= 0.0 && v <= f64::from(u32::MAX) && v.fract() == 0.0).then_some(v as u32)
            };
            let corners: Option<Vec<u32>> = values.iter().map(|&v| index(v)).collect();
            let corners = corners.ok_or_else(|| {
                ReadError::format(self.path, "a face index that is not a vertex number")
            })?;
            for k in 1..corners.len() - 1 {
                triangles.push([corners[0], corners[k], corners[k + 1]]);
            }
        }
        Ok(())
    }

    fn skip(&mut self, element: &Element) -> Result<()> {
        let mut values = Vec::new();
        for p in &element.properties {
            self.property(p, &mut values)?;
        }
        Ok(())
    }
}

pub(super) fn write(w: &mut dyn Write, mesh: &TriangleMesh) -> std::io::Result<()> {
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment endocast mesh, world mm (LPS)\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.vertices().len(),
        mesh.triangles().len()
    )?;
    for v in mesh.vertices() {
        write_f32s(w, &v.as_vec3().to_array())?;
    }
    for t in mesh.triangles() {
        w.write_all(&[3])?;
        for i in t {
            w.write_all(&i.to_le_bytes())?;
        }
    }
    Ok(())
}
