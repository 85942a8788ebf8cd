//! Flying edges' last pass: each plane of voxels writes its rows' vertices and triangles into
//! the ranges the layout gave them, in parallel and without locks. A vertex lies where the
//! linear interpolation of the field along its edge equals the isovalue; a triangle names its
//! vertices by counting, along its row of cubes, the crossed edges met so far in each of the
//! rows it touches.

use super::cases::{crossed, CASES};
use super::grid::Grid;
use super::layout::{Layout, RowLayout};
use glam::DVec3;
use rayon::prelude::*;

/// How close to its ends a vertex may come, as a fraction of its edge. A voxel equal to the
/// isovalue is on the wall's side, as if a hair beyond it (a symbolic perturbation): the crossing
/// on each of its edges to an inside voxel is then just off it, so that the several vertices
/// around it stay apart and no triangle between them has zero area, while the surface keeps the
/// topology of the perturbed field (watertight). Elsewhere the vertex is the exact crossing.
const END_GAP: f64 = 1e-3;

/// The field's values and the isovalue, to place vertices.
struct Placer<'g> {
    grid: &'g Grid<'g>,
    iso: f64,
}

/// Every plane's vertices (world mm) and triangles, written in parallel.
pub(super) fn emit(grid: &Grid, layout: &Layout, iso: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let [_, ny, nz] = grid.dims;
    let (vertex_bounds, triangle_bounds) = layout.plane_starts(ny);
    let mut vertices = vec![DVec3::ZERO; layout.vertices];
    let mut triangles = vec![[0u32; 3]; layout.triangles];
    let placer = Placer { grid, iso };
    split(&mut vertices, &vertex_bounds)
        .into_par_iter()
        .zip(split(&mut triangles, &triangle_bounds))
        .enumerate()
        .for_each(|(k, (vs, ts))| {
            for j in 0..ny {
                let row = layout.row(j, k, ny);
                let at = row.vertex as usize - vertex_bounds[k];
                placer.row_vertices(j, k, row, &mut vs[at..]);
                if j + 1 < ny && k + 1 < nz {
                    let at = row.triangle - triangle_bounds[k];
                    row_triangles(grid, layout, j, k, &mut ts[at..]);
                }
            }
        });
    (vertices, triangles)
}

/// `items` cut at `bounds` (ascending, from 0 to its length) into consecutive pieces.
fn split<'a, T>(mut items: &'a mut [T], bounds: &[usize]) -> Vec<&'a mut [T]> {
    let mut pieces = Vec::with_capacity(bounds.len());
    for w in bounds.windows(2) {
        let (piece, rest) = items.split_at_mut(w[1] - w[0]);
        pieces.push(piece);
        items = rest;
    }
    pieces
}

impl Placer<'_> {
    /// Writes the vertices of row `(j, k)`'s crossed `i`, `j` and `k` edges, in that order,
    /// from the start of `out`.
    fn row_vertices(&self, j: usize, k: usize, layout: &RowLayout, out: &mut [DVec3]) {
        let row = self.grid.row(j, k);
        let span = self.grid.span(j, k);
        let mut n = 0;
        let mut put = |i: usize, axis: usize| {
            out[n] = self.vertex([i, j, k], axis);
            n += 1;
        };
        for i in span.first as usize..span.end as usize {
            if row[i] != row[i + 1] {
                put(i, 0);
            }
        }
        for (axis, count) in [(1, layout.y), (2, layout.z)] {
            if count == 0 {
                continue;
            }
            let next = if axis == 1 {
                self.grid.row(j + 1, k)
            } else {
                self.grid.row(j, k + 1)
            };
            for (i, (a, b)) in row.iter().zip(next).enumerate() {
                if a != b {
                    put(i, axis);
                }
            }
        }
    }

    /// The vertex on the edge from box voxel `v` along `axis`, in world mm: where the field
    /// crosses the isovalue, kept [`END_GAP`] from the ends. An edge whose ends do not straddle
    /// the isovalue (an inside voxel that is not on the inside's side of it) gives its midpoint.
    fn vertex(&self, v: [usize; 3], axis: usize) -> DVec3 {
        let grid = self.grid;
        let [nx, ny, _] = grid.volume.dims();
        let at = |v: [usize; 3]| {
            let w = [0, 1, 2].map(|a| grid.lo[a] + v[a]);
            let stored = grid.volume.voxels()[w[0] + nx * (w[1] + ny * w[2])];
            grid.volume.value_map().physical(stored) - self.iso
        };
        let mut u = v;
        u[axis] += 1;
        let (f0, f1) = (at(v), at(u));
        let t = f0 / (f0 - f1);
        let t = if (0.0..=1.0).contains(&t) { t } else { 0.5 };
        let mut p = DVec3::from(v.map(|c| c as f64)) + DVec3::from(grid.lo.map(|c| c as f64));
        p[axis] += t.clamp(END_GAP, 1.0 - END_GAP);
        grid.volume.geometry().world_of(p)
    }
}

/// Writes the triangles of the row of cubes `(j, k)` from the start of `out`.
fn row_triangles(grid: &Grid, layout: &Layout, j: usize, k: usize, out: &mut [[u32; 3]]) {
    let ny = grid.dims[1];
    let cube_row = grid.cube_rows(j, k);
    let row = |dy: usize, dz: usize| layout.row(j + dy, k + dz, ny);
    // The id the next crossed edge would get, for the edges at the cube's lower `i` (the `i`
    // edges, and the `j` and `k` edges with dx = 0; the others are their twins one column on).
    let mut next = [0u32; 12];
    for (o, (dy, dz)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
        next[o] = row(dy, dz).vertex;
    }
    for d in 0..2 {
        let (y_row, z_row) = (row(0, d), row(d, 0));
        next[4 + 2 * d] = y_row.vertex + y_row.x;
        next[8 + 2 * d] = z_row.vertex + z_row.x + z_row.y;
    }
    let mut n = 0;
    for case in cube_row.cut(layout.row(j, k, ny).cubes.clone()) {
        let id = |e: usize| match e {
            5 | 7 | 9 | 11 => next[e - 1] + u32::from(crossed(case, e - 1)),
            _ => next[e],
        };
        let c = &CASES[usize::from(case)];
        for t in &c.triangles[..usize::from(c.count)] {
            out[n] = t.map(|e| id(usize::from(e)));
            n += 1;
        }
        for e in [0, 1, 2, 3, 4, 6, 8, 10] {
            next[e] += u32::from(crossed(case, e));
        }
    }
}
