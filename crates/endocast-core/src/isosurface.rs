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

/// The surface between the voxels for which `inside(voxel, value)` holds and the others.
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
    let slabs: Vec<Slab> = (0..dims[2] - 1)
        .into_par_iter()
        .map(|k| field.slab(k))
        .collect();
    let mut edges: Vec<(u64, DVec3)> = slabs.iter().flat_map(|s| s.edges.iter().copied()).collect();
    edges.par_sort_unstable_by_key(|e| e.0);
    edges.dedup_by_key(|e| e.0);
    let index = |id: u64| edges.binary_search_by_key(&id, |e| e.0).unwrap_or(0) as u32;
    let triangles: Vec<[u32; 3]> = slabs
        .par_iter()
        .flat_map_iter(|s| s.triangles.iter().map(|t| t.map(index)))
        .collect();
    let g = volume.geometry();
    let vertices = edges.iter().map(|e| g.world_of(e.1)).collect();
    TriangleMesh::new(vertices, triangles)
}

/// One slab's share: the edges it put vertices on (id, voxel position) and its triangles as
/// edge ids.
struct Slab {
    edges: Vec<(u64, DVec3)>,
    triangles: Vec<[u64; 3]>,
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

    /// The cubes `(·, ·, k)`.
    fn slab(&self, k: usize) -> Slab {
        let mut slab = Slab {
            edges: Vec::new(),
            triangles: Vec::new(),
        };
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
                    self.cube([i, j, k], flags, &mut slab);
                }
            }
        }
        slab
    }

    /// The triangles of the cube at `base` whose inside corners are the bits of `flags`.
    fn cube(&self, base: [usize; 3], flags: u8, slab: &mut Slab) {
        let values: [f64; 8] = std::array::from_fn(|c| self.value(corner(base, c as u8)));
        let cube = Cube {
            field: self,
            base,
            values,
        };
        for tet in TETRAHEDRA {
            let (ins, outs): (Vec<u8>, Vec<u8>) = tet.iter().partition(|&&c| flags >> c & 1 == 1);
            match (ins.as_slice(), outs.as_slice()) {
                ([a], [b, c, d]) | ([b, c, d], [a]) => {
                    let edges = [(*a, *b), (*a, *c), (*a, *d)];
                    cube.triangle(edges, &ins, &outs, slab);
                }
                ([a, b], [c, d]) => {
                    let (ac, ad, bd, bc) = ((*a, *c), (*a, *d), (*b, *d), (*b, *c));
                    cube.triangle([ac, ad, bd], &ins, &outs, slab);
                    cube.triangle([ac, bd, bc], &ins, &outs, slab);
                }
                _ => {}
            }
        }
    }
}

/// One cube being cut: its lowest voxel and its corners' values.
struct Cube<'a> {
    field: &'a Field<'a>,
    base: [usize; 3],
    values: [f64; 8],
}

impl Cube<'_> {
    /// Adds the triangle on the corner-pair `edges`, turned to face from the `ins` corners to
    /// the `outs`.
    fn triangle(&self, edges: [(u8, u8); 3], ins: &[u8], outs: &[u8], slab: &mut Slab) {
        let points = edges.map(|(p, q)| self.vertex(p, q));
        let centre = |cs: &[u8]| cs.iter().map(|&c| local(c)).sum::<DVec3>() / cs.len() as f64;
        let outward = centre(outs) - centre(ins);
        let normal = (points[1] - points[0]).cross(points[2] - points[0]);
        let order = if normal.dot(outward) >= 0.0 {
            [0, 1, 2]
        } else {
            [0, 2, 1]
        };
        let base = DVec3::from(self.base.map(|v| v as f64));
        let mut ids = [0u64; 3];
        for (slot, &k) in ids.iter_mut().zip(&order) {
            let (p, q) = edges[k];
            let id = self.edge_id(p, q);
            slab.edges.push((id, base + points[k]));
            *slot = id;
        }
        slab.triangles.push(ids);
    }

    /// The global id of the grid edge between corners `p` and `q`: its lower voxel's index
    /// and the direction bits (Kuhn's edges all run from a corner to one with more bits set).
    fn edge_id(&self, p: u8, q: u8) -> u64 {
        let (lo, hi) = if p & q == p { (p, q) } else { (q, p) };
        let v = self.field.linear(corner(self.base, lo)) as u64;
        v * 8 + u64::from(hi ^ lo)
    }

    /// Where the trilinear field crosses the isovalue between corners `p` and `q`, in the
    /// cube's local coordinates (0–1). A pair with no crossing (a neighbour on the lumen's
    /// side outside the lumen) gives the midpoint.
    fn vertex(&self, p: u8, q: u8) -> DVec3 {
        let (a, b) = (local(p), local(q));
        let iso = self.field.iso;
        let f = |s: f64| self.trilinear(a + (b - a) * s) - iso;
        let (mut s0, mut s1) = (0.0, 1.0);
        let (mut f0, mut f1) = (self.values[p as usize] - iso, self.values[q as usize] - iso);
        if (f0 < 0.0) == (f1 < 0.0) {
            return a + (b - a) * 0.5;
        }
        let linear = |f0: f64, f1: f64| if f1 != f0 { f0 / (f0 - f1) } else { 0.5 };
        if (p ^ q).count_ones() == 1 {
            return a + (b - a) * linear(f0, f1);
        }
        // Illinois regula falsi: the bracket always holds the crossing.
        let mut side = 0i8;
        for _ in 0..ROOT_STEPS {
            let s = s0 + (s1 - s0) * linear(f0, f1);
            let fs = f(s);
            if fs == 0.0 || (s1 - s0) < 1e-9 {
                return a + (b - a) * s;
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
        a + (b - a) * (s0 + (s1 - s0) * linear(f0, f1))
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
