//! The exact Euclidean distance transform of a lumen: every lumen voxel's distance (mm) to the
//! nearest voxel that is not lumen.
//!
//! The transform is separable (Felzenszwalb & Huttenlocher's lower envelope of parabolas): the
//! squared distance is computed one index axis at a time, each line in linear time, with the
//! spacing of that axis, so anisotropic voxels are exact too. Distances are measured between
//! voxel *centres*: a lumen voxel's value is the distance to the centre of the nearest wall voxel,
//! which lies up to half a voxel beyond the wall's actual surface (the threshold crossing). On a
//! sheared grid (gantry tilt) the index axes are treated as orthogonal with their spacings, an
//! approximation of a few percent at the usual tilts.
//!
//! The field covers the lumen's bounding box grown by one voxel on each side, so every line
//! starts and ends on a non-lumen voxel; voxels beyond the volume's border count as wall. Values
//! are `f32` millimetres: 4 bytes per voxel of that box, and twice that while it is computed.

use super::lumen::Lumen;
use crate::Geometry;
use glam::{DAffine3, DVec3};
use rayon::prelude::*;

/// Distance to the wall (mm) of every voxel of a lumen's bounding box (0 outside the lumen).
#[derive(Debug, Clone)]
pub struct DistanceField {
    /// Volume voxel index of the field's voxel (0, 0, 0): the lumen's lowest corner less one.
    origin: [isize; 3],
    dims: [usize; 3],
    values_mm: Vec<f32>,
    world_from_voxel: DAffine3,
    voxel_from_world: DAffine3,
    spacing_mm: DVec3,
    max_mm: f64,
    max_voxel: [usize; 3],
}

impl DistanceField {
    /// The distance field of `lumen`, found in a volume of the given `geometry` (the lumen's own
    /// volume's: only its spacing and placement are used). Lines run in parallel.
    pub fn new(lumen: &Lumen, geometry: &Geometry) -> Self {
        let (lo, hi) = lumen.bounds();
        let dims = [0, 1, 2].map(|a| hi[a] - lo[a] + 3);
        let origin = lo.map(|l| l as isize - 1);
        let values_mm = exact_edt(lumen, dims, geometry.spacing_mm());
        let (max_mm, max_index) = values_mm
            .par_iter()
            .enumerate()
            .map(|(n, &d)| (d, n))
            .reduce(
                || (0.0, usize::MAX),
                |a, b| {
                    if b.0 > a.0 || (b.0 == a.0 && b.1 < a.1) {
                        b
                    } else {
                        a
                    }
                },
            );
        let local = [
            max_index % dims[0],
            max_index / dims[0] % dims[1],
            max_index / (dims[0] * dims[1]),
        ];
        Self {
            origin,
            dims,
            values_mm,
            world_from_voxel: geometry.world_from_voxel(),
            voxel_from_world: geometry.voxel_from_world(),
            spacing_mm: geometry.spacing_mm(),
            max_mm: f64::from(max_mm),
            max_voxel: [0, 1, 2].map(|a| (local[a] as isize + origin[a]) as usize),
        }
    }

    /// Distance (mm) of voxel `v` (volume index) to the nearest wall voxel centre; 0 for voxels
    /// outside the lumen.
    pub fn distance_at_voxel(&self, v: [usize; 3]) -> f64 {
        let local = [0, 1, 2].map(|a| (v[a] as isize).wrapping_sub(self.origin[a]) as usize);
        if (0..3).all(|a| local[a] < self.dims[a]) {
            f64::from(self.values_mm[self.index(local)])
        } else {
            0.0
        }
    }

    /// Distance (mm) to the wall at a world point (mm, LPS): the trilinear interpolation of the
    /// voxel values, so 0 at and beyond the centres of wall voxels, and outside the lumen's box.
    pub fn distance_mm(&self, p_mm: DVec3) -> f64 {
        self.sample(self.local_of(p_mm))
    }

