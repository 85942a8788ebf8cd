//! Flying edges' second pass and the prefix sums, for one slab: how many vertices each row of
//! voxels owns (one per crossed edge from its voxels along `i`, then `j`, then `k`), so that
//! every crossed edge has its id before the triangles that use it are written.
//!
//! The numbering, plane after plane: first the vertices in the plane (each row's `i` edges, then
//! its `j` edges), then those on the `k` edges to the next plane (row after row). The in-plane
//! vertices of a plane are thus numbered without looking past it, so the last plane of a slab
//! gets the ids the next slab (which starts at that plane) gives it: a slab writes the vertices
//! of its planes but the last, and names the last plane's by those ids.

use super::grid::{along, count, Grid};

/// Where one row's vertices lie.
#[derive(Debug, Clone, Default)]
pub(super) struct RowLayout {
    /// The id of the row's first in-plane vertex (its `i` edges' vertices, then `j`'s).
    pub vertex: u32,
    /// The id of its first vertex on a `k` edge.
    pub z_vertex: u32,
    /// How many of its `i` edges are crossed.
    pub x: u32,
    /// How many of its `j` edges (to the next row) are crossed.
    pub y: u32,
    /// How many of its `k` edges (to the next plane) are crossed.
    pub z: u32,
}

/// Every row's layout in a slab (`j + ny·k`), ids counted from the slab's first vertex.
#[derive(Default)]
pub(super) struct Layout {
    /// The rows.
    pub rows: Vec<RowLayout>,
    /// How many vertices the slab writes: all of its planes' but the last one's in-plane
    /// vertices, which the next slab writes (all of them when there is no next slab).
    pub written: usize,
    /// How many ids the slab's rows name (its vertices and its last plane's in-plane ones).
    pub named: usize,
}

impl Layout {
    /// Counts every row of the slab loaded in `grid` and numbers its vertices; `last` tells
    /// whether the slab ends the box (and so writes its last plane's vertices too).
    pub fn count(&mut self, grid: &Grid, last: bool) {
        let [_, ny, nz] = grid.dims;
        self.rows.clear();
        self.rows
            .extend((0..ny * nz).map(|r| count_row(grid, r % ny, r / ny)));
        // Ids past u32 wrap here; the caller checks `named` before any is used.
        let mut next = 0usize;
        for k in 0..nz {
            let plane = &mut self.rows[k * ny..(k + 1) * ny];
            if k + 1 == nz && !last {
                self.written = next;
            }
            for row in plane.iter_mut() {
                row.vertex = next as u32;
                next += (row.x + row.y) as usize;
            }
            for row in plane.iter_mut() {
                row.z_vertex = next as u32;
                next += row.z as usize;
            }
        }
        self.named = next;
        if last {
            self.written = next;
        }
    }

    /// The row `(j, k)`.
    pub fn row(&self, j: usize, k: usize, ny: usize) -> &RowLayout {
        &self.rows[j + ny * k]
    }
}

/// The crossed edges of row `(j, k)` (ids not yet given).
fn count_row(grid: &Grid, j: usize, k: usize) -> RowLayout {
    let [nx, ny, nz] = grid.dims;
    let row = grid.row(j, k);
    let crossings = |other: &[u64]| count(row.len(), |w| row[w] ^ other[w]);
    let y = if j + 1 < ny {
        crossings(grid.row(j + 1, k))
    } else {
        0
    };
    let z = if k + 1 < nz {
        crossings(grid.row(j, k + 1))
    } else {
        0
    };
    RowLayout {
        vertex: 0,
        z_vertex: 0,
        x: count(row.len(), |w| along(row, nx, w)),
        y,
        z,
    }
}
