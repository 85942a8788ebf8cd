//! The lumen's wall as a triangle mesh: marching tetrahedra over the voxel grid, each cube cut
//! into the six tetrahedra around its main diagonal (Kuhn's triangulation, the same on both
//! sides of every face, so the surface has no cracks and needs no ambiguity rule: a closed
//! lumen gives a watertight mesh). Which voxels lie inside is a [`Lumen`] (the component
//! around a seed) or, for the whole volume, the side of the isovalue; each vertex lies on a
//! grid edge (axis, face or cube diagonal) where the trilinear field crosses the isovalue,
//! found exactly on axis edges and by safeguarded regula falsi on the diagonals. Triangles
//! face out of the lumen (into the wall). Slabs of cubes run in parallel; vertices are shared
//! through their edge's index, so the result does not depend on the thread count.

use crate::navigate::{Lumen, LumenSide};
use crate::scene::{MeshError, TriangleMesh};
use crate::Volume;
use glam::DVec3;
use rayon::prelude::*;

/// The six tetrahedra of a cube around its diagonal from corner 0 to corner 7 (corner bits:
/// 1 = +i, 2 = +j, 4 = +k), one per order of the axes.
const TETRAHEDRA: [[u8; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// Regula falsi steps on a diagonal edge at most (converges to float precision in far fewer).
const ROOT_STEPS: usize = 40;

/// The surface of `lumen` at its threshold: the boundary between its voxels and the rest, in
/// world mm (watertight where the lumen does not reach the volume's border). Vertices between
/// a lumen voxel and a diagonal neighbour on the lumen's side outside it (another component)
/// have no crossing and sit at the edge's midpoint.
pub fn lumen_surface(volume: &Volume, lumen: &Lumen) -> Result<TriangleMesh, MeshError> {
    extract(volume, lumen.threshold(), &|v, _| lumen.contains(v))
}

/// The isosurface at `iso` (physical units) of the whole volume, facing away from the voxels on
/// `side` of it, in world mm.
pub fn isosurface(volume: &Volume, iso: f64, side: LumenSide) -> Result<TriangleMesh, MeshError> {
    extract(volume, iso, &|_, value| side.holds(value, iso))
}

/// The surface of the voxels whose value is `label` (a segmentation's region), in world mm,
/// facing out of it: the region's indicator, padded by a voxel of nothing on every side (so a
/// region touching the grid's edge is closed), blurred once by [1, 2, 1] / 4 along each axis
/// and cut at one half — a smooth surface instead of voxel steps, that keeps the region's
/// volume and its place to a fraction of a voxel.
pub fn label_surface(volume: &Volume, label: u16) -> Result<TriangleMesh, MeshError> {
    let [nx, ny, nz] = volume.dims();
    let dims = [nx + 2, ny + 2, nz + 2];
    let mut field = vec![0.0f32; dims.iter().product()];
    let at = |[i, j, k]: [usize; 3]| i + dims[0] * (j + dims[1] * k);
    for (n, &v) in volume.voxels().iter().enumerate() {
        if v == label {
            field[at([n % nx + 1, n / nx % ny + 1, n / (nx * ny) + 1])] = 1.0;
        }
    }
    for axis in 0..3 {
        field = blurred(&field, dims, axis);
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

/// The surface between the voxels for which `inside(voxel, value)` holds and the others.
/// Slabs of cubes list their triangles as grid-edge ids; each edge's vertex is then solved once.
fn extract(
    volume: &Volume,
    iso: f64,
    inside: &(dyn Fn([usize; 3], f64) -> bool + Sync),
) -> Result<TriangleMesh, MeshError> {
    let dims = volume.dims();
    if dims.iter().any(|&n| n < 2) {
        return Err(MeshError::Empty);
    }
    let map = volume.value_map();
    let table: Vec<f64> = (0..=u16::MAX).map(|s| map.physical(s)).collect();
    let field = Field {
        voxels: volume.voxels(),
        table: &table,
        dims,
        iso,
        inside,
    };
    let slabs: Vec<Vec<[u64; 3]>> = (0..dims[2] - 1)
        .into_par_iter()
        .map(|k| field.slab(k))
        .collect();
    let mut edges: Vec<u64> = slabs
        .par_iter()
        .flat_map_iter(|s| s.iter().flatten().copied())
        .collect();
    edges.par_sort_unstable();
    edges.dedup();
    let index = |id: u64| edges.binary_search(&id).unwrap_or(0) as u32;
    let triangles: Vec<[u32; 3]> = slabs
        .par_iter()
        .flat_map_iter(|s| s.iter().map(|t| t.map(index)))
        .collect();
    let g = volume.geometry();
    let vertices = edges
        .par_iter()
        .map(|&id| g.world_of(field.edge_vertex(id)))
        .collect();
    TriangleMesh::new(vertices, triangles)
}

/// The sampled field and the inside test.
struct Field<'a> {
    voxels: &'a [u16],
    table: &'a [f64],
    dims: [usize; 3],
    iso: f64,
    inside: &'a (dyn Fn([usize; 3], f64) -> bool + Sync),
}

impl Field<'_> {
    fn linear(&self, [i, j, k]: [usize; 3]) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    fn value(&self, v: [usize; 3]) -> f64 {
        self.table[usize::from(self.voxels[self.linear(v)])]
    }

    /// The triangles of the cubes `(·, ·, k)`, as the ids of the grid edges their vertices lie
    /// on.
    fn slab(&self, k: usize) -> Vec<[u64; 3]> {
        let mut triangles = Vec::new();
        let [nx, ny, _] = self.dims;
        // The inside flags of planes k and k + 1, computed once.
        let plane = |k: usize| -> Vec<bool> {
            let mut flags = Vec::with_capacity(nx * ny);
            for j in 0..ny {
                for i in 0..nx {
                    let v = [i, j, k];
                    flags.push((self.inside)(v, self.value(v)));
                }
            }
            flags
        };
        let planes = [plane(k), plane(k + 1)];
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let mut flags = 0u8;
                for c in 0..8u8 {
                    let (di, dj, dk) = corner_offset(c);
                    if planes[dk][i + di + nx * (j + dj)] {
                        flags |= 1 << c;
                    }
                }
                if flags != 0 && flags != 0xff {
                    self.cube([i, j, k], flags, &mut triangles);
                }
            }
        }
        triangles
    }

    /// The triangles of the cube at `base` whose inside corners are the bits of `flags`.
    fn cube(&self, base: [usize; 3], flags: u8, triangles: &mut Vec<[u64; 3]>) {
        for tet in TETRAHEDRA {
            let mut split = ([0u8; 4], 0, [0u8; 4], 0);
            for c in tet {
                if flags >> c & 1 == 1 {
                    split.0[split.1] = c;
                    split.1 += 1;
                } else {
                    split.2[split.3] = c;
                    split.3 += 1;
                }
            }
            let (ins, outs) = (&split.0[..split.1], &split.2[..split.3]);
            let mut add = |edges| triangles.push(self.triangle(base, edges, ins, outs));
            match (ins, outs) {
                (&[a], &[b, c, d]) | (&[b, c, d], &[a]) => add([(a, b), (a, c), (a, d)]),
                (&[a, b], &[c, d]) => {
                    add([(a, c), (a, d), (b, d)]);
                    add([(a, c), (b, d), (b, c)]);
                }
                _ => {}
            }
        }
    }

    /// The triangle of the cube at `base` on the corner-pair `edges`, turned to face from the
    /// `ins` corners to the `outs`. The turn is decided on the edges' midpoints: the vertices
    /// lie strictly inside their edges, where a tetrahedron's cut never changes its side.
    fn triangle(
        &self,
        base: [usize; 3],
        edges: [(u8, u8); 3],
        ins: &[u8],
        outs: &[u8],
    ) -> [u64; 3] {
        let points = edges.map(|(p, q)| (local(p) + local(q)) * 0.5);
        let centre = |cs: &[u8]| cs.iter().map(|&c| local(c)).sum::<DVec3>() / cs.len() as f64;
        let outward = centre(outs) - centre(ins);
        let normal = (points[1] - points[0]).cross(points[2] - points[0]);
        let order = if normal.dot(outward) >= 0.0 {
            [0, 1, 2]
        } else {
            [0, 2, 1]
        };
        order.map(|k| self.edge_id(base, edges[k]))
    }

    /// The global id of the grid edge between corners `p` and `q` of the cube at `base`: its
    /// lower voxel's index and the direction bits (Kuhn's edges all run from a corner to one
    /// with more bits set).
    fn edge_id(&self, base: [usize; 3], (p, q): (u8, u8)) -> u64 {
        let (lo, hi) = if p & q == p { (p, q) } else { (q, p) };
        let v = self.linear(corner(base, lo)) as u64;
        v * 8 + u64::from(hi ^ lo)
    }

    /// The voxel position where the trilinear field crosses the isovalue on the grid edge `id`
    /// (from its lower voxel along its direction bits). An edge with no crossing (a neighbour
    /// on the lumen's side outside the lumen) gives its midpoint.
    fn edge_vertex(&self, id: u64) -> DVec3 {
        let (linear, dir) = ((id / 8) as usize, (id % 8) as u8);
        let [nx, ny, _] = self.dims;
        let lo = [linear % nx, linear / nx % ny, linear / (nx * ny)];
        // Only the corners on the edge's face (or cube) enter the field along it.
        let values = std::array::from_fn(|c| {
            let c = c as u8;
            if c & !dir == 0 {
                self.value(corner(lo, c))
            } else {
                0.0
            }
        });
        let cube = Cube {
            values,
            iso: self.iso,
        };
        DVec3::from(lo.map(|v| v as f64)) + cube.crossing(local(dir))
    }
}