    /// The gradient of [`DistanceField::distance_mm`] at a world point, in mm per mm (world
    /// axes): it points away from the nearest wall, with a length near 1 except on the lumen's
    /// medial axis, where it vanishes. Central differences half a voxel to each side.
    pub fn gradient(&self, p_mm: DVec3) -> DVec3 {
        let p = self.local_of(p_mm);
        let h = 0.5;
        let along = |e: DVec3| (self.sample(p + e * h) - self.sample(p - e * h)) / (2.0 * h);
        let per_index = DVec3::new(along(DVec3::X), along(DVec3::Y), along(DVec3::Z));
        // d/dworld = (dvoxel/dworld)ᵀ · d/dvoxel.
        self.voxel_from_world.matrix3.transpose() * per_index
    }

    /// The largest distance in the lumen, mm.
    pub fn max_mm(&self) -> f64 {
        self.max_mm
    }

    /// The voxel (volume index) of the largest distance: the lowest linear index among ties.
    pub fn max_voxel(&self) -> [usize; 3] {
        self.max_voxel
    }

    /// World position (mm) of the centre of voxel `v` (volume index).
    pub fn world_of_voxel(&self, v: [usize; 3]) -> DVec3 {
        self.world_from_voxel
            .transform_point3(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
    }

    /// The continuous volume voxel index of a world point (mm).
    pub fn voxel_of_world(&self, p_mm: DVec3) -> DVec3 {
        self.voxel_from_world.transform_point3(p_mm)
    }

    /// The smallest voxel spacing, mm.
    pub fn min_spacing_mm(&self) -> f64 {
        self.spacing_mm.min_element()
    }

    /// Length of the diagonal of the field's box, mm: no path inside the lumen is straighter.
    pub fn diagonal_mm(&self) -> f64 {
        let d = self.dims.map(|n| n as f64);
        (DVec3::new(d[0], d[1], d[2]) * self.spacing_mm).length()
    }

    /// Bytes held by the distance values.
    pub fn bytes(&self) -> usize {
        self.values_mm.len() * size_of::<f32>()
    }

    #[inline]
    fn index(&self, [i, j, k]: [usize; 3]) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// The continuous field index of a world point.
    fn local_of(&self, p_mm: DVec3) -> DVec3 {
        let o = DVec3::new(
            self.origin[0] as f64,
            self.origin[1] as f64,
            self.origin[2] as f64,
        );
        self.voxel_from_world.transform_point3(p_mm) - o
    }

    /// Trilinear interpolation at a continuous field index; 0 outside the field or for NaN.
    fn sample(&self, p: DVec3) -> f64 {
        let max = DVec3::new(
            (self.dims[0] - 1) as f64,
            (self.dims[1] - 1) as f64,
            (self.dims[2] - 1) as f64,
        );
        if !p.is_finite() || p.cmplt(DVec3::ZERO).any() || p.cmpgt(max).any() {
            return 0.0;
        }
        // Every field dimension is at least 3 (the box plus two margins), so max − 1 ≥ 1.
        let base = p.floor().min(max - 1.0);
        let f = p - base;
        let b = [base.x as usize, base.y as usize, base.z as usize];
        let at =
            |di, dj, dk| f64::from(self.values_mm[self.index([b[0] + di, b[1] + dj, b[2] + dk])]);
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let c00 = lerp(at(0, 0, 0), at(1, 0, 0), f.x);
        let c10 = lerp(at(0, 1, 0), at(1, 1, 0), f.x);
        let c01 = lerp(at(0, 0, 1), at(1, 0, 1), f.x);
        let c11 = lerp(at(0, 1, 1), at(1, 1, 1), f.x);
        lerp(lerp(c00, c10, f.y), lerp(c01, c11, f.y), f.z)
    }
}

/// The distance (mm) of every voxel of the `dims` box (the lumen's box grown by one) to the
/// nearest non-lumen voxel. Three passes, each writing lines contiguously into a buffer laid out
/// for it (so lines run in parallel without sharing): along `k` into `[k][i][j]` order, along `j`
/// into `[j][i][k]`, along `i` into the final `[i][j][k]` (`i` fastest).
fn exact_edt(lumen: &Lumen, dims: [usize; 3], spacing_mm: DVec3) -> Vec<f32> {
    let [nx, ny, nz] = dims;
    let n = nx * ny * nz;
    let mut along_k = vec![0f32; n];
    along_k
        .par_chunks_mut(nz)
        .enumerate()
        .for_each(|(column, out)| {
            let (i, j) = ((column % nx) as isize, (column / nx) as isize);
            let inside = |k: usize| lumen.contains_in_box([i - 1, j - 1, k as isize - 1]);
            binary_line(inside, out, spacing_mm.z);
        });
    let mut along_j = vec![0f32; n];
    along_j.par_chunks_mut(ny).enumerate().for_each_init(
        || Envelope::new(ny),
        |envelope, (line, out)| {
            let (i, k) = (line % nx, line / nx);
            envelope.transform(|j| along_k[k + nz * (i + nx * j)], out, spacing_mm.y);
        },
    );
    drop(along_k);
    let mut squared = vec![0f32; n];
    squared.par_chunks_mut(nx).enumerate().for_each_init(
        || Envelope::new(nx),
        |envelope, (line, out)| {
            let (j, k) = (line % ny, line / ny);
            envelope.transform(|i| along_j[j + ny * (i + nx * k)], out, spacing_mm.x);
            out.iter_mut().for_each(|d| *d = d.sqrt());
        },
    );
    squared
}

/// First pass: the squared distance (mm²) along one line from each voxel to the nearest
/// non-lumen voxel on it. The line's first and last voxels are margin, never lumen, so every
/// voxel gets a finite value.
fn binary_line(inside: impl Fn(usize) -> bool, out: &mut [f32], spacing_mm: f64) {
    let n = out.len();
    let mut last_wall = 0;
    for (q, value) in out.iter_mut().enumerate() {
        if !inside(q) {
            last_wall = q;
        }
        *value = (q - last_wall) as f32;
    }
    let mut next_wall = n - 1;
    for q in (0..n).rev() {
        if !inside(q) {
            next_wall = q;
        }
        let steps = f64::from(out[q]).min((next_wall - q) as f64) * spacing_mm;
        out[q] = (steps * steps) as f32;
    }
}

/// Scratch space of the 1-D transform: the lower envelope of the parabolas
/// `y = f(q) + (x − x_q)²` rooted at each sample `x_q = q · spacing`.
struct Envelope {
    f: Vec<f64>,
    /// Samples whose parabolas form the envelope, left to right.
    roots: Vec<usize>,
    /// `bounds[m]..bounds[m + 1]` is where parabola `roots[m]` is lowest (mm).
    bounds: Vec<f64>,
}

impl Envelope {
    fn new(n: usize) -> Self {
        Self {
            f: vec![0.0; n],
            roots: vec![0; n],
            bounds: vec![0.0; n + 1],
        }
    }

