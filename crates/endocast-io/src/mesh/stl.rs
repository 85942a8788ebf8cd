//! STL: binary (an 80-byte header, a triangle count, 50 bytes a triangle) or ASCII
//! (`solid … facet normal … outer loop vertex ×3 endloop endfacet … endsolid`). A file is
//! binary when its size is what its count says, even if it starts with `solid` (many
//! exporters do that); otherwise one starting with `solid` is ASCII.

use super::{check_count, write_f32s, Parts};
use crate::error::{ReadError, Result};
use endocast_core::scene::TriangleMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;

pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Parts> {
    let claimed = (bytes.len() >= 84).then(|| {
        u64::from(u32::from_le_bytes([
            bytes[80], bytes[81], bytes[82], bytes[83],
        ]))
    });
    if let Some(n) = claimed {
        if 84 + 50 * n == bytes.len() as u64 {
            return binary(path, bytes, n);
        }
    }
    if bytes.trim_ascii_start().starts_with(b"solid") {
        return ascii(path, bytes);
    }
    Err(match claimed {
        Some(n) => ReadError::format(
            path,
            format!(
                "binary STL truncated or padded: its header claims {n} triangles ({} bytes) but \
                 the file has {} bytes",
                84 + 50 * n,
                bytes.len()
            ),
        ),
        None => ReadError::format(path, "too short for a binary STL and not ASCII STL"),
    })
}

fn binary(path: &Path, bytes: &[u8], n: u64) -> Result<Parts> {
    let n = check_count(path, "triangles", n)?;
    let mut vertices = Vec::with_capacity(3 * n);
    for t in 0..n {
        let record = &bytes[84 + 50 * t..84 + 50 * t + 50];
        for v in 0..3 {
            let at = |a: usize| {
                let o = 12 + 12 * v + 4 * a;
                f64::from(f32::from_le_bytes([
                    record[o],
                    record[o + 1],
                    record[o + 2],
                    record[o + 3],
                ]))
            };
            vertices.push(DVec3::new(at(0), at(1), at(2)));
        }
    }
    Ok(unshared(vertices))
}

/// Triangles of three consecutive vertices each.
fn unshared(vertices: Vec<DVec3>) -> Parts {
    let triangles = (0..vertices.len() as u32 / 3)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    (vertices, triangles)
}

fn ascii(path: &Path, bytes: &[u8]) -> Result<Parts> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| ReadError::format(path, "ASCII STL with bytes that are not text"))?;
    let mut vertices = Vec::new();
    let mut in_loop = 0usize;
    let mut ended = false;
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let at = |what: &str| format!("line {}: {what}", number + 1);
        match words.next() {
            Some("vertex") => {
                let xyz: Vec<f64> = words.map(|w| w.parse().unwrap_or(f64::NAN)).collect();
                let [x, y, z] = xyz[..] else {
                    return Err(ReadError::format(path, at("a vertex needs three numbers")));
                };
                vertices.push(DVec3::new(x, y, z));
                in_loop += 1;
                check_count(path, "vertices", vertices.len() as u64)?;
            }
            Some("outer") => in_loop = 0,
            Some("endsolid") => ended = true,
            Some("endloop") if in_loop != 3 => {
                let message = format!("a facet with {in_loop} vertices (STL needs 3)");
                return Err(ReadError::format(path, at(&message)));
            }
            _ => {}
        }
    }
    if vertices.len() % 3 != 0 {
        return Err(ReadError::format(path, "the last facet is incomplete"));
    }
    if !ended {
        return Err(ReadError::format(
            path,
            "the ASCII STL ends without its endsolid line: the file is truncated",
        ));
    }
    Ok(unshared(vertices))
}

pub(super) fn write(w: &mut dyn Write, mesh: &TriangleMesh) -> std::io::Result<()> {
    let mut header = [b' '; 80];
    let title = b"endocast mesh, world mm (LPS)";
    header[..title.len()].copy_from_slice(title);
    w.write_all(&header)?;
    let n = u32::try_from(mesh.triangles().len()).unwrap_or(u32::MAX);
    w.write_all(&n.to_le_bytes())?;
    for i in 0..n as usize {
        let [a, b, c] = mesh.corners(i);
        let normal = (b - a).cross(c - a).normalize_or_zero();
        for p in [normal, a, b, c] {
            write_f32s(w, &p.as_vec3().to_array())?;
        }
        w.write_all(&[0, 0])?;
    }
    Ok(())
}
