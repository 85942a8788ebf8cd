//! The lumen's wall as a triangle mesh, by marching cubes with flying edges' structure.
//!
//! Why this design: one vertex per crossed grid edge (shared by the four cubes around the
//! edge, named by its place in the output rather than looked up) gives about a third of the
//! triangles of marching tetrahedra for the same surface; a case table generated from one rule
//! on faces (`cases`) keeps it watertight without face or body deciders, and the rule keeps
//! the inside 6-connected, as a [`Lumen`] is, so the lumen's surface never merges two lumen
//! voxels that only touch along a diagonal. Flying edges' passes (`grid`, `layout`,
//! `emit`) run on one slab of planes after another while it is in the cache: classify its voxels
//! into bits, count each row's crossed edges and number their vertices, then write the vertices
//! and triangles. Several threads sweep consecutive runs of slabs, joined in order without locks
//! or sorting: the result does not depend on the thread count.
//!
//! Which voxels lie inside is a [`Lumen`] (the component around a seed; only its bounding box
//! is scanned) or, for the whole volume, the side of the isovalue (a voxel equal to it is on
//! the wall's side, as for the lumen). Each vertex lies on a grid edge where the linear field
//! along it crosses the isovalue (the trilinear field's crossing there), but never closer than
//! a thousandth of the edge to its ends: a voxel equal to the isovalue thus gives no triangle
//! of zero area (see `emit`). Triangles face out of the inside (into the wall); a closed lumen
//! gives a watertight mesh.

mod cases;
mod emit;
mod grid;
mod layout;

use crate::navigate::{Lumen, LumenSide};
use crate::scene::{MeshError, TriangleMesh};
use crate::Volume;
use emit::{emit, Pieces, Placer};
use glam::DVec3;
use grid::{Grid, Inside};
use layout::Layout;
use rayon::prelude::*;
use std::ops::Range;

/// The surface of `lumen` at its threshold: the boundary between its voxels and the rest, in
/// world mm (watertight where the lumen does not reach the volume's border).
pub fn lumen_surface(volume: &Volume, lumen: &Lumen) -> Result<TriangleMesh, MeshError> {
    extract(
        volume,
        lumen_box(volume, lumen),
        &Inside::Lumen(lumen),
        lumen.threshold(),
    )
}

/// The isosurface at `iso` (physical units) of the whole volume, facing away from the voxels on
/// `side` of it, in world mm.
pub fn isosurface(volume: &Volume, iso: f64, side: LumenSide) -> Result<TriangleMesh, MeshError> {
    let map = volume.value_map();
    let holds = |s: &u16| side.holds(map.physical(*s), iso);
    // No voxel value on the inside's side: no surface.
    let (Some(lo), Some(hi)) = ((0..=u16::MAX).find(holds), (0..=u16::MAX).rev().find(holds))
    else {
        return Err(MeshError::Empty);
    };
    extract(
        volume,
        ([0; 3], volume.dims()),
        &Inside::Values(lo..=hi),
        iso,
    )
}

/// The surface of the voxels whose value is `label` (a segmentation's region), in world mm,
/// facing out of it: the region's indicator, padded by a voxel of nothing on every side (so a
/// region touching the grid's edge is closed), blurred once by [1, 2, 1] / 4 along each axis
/// and cut at one half — a smooth surface instead of voxel steps, that keeps the region's
/// volume and its place to a fraction of a voxel. Every voxel of the region stays inside (the
/// blurred value of its centre is kept at [`LABEL_FLOOR`] at least), so a region one voxel
/// thin (a small vessel, a lymph node of a voxel or two) keeps a surface instead of vanishing
/// under the blur.
pub fn label_surface(volume: &Volume, label: u16) -> Result<TriangleMesh, MeshError> {
    let [nx, ny, nz] = volume.dims();
    let dims = [nx + 2, ny + 2, nz + 2];
    let mut field = vec![0.0f32; dims.iter().product()];
    let at = |[i, j, k]: [usize; 3]| i + dims[0] * (j + dims[1] * k);
    let region: Vec<usize> = (volume.voxels().iter().enumerate())
        .filter(|(_, &v)| v == label)
        .map(|(n, _)| at([n % nx + 1, n / nx % ny + 1, n / (nx * ny) + 1]))
        .collect();
    for &n in &region {
        field[n] = 1.0;
    }
    for axis in 0..3 {
        field = blurred(&field, dims, axis);
    }
    for &n in &region {
        field[n] = field[n].max(LABEL_FLOOR);
    }
    let geometry = volume.geometry();
    let origin = geometry.world_of(DVec3::splat(-1.0));
    let padded = crate::Geometry::new(dims, geometry.spacing_mm(), origin, geometry.direction())
        .map_err(|_| MeshError::Empty)?;
    let voxels = field.iter().map(|&f| (f * 1000.0).round() as u16).collect();
    let indicator = Volume::new(
        padded,
        voxels,
        crate::ValueMap::IDENTITY,
        crate::Modality::Unknown,
    )
    .map_err(|_| MeshError::Empty)?;
    isosurface(&indicator, 500.0, LumenSide::Above)
}