    /// `out[q] = min_p f(p) + ((q − p) · spacing)²` for the line `f` (squared mm), in O(n).
    fn transform(&mut self, f: impl Fn(usize) -> f32, out: &mut [f32], spacing_mm: f64) {
        let n = out.len();
        for q in 0..n {
            self.f[q] = f64::from(f(q));
        }
        let x = |q: usize| q as f64 * spacing_mm;
        let mut top = 0;
        self.roots[0] = 0;
        self.bounds[0] = f64::NEG_INFINITY;
        self.bounds[1] = f64::INFINITY;
        for q in 1..n {
            loop {
                let p = self.roots[top];
                // Where parabola q starts to undercut parabola p.
                let s =
                    ((self.f[q] + x(q) * x(q)) - (self.f[p] + x(p) * x(p))) / (2.0 * (x(q) - x(p)));
                if s <= self.bounds[top] && top > 0 {
                    top -= 1;
                } else {
                    top += 1;
                    self.roots[top] = q;
                    self.bounds[top] = s;
                    self.bounds[top + 1] = f64::INFINITY;
                    break;
                }
            }
        }
        let mut m = 0;
        for (q, value) in out.iter_mut().enumerate() {
            while self.bounds[m + 1] < x(q) {
                m += 1;
            }
            let p = self.roots[m];
            let dx = x(q) - x(p);
            *value = (dx * dx + self.f[p]) as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::navigate::lumen::LumenSide;
    use crate::navigate::test_util::random_volume;
    use crate::phantom::{self, PhantomOptions};

    /// Brute force: the distance from every lumen voxel to every non-lumen voxel of the volume
    /// grown by one voxel (the border beyond counts as wall).
    fn brute_force(lumen: &Lumen, dims: [usize; 3], spacing: DVec3) -> Vec<([usize; 3], f64)> {
        let walls: Vec<DVec3> = (-1..=dims[2] as isize)
            .flat_map(|k| {
                (-1..=dims[1] as isize)
                    .flat_map(move |j| (-1..=dims[0] as isize).map(move |i| [i, j, k]))
            })
            .filter(|v| {
                let inside = (0..3).all(|a| v[a] >= 0 && (v[a] as usize) < dims[a]);
                !(inside && lumen.contains(v.map(|x| x as usize)))
            })
            .map(|v| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64) * spacing)
            .collect();
        lumen
            .voxels()
            .map(|v| {
                let p = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64) * spacing;
                let d = walls
                    .iter()
                    .map(|w| w.distance(p))
                    .fold(f64::INFINITY, f64::min);
                (v, d)
            })
            .collect()
    }

