//! Triangle meshes: STL (ASCII and binary), Wavefront OBJ and PLY (ASCII and binary) in, the
//! same three out (binary STL, OBJ, binary little-endian PLY), picked by the file's extension.
//! Coordinates are taken as world millimetres in the LPS patient frame, as endocast writes
//! them (3D Slicer writes RAS by default: its "LPS" option matches).
//!
//! A bad file is an error naming it and the problem — a truncated binary STL, an index out of
//! range, a NaN vertex, a face of fewer than three vertices — and counts in a header are
//! checked against [`MAX_TRIANGLES`] and against what the file can hold before anything is
//! allocated for them.

mod obj;
mod ply;
mod stl;

use crate::error::{ReadError, Result};
use endocast_core::scene::TriangleMesh;
use glam::DVec3;
use std::io::Write;
use std::path::Path;

/// The most triangles (and vertices) a mesh file may hold.
pub const MAX_TRIANGLES: u64 = 20_000_000;
/// The largest mesh file read, bytes.
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// The mesh formats, by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    /// `.stl`: ASCII or binary.
    Stl,
    /// `.obj`: Wavefront.
    Obj,
    /// `.ply`: Stanford polygon file.
    Ply,
}

impl MeshFormat {
    /// The format `path`'s extension names (ASCII case ignored).
    pub fn of(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("stl") => Ok(Self::Stl),
            Some("obj") => Ok(Self::Obj),
            Some("ply") => Ok(Self::Ply),
            _ => Err(ReadError::unsupported(
                path,
                "mesh format: use a .stl, .obj or .ply file",
            )),
        }
    }
}

/// Reads the mesh in `path` (STL, OBJ or PLY by its extension).
pub fn read_mesh(path: &Path) -> Result<TriangleMesh> {
    let format = MeshFormat::of(path)?;
    let meta = std::fs::metadata(path).map_err(|e| ReadError::io(path, e))?;
    if !meta.is_file() {
        // A device or pipe has no size to check and may never end (/dev/zero).
        return Err(ReadError::format(
            path,
            "not a regular file (a device, pipe or folder): give the mesh file itself",
        ));
    }
    let size = meta.len();
    if size > MAX_FILE_BYTES {
        return Err(limit(path, "file bytes", size, MAX_FILE_BYTES));
    }
    let bytes = std::fs::read(path).map_err(|e| ReadError::io(path, e))?;
    let (vertices, triangles) = match format {
        MeshFormat::Stl => stl::parse(path, &bytes)?,
        MeshFormat::Obj => obj::parse(path, &bytes)?,
        MeshFormat::Ply => ply::parse(path, &bytes)?,
    };
    TriangleMesh::new(vertices, triangles).map_err(|e| ReadError::format(path, e.to_string()))
}

/// Writes `mesh` to `path` atomically, in the format its extension names.
pub fn write_mesh(path: &Path, mesh: &TriangleMesh) -> Result<()> {
    let format = MeshFormat::of(path)?;
    crate::atomic::write_file(path, |w| match format {
        MeshFormat::Stl => stl::write(w, mesh),
        MeshFormat::Obj => obj::write(w, mesh),
        MeshFormat::Ply => ply::write(w, mesh),
    })
}

/// A limit error.
fn limit(path: &Path, what: &str, requested: u64, limit: u64) -> ReadError {
    ReadError::Limit {
        path: path.to_path_buf(),
        what: what.into(),
        requested,
        limit,
    }
}

/// Checks a count against [`MAX_TRIANGLES`].
fn check_count(path: &Path, what: &str, count: u64) -> Result<usize> {
    if count > MAX_TRIANGLES {
        return Err(limit(path, what, count, MAX_TRIANGLES));
    }
    Ok(count as usize)
}

/// Vertices and triangles as parsed, before validation.
type Parts = (Vec<DVec3>, Vec<[u32; 3]>);

/// Writes `values` as little-endian `f32`s.
fn write_f32s(w: &mut dyn Write, values: &[f32]) -> std::io::Result<()> {
    for v in values {
        w.write_all(&v.to_le_bytes())?;
    }
    Ok(())
}