/// The field of one cube (its corners' values) and the isovalue.
struct Cube {
    values: [f64; 8],
    iso: f64,
}

impl Cube {
    /// Where the trilinear field crosses the isovalue between corner 0 and the corner at local
    /// position `b` (0–1 per axis), in local coordinates: exact on an axis edge, safeguarded
    /// (Illinois) regula falsi on a diagonal. No crossing gives the midpoint.
    fn crossing(&self, b: DVec3) -> DVec3 {
        let f = |s: f64| self.trilinear(b * s) - self.iso;
        let (mut s0, mut s1) = (0.0, 1.0);
        let far = self.values[(b.x + 2.0 * b.y + 4.0 * b.z) as usize];
        let (mut f0, mut f1) = (self.values[0] - self.iso, far - self.iso);
        if (f0 < 0.0) == (f1 < 0.0) {
            return b * 0.5;
        }
        let linear = |f0: f64, f1: f64| if f1 != f0 { f0 / (f0 - f1) } else { 0.5 };
        if b.element_sum() == 1.0 {
            return b * linear(f0, f1);
        }
        let mut side = 0i8;
        for _ in 0..ROOT_STEPS {
            let s = s0 + (s1 - s0) * linear(f0, f1);
            let fs = f(s);
            if fs == 0.0 || (s1 - s0) < 1e-9 {
                return b * s;
            }
            if (fs < 0.0) == (f0 < 0.0) {
                (s0, f0) = (s, fs);
                if side == -1 {
                    f1 *= 0.5;
                }
                side = -1;
            } else {
                (s1, f1) = (s, fs);
                if side == 1 {
                    f0 *= 0.5;
                }
                side = 1;
            }
        }
        b * (s0 + (s1 - s0) * linear(f0, f1))
    }