    #[test]
    fn equals_brute_force_on_random_volumes() {
        let cases = [
            ([14, 12, 10], DVec3::ONE, 0.75),
            ([16, 9, 11], DVec3::new(0.7, 1.3, 2.1), 0.8),
            ([9, 15, 12], DVec3::new(2.5, 0.4, 1.0), 0.9),
            ([20, 20, 6], DVec3::new(0.5, 0.5, 3.0), 0.95),
        ];
        for (seed, (dims, spacing, fraction)) in cases.into_iter().enumerate() {
            let volume = random_volume(dims, spacing, seed as u64, fraction);
            let lumen = Lumen::largest(&volume, 0.0, LumenSide::Below, false)
                .unwrap()
                .unwrap();
            let field = DistanceField::new(&lumen, volume.geometry());
            let mut worst: f64 = 0.0;
            for (v, expected) in brute_force(&lumen, dims, spacing) {
                worst = worst.max((field.distance_at_voxel(v) - expected).abs());
            }
            assert!(worst < 1e-4, "case {seed}: worst error {worst} mm");
            // Non-lumen voxels are 0; the maximum is where it says.
            let wall = (0..dims[0])
                .flat_map(|i| (0..dims[1]).map(move |j| [i, j, dims[2] / 2]))
                .find(|&v| !lumen.contains(v))
                .unwrap();
            assert_eq!(field.distance_at_voxel(wall), 0.0);
            assert_eq!(field.distance_at_voxel(field.max_voxel()), field.max_mm());
        }
    }

    #[test]
    fn interpolation_and_gradient_in_the_tube() {
        let (volume, tube) = phantom::straight_tube(&PhantomOptions {
            size: 48,
            ..Default::default()
        });
        let lumen = Lumen::from_seed(&volume, [24, 24, 24], -480.0, LumenSide::Below).unwrap();
        let field = DistanceField::new(&lumen, volume.geometry());
        let g = volume.geometry();
        let axis = g.world_of(tube.centreline.point_at(24.0));
        // On the axis the distance to the nearest wall voxel centre is the radius, give or take
        // the voxel lattice: wall centres lie beyond the surface, by less than a voxel, and the
        // axis lies between voxel centres (up to √2/2 voxel from them).
        let d = field.distance_mm(axis);
        assert!((d - tube.radius_vox).abs() < 1.0, "{d}");
        // Off-axis the gradient points radially inwards, away from the wall.
        let off = axis + DVec3::new(4.0, 3.0, 0.0);
        let grad = field.gradient(off);
        let inward = -DVec3::new(4.0, 3.0, 0.0).normalize();
        assert!(grad.normalize().dot(inward) > 0.95, "{grad}");
        assert!((grad.length() - 1.0).abs() < 0.25, "{grad}");
        assert_eq!(field.distance_mm(DVec3::splat(1e6)), 0.0);
        assert_eq!(field.distance_mm(DVec3::NAN), 0.0);
    }
}