/// The least value a region's voxel keeps after the blur (the cut is at 0.5): a voxel alone
/// then has its surface about 0.4 voxel from its centre, and a flat face (0.75 after the blur)
/// is untouched.
const LABEL_FLOOR: f32 = 0.75;

/// `field` (a `dims` grid) blurred by [1, 2, 1] / 4 along `axis` (the ends see zero beyond).
fn blurred(field: &[f32], dims: [usize; 3], axis: usize) -> Vec<f32> {
    let stride = [1, dims[0], dims[0] * dims[1]][axis];
    let len = dims[axis];
    field
        .par_iter()
        .enumerate()
        .map(|(n, &centre)| {
            let along = n / stride % len;
            let before = if along > 0 { field[n - stride] } else { 0.0 };
            let after = if along + 1 < len {
                field[n + stride]
            } else {
                0.0
            };
            0.25 * before + 0.5 * centre + 0.25 * after
        })
        .collect()
}

/// How many planes of cubes a slab holds: its bits and voxels (9 planes of a 256² scan: 74 KiB
/// and 1.2 MiB) stay in the cache from classifying them to placing the vertices.
const SLAB: usize = 8;

/// The surface between the inside voxels of the box at `lo` of size `dims` and the others,
/// vertices where the field crosses `iso`: slabs of planes swept in order, by one thread or, cut
/// into consecutive runs of slabs, by several (the runs joined in order: the same mesh).
fn extract(
    volume: &Volume,
    (lo, dims): ([usize; 3], [usize; 3]),
    inside: &Inside,
    iso: f64,
) -> Result<TriangleMesh, MeshError> {
    if dims.iter().any(|&n| n < 2) {
        return Err(MeshError::Empty);
    }
    let slabs = (dims[2] - 1).div_ceil(SLAB);
    let threads = rayon::current_num_threads();
    // Several runs a thread even out the work of unequal slabs.
    let runs = if threads == 1 {
        1
    } else {
        (4 * threads).min(slabs)
    };
    let pieces = (0..runs)
        .into_par_iter()
        .map(|r| {
            sweep(
                volume,
                inside,
                (lo, dims),
                r * slabs / runs..(r + 1) * slabs / runs,
                iso,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let Pieces {
        vertices,
        triangles,
    } = joined(pieces)?;
    TriangleMesh::new(vertices, triangles)
}

/// The vertices and triangles of the slabs `slabs` of the box, their ids counted from the run's
/// first vertex (ids at or past its end name the next run's first vertices).
fn sweep(
    volume: &Volume,
    inside: &Inside,
    (lo, dims): ([usize; 3], [usize; 3]),
    slabs: Range<usize>,
    iso: f64,
) -> Result<Pieces, MeshError> {
    let mut grid = Grid::new(volume, inside, lo, [dims[0], dims[1]]);
    let mut layout = Layout::default();
    let placer = Placer::new(volume, iso);
    let mut out = Pieces::default();
    for s in slabs {
        let k0 = s * SLAB;
        let planes = (dims[2] - 1 - k0).min(SLAB) + 1;
        grid.load(lo[2] + k0, planes);
        layout.count(&grid, k0 + planes == dims[2]);
        let base = out.vertices.len();
        if base + layout.named > u32::MAX as usize {
            let vertices = base + layout.named;
            return Err(MeshError::TooLarge { vertices });
        }
        emit(&grid, &layout, &placer, base as u32, &mut out);
    }
    Ok(out)
}

/// The runs' pieces one after another, each run's ids moved by the vertices before it.
fn joined(pieces: Vec<Pieces>) -> Result<Pieces, MeshError> {
    let vertices = pieces.iter().map(|p| p.vertices.len()).sum::<usize>();
    if vertices > u32::MAX as usize {
        return Err(MeshError::TooLarge { vertices });
    }
    let triangles = pieces.iter().map(|p| p.triangles.len()).sum::<usize>();
    let mut pieces = pieces.into_iter();
    let mut whole = pieces.next().unwrap_or_default();
    whole.vertices.reserve(vertices - whole.vertices.len());
    whole.triangles.reserve(triangles - whole.triangles.len());
    for piece in pieces {
        let base = whole.vertices.len() as u32;
        whole.vertices.extend_from_slice(&piece.vertices);
        (whole.triangles).extend(piece.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    Ok(whole)
}

/// The box of the volume that holds `lumen` and a voxel more on every side (within the volume).
fn lumen_box(volume: &Volume, lumen: &Lumen) -> ([usize; 3], [usize; 3]) {
    let (lo, hi) = lumen.bounds();
    let dims = volume.dims();
    let lo = lo.map(|c| c.saturating_sub(1));
    let hi = [0, 1, 2].map(|a| (hi[a] + 1).min(dims[a].saturating_sub(1)));
    (lo, [0, 1, 2].map(|a| (hi[a] + 1).saturating_sub(lo[a])))
}

#[cfg(test)]
mod tests;
