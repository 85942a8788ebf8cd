//! Flying edges' second pass and the prefix sums: how many vertices each row of voxels owns
//! (one per crossed edge from its voxels along `i`, then `j`, then `k`) and how many triangles
//! each row of cubes makes, so that every row knows where its output starts and the last pass
//! can write rows in parallel without locks, in an order that does not depend on the threads.

use super::cases::CASES;
use super::grid::{differences, Grid};
use crate::scene::MeshError;
use rayon::prelude::*;
use std::ops::Range;

/// Where one row's output lies.
#[derive(Debug, Clone, Default)]
pub(super) struct RowLayout {
    /// The id of the row's first vertex (its `i` edges' vertices, then `j`'s, then `k`'s).
    pub vertex: u32,
    /// How many of its `i` edges are crossed.
    pub x: u32,
    /// How many of its `j` edges (to the next row) are crossed.
    pub y: u32,
    /// How many of its `k` edges (to the next plane) are crossed.
    pub z: u32,
    /// The index of the first triangle of the row of cubes starting at this row.
    pub triangle: usize,
    /// The cubes of that row that may be cut.
    pub cubes: Range<usize>,
}

/// Every row's layout (`j + ny·k`) and the totals.
pub(super) struct Layout {
    /// The rows.
    pub rows: Vec<RowLayout>,
    /// How many vertices in all.
    pub vertices: usize,
    /// How many triangles in all.
    pub triangles: usize,
}

/// What pass two counts for one row: its crossed `i`, `j` and `k` edges and its cubes.
struct Counts {
    edges: [usize; 3],
    cubes: Range<usize>,
    triangles: usize,
}

impl Layout {
    /// Counts every row (planes in parallel), then lays the rows out one after another.
    pub fn new(grid: &Grid) -> Result<Self, MeshError> {
        let [_, ny, nz] = grid.dims;
        let counts: Vec<Counts> = (0..ny * nz)
            .into_par_iter()
            .with_min_len(ny)
            .map(|r| count_row(grid, r % ny, r / ny))
            .collect();
        let (mut vertices, mut triangles) = (0usize, 0usize);
        let mut rows = Vec::with_capacity(counts.len());
        for c in counts {
            rows.push(RowLayout {
                vertex: vertices as u32,
                x: c.edges[0] as u32,
                y: c.edges[1] as u32,
                z: c.edges[2] as u32,
                triangle: triangles,
                cubes: c.cubes,
            });
            vertices += c.edges.iter().sum::<usize>();
            triangles += c.triangles;
        }
        if vertices > u32::MAX as usize {
            return Err(MeshError::TooLarge { vertices });
        }
        Ok(Self {
            rows,
            vertices,
            triangles,
        })
    }

    /// Where each plane's vertices and triangles start (planes of `ny` rows), then the totals.
    pub fn plane_starts(&self, ny: usize) -> (Vec<usize>, Vec<usize>) {
        let starts = self.rows.iter().step_by(ny);
        let vertices = starts.clone().map(|r| r.vertex as usize);
        let triangles = starts.map(|r| r.triangle);
        (
            vertices.chain([self.vertices]).collect(),
            triangles.chain([self.triangles]).collect(),
        )
    }

    /// The row `(j, k)`.
    pub fn row(&self, j: usize, k: usize, ny: usize) -> &RowLayout {
        &self.rows[j + ny * k]
    }
}

/// The crossed edges of row `(j, k)` and its row of cubes' trim and triangles.
fn count_row(grid: &Grid, j: usize, k: usize) -> Counts {
    let [_, ny, nz] = grid.dims;
    let row = grid.row(j, k);
    let crossings = |other: &[u8]| differences(row, other);
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
    let (mut cubes, mut triangles) = (0..0, 0);
    if j + 1 < ny && k + 1 < nz {
        let cube_row = grid.cube_rows(j, k);
        cubes = cube_row.trim();
        triangles = cube_row
            .cut(cubes.clone())
            .map(|case| usize::from(CASES[usize::from(case)].count))
            .sum();
    }
    Counts {
        edges: [grid.span(j, k).count as usize, y, z],
        cubes,
        triangles,
    }
}
