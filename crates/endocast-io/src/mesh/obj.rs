//! Wavefront OBJ: `v x y z` vertices and `f` faces (`i`, `i/t`, `i//n`, `i/t/n`; negative
//! indices count back from the last vertex), polygons cut into fans of triangles; everything
//! else (normals, texture coordinates, groups, materials) is ignored.

use super::{check_count, Parts};
use crate::error::{ReadError, Result};
use endocast_core::scene::TriangleMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;

pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Parts> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| ReadError::format(path, "OBJ with bytes that are not UTF-8 text"))?;
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for (number, line) in text.lines().enumerate() {
        let bad = |what: String| ReadError::format(path, format!("line {}: {what}", number + 1));
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let xyz: Vec<f64> = words
                    .take(3)
                    .map(|w| w.parse().unwrap_or(f64::NAN))
                    .collect();
                let [x, y, z] = xyz[..] else {
                    return Err(bad("a vertex needs three coordinates".into()));
                };
                vertices.push(DVec3::new(x, y, z));
                check_count(path, "vertices", vertices.len() as u64)?;
            }
            Some("f") => {
                let corners = words
                    .map(|w| index(w, vertices.len()))
                    .collect::<Option<Vec<u32>>>()
                    .ok_or_else(|| bad("a face index is not a vertex number".into()))?;
                if corners.len() < 3 {
                    return Err(bad(format!(
                        "a face with {} vertices (at least 3)",
                        corners.len()
                    )));
                }
                for k in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[k], corners[k + 1]]);
                }
                check_count(path, "triangles", triangles.len() as u64)?;
            }
            _ => {}
        }
    }
    Ok((vertices, triangles))
}

/// The zero-based vertex index of face corner `word` (`i`, `i/t`, `i//n`, `i/t/n`), with
/// `count` vertices read so far; `None` for 0 or a relative index before the first vertex.
/// (An index past the end is caught when the mesh is validated.)
fn index(word: &str, count: usize) -> Option<u32> {
    let i: i64 = word.split('/').next()?.parse().ok()?;
    let zero_based = match i {
        0 => return None,
        i if i > 0 => i - 1,
        i => count as i64 + i,
    };
    u32::try_from(zero_based).ok()
}

pub(super) fn write(w: &mut dyn Write, mesh: &TriangleMesh) -> std::io::Result<()> {
    writeln!(w, "# endocast mesh, world mm (LPS)")?;
    for v in mesh.vertices() {
        writeln!(w, "v {} {} {}", v.x as f32, v.y as f32, v.z as f32)?;
    }
    for [a, b, c] in mesh.triangles() {
        writeln!(w, "f {} {} {}", a + 1, b + 1, c + 1)?;
    }
    Ok(())
}