    /// The trilinear field at local position `x` (0–1 per axis).
    fn trilinear(&self, x: DVec3) -> f64 {
        let v = &self.values;
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let y0 = lerp(lerp(v[0], v[1], x.x), lerp(v[2], v[3], x.x), x.y);
        let y1 = lerp(lerp(v[4], v[5], x.x), lerp(v[6], v[7], x.x), x.y);
        lerp(y0, y1, x.z)
    }
}

/// Corner `c`'s offsets along i, j, k.
fn corner_offset(c: u8) -> (usize, usize, usize) {
    (
        usize::from(c & 1),
        usize::from(c >> 1 & 1),
        usize::from(c >> 2 & 1),
    )
}

/// Corner `c` of the cube at `base`.
fn corner(base: [usize; 3], c: u8) -> [usize; 3] {
    let (di, dj, dk) = corner_offset(c);
    [base[0] + di, base[1] + dj, base[2] + dk]
}

/// Corner `c`'s local position.
fn local(c: u8) -> DVec3 {
    let (di, dj, dk) = corner_offset(c);
    DVec3::new(di as f64, dj as f64, dk as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};

    #[test]
    fn the_sphere_phantom_gives_a_closed_surface_on_the_isovalue() {
        let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        let c = shell.centre_vox.round();
        let seed = [c.x as usize, c.y as usize, c.z as usize];
        let lumen = Lumen::from_seed(&volume, seed, -480.0, LumenSide::Below).unwrap();
        let mesh = lumen_surface(&volume, &lumen).unwrap();
        assert_eq!(mesh.open_edges(), 0);
        let g = volume.geometry();
        for v in mesh.vertices() {
            let p = g.voxel_from_world().transform_point3(*v);
            let value = volume.sample_physical(p).unwrap();
            // The wall's ramp is about 1000 HU per voxel: 0.1 voxel is 100 HU.
            assert!((value + 480.0).abs() < 5.0, "{value} at {p}");
            let r = p.distance(shell.centre_vox);
            assert!((r - shell.inner_radius_vox).abs() < 0.1, "{r}");
        }
        // Facing out of the lumen: the signed volume is positive.
        let volume_mm3: f64 = (0..mesh.triangles().len())
            .map(|i| {
                let [a, b, c] = mesh.corners(i);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        let sphere = 4.0 / 3.0 * std::f64::consts::PI * shell.inner_radius_vox.powi(3);
        assert!(
            (volume_mm3 / sphere - 1.0).abs() < 0.02,
            "{volume_mm3} vs {sphere}"
        );
    }
}
