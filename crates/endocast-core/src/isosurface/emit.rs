//! Flying edges' last pass, for one slab: its vertices and triangles appended to the output. A
//! vertex lies where the linear interpolation of the field along its edge equals the isovalue;
//! a triangle names its vertices by counting, along its row of cubes, the crossed edges met so
//! far in each of the rows it touches.

use super::cases::{crossed, CASES};
use super::grid::{along, for_each_one, Grid};
use super::layout::Layout;
use crate::{ValueMap, Volume};
use glam::{DAffine3, DVec3};

/// How close to its ends a vertex may come, as a fraction of its edge. A voxel equal to the
/// isovalue is on the wall's side, as if a hair beyond it (a symbolic perturbation): the crossing
/// on each of its edges to an inside voxel is then just off it, so that the several vertices
/// around it stay apart and no triangle between them has zero area, while the surface keeps the
/// topology of the perturbed field (watertight). Elsewhere the vertex is the exact crossing.
const END_GAP: f64 = 1e-3;

/// A mesh being written: vertices in world mm, triangles as vertex ids.
#[derive(Default)]
pub(super) struct Pieces {
    /// The vertices.
    pub vertices: Vec<DVec3>,
    /// The triangles.
    pub triangles: Vec<[u32; 3]>,
}

/// The field's values and the isovalue, to place vertices.
pub(super) struct Placer<'v> {
    voxels: &'v [u16],
    /// The steps between neighbouring voxels along `i`, `j` and `k`.
    strides: [usize; 3],
    map: ValueMap,
    iso: f64,
    world: DAffine3,
}

impl<'v> Placer<'v> {
    /// Places vertices on the isovalue `iso` (physical units) of `volume`.
    pub fn new(volume: &'v Volume, iso: f64) -> Self {
        let [nx, ny, _] = volume.dims();
        Self {
            voxels: volume.voxels(),
            strides: [1, nx, nx * ny],
            map: volume.value_map(),
            iso,
            world: volume.geometry().world_from_voxel(),
        }
    }

    /// The vertex on the edge from volume voxel `v` along `axis`, in world mm: where the field
    /// crosses the isovalue, kept [`END_GAP`] from the ends. An edge whose ends do not straddle
    /// the isovalue (an inside voxel that is not on the inside's side of it) gives its midpoint.
    #[inline]
    fn vertex(&self, v: [usize; 3], axis: usize) -> DVec3 {
        let at = v[0] + self.strides[1] * v[1] + self.strides[2] * v[2];
        let f0 = self.map.physical(self.voxels[at]) - self.iso;
        let f1 = self.map.physical(self.voxels[at + self.strides[axis]]) - self.iso;
        let t = f0 / (f0 - f1);
        let t = if (0.0..=1.0).contains(&t) { t } else { 0.5 };
        let mut p = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
        p[axis] += t.clamp(END_GAP, 1.0 - END_GAP);
        self.world.transform_point3(p)
    }
}

/// Appends the vertices the slab in `grid` writes and the triangles of its cubes to `out`, its
/// ids counted from `base`.
pub(super) fn emit(grid: &Grid, layout: &Layout, placer: &Placer, base: u32, out: &mut Pieces) {
    let [nx, ny, nz] = grid.dims;
    let writes_last = layout.written == layout.named;
    for k in 0..nz {
        let edges = |j| Edges { grid, placer, j, k };
        if k + 1 < nz || writes_last {
            for j in 0..ny {
                let row = grid.row(j, k);
                edges(j).push(0, |w| along(row, nx, w), &mut out.vertices);
                if j + 1 < ny {
                    let next = grid.row(j + 1, k);
                    edges(j).push(1, |w| row[w] ^ next[w], &mut out.vertices);
                }
            }
        }
        if k + 1 < nz {
            for j in 0..ny {
                let (row, next) = (grid.row(j, k), grid.row(j, k + 1));
                edges(j).push(2, |w| row[w] ^ next[w], &mut out.vertices);
            }
        }
    }
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            row_triangles(grid, layout, base, j, k, &mut out.triangles);
        }
    }
}

/// The edges from the voxels of row `(j, k)` of a slab.
struct Edges<'e> {
    grid: &'e Grid<'e>,
    placer: &'e Placer<'e>,
    j: usize,
    k: usize,
}

impl Edges<'_> {
    /// Appends the vertices on the row's edges along `axis` that are crossed: the edge from
    /// voxel `i` where bit `i % 64` of `crossed(i / 64)` is set.
    fn push(&self, axis: usize, crossed: impl Fn(usize) -> u64, out: &mut Vec<DVec3>) {
        let g = self.grid;
        let v = [g.lo[0], g.lo[1] + self.j, g.lo[2] + self.k];
        for_each_one(g.row(self.j, self.k).len(), crossed, |i| {
            out.push(self.placer.vertex([v[0] + i, v[1], v[2]], axis));
        });
    }
}

/// Appends the triangles of the row of cubes `(j, k)`, ids counted from `base`.
fn row_triangles(
    grid: &Grid,
    layout: &Layout,
    base: u32,
    j: usize,
    k: usize,
    out: &mut Vec<[u32; 3]>,
) {
    let ny = grid.dims[1];
    let cube_row = grid.cube_rows(j, k);
    let row = |dy: usize, dz: usize| layout.row(j + dy, k + dz, ny);
    // The id the next crossed edge would get, for the edges at the cube's lower `i` (the `i`
    // edges, and the `j` and `k` edges with dx = 0; the others are their twins one column on).
    let mut next = [0u32; 12];
    for (o, (dy, dz)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
        next[o] = base + row(dy, dz).vertex;
    }
    for d in 0..2 {
        let y_row = row(0, d);
        next[4 + 2 * d] = base + y_row.vertex + y_row.x;
        next[8 + 2 * d] = base + row(d, 0).z_vertex;
    }
    for case in cube_row.cut() {
        let id = |e: usize| match e {
            5 | 7 | 9 | 11 => next[e - 1] + u32::from(crossed(case, e - 1)),
            _ => next[e],
        };
        let c = &CASES[usize::from(case)];
        out.extend(
            c.triangles[..usize::from(c.count)]
                .iter()
                .map(|t| t.map(|e| id(usize::from(e)))),
        );
        for e in [0, 1, 2, 3, 4, 6, 8, 10] {
            next[e] += u32::from(crossed(case, e));
        }
    }
}
