//! The helpers every render mode shares: trilinear sampling in stored units, gradients mapped to
//! world-space normals, Blinn-Phong shading with a headlight, and front-to-back compositing.

use super::simd::Avx2;
use super::voxel_grid::VoxelGrid;
pub use super::voxel_grid::{Lanes, SampleGrid};
use crate::Volume;
use glam::{DMat3, Mat3, Vec3, Vec3A};

pub(super) mod bricked;
pub(super) mod bspline;
#[cfg(test)]
mod bspline_tests;

pub use bricked::BrickedVoxels;
pub use bspline::BSplineCoefficients;
use bspline::Spline;

/// Trilinear reconstruction of a volume's stored values, in `f32`, with positions clamped to the
/// voxel centres' hull (so a gradient stencil at the border reads the border value).
///
/// The sample loop's hot spot: everything constant is precomputed here, cell indices are `i32`
/// (a cheap conversion from `f32`, unlike `usize`), and the eight corners are read from one
/// bounds-checked slice of the cell's span.
///
/// Batches of eight samples ([`Sampler::grid8`], [`Sampler::points8`]) run on AVX2 where the
/// CPU has it (detected at run time): one gather per pair of x-neighbours fetches eight cells'
/// corners at once, and the arithmetic is the scalar path's operation for operation (no fused
/// multiply-add), so both give bit-identical values.
///
/// A still may reconstruct by tricubic B-splines instead ([`Self::with_spline`]): then every
/// value and gradient is the spline's, one sample at a time.
#[derive(Debug, Clone, Copy)]
pub struct Sampler<'a> {
    /// The voxels and their layout, as the batches read them.
    grid: VoxelGrid<'a>,
    /// Where batches run on AVX2 (the CPU has it, x has two voxels or more for the paired
    /// gathers, and every index fits the gathers' `i32`).
    avx2: Option<Avx2>,
    /// The B-spline reconstruction, where a still asked for it (no AVX2 batches then).
    spline: Option<Spline<'a>>,
}

impl<'a> Sampler<'a> {
    /// A sampler over `volume`'s voxels.
    pub fn new(volume: &'a Volume) -> Self {
        let nx = volume.dims()[0];
        let fits = i32::try_from(volume.voxels().len()).is_ok();
        Self {
            grid: VoxelGrid::new(volume),
            avx2: Avx2::detect().filter(|_| nx >= 2 && fits),
            spline: None,
        }
    }

    /// A sampler whose batches read `bricked`, the same voxels brick by brick (bit-identical
    /// values; the single samples read the volume).
    /// Falls back to [`Self::new`] where `bricked` holds another shape or too many voxels for
    /// the gathers' `i32` indices.
    pub fn with_bricks(volume: &'a Volume, bricked: &'a BrickedVoxels) -> Self {
        let plain = Self::new(volume);
        let Some(avx2) = Avx2::detect().filter(|_| bricked.fits(volume.dims())) else {
            return plain;
        };
        let bricks = bricked.bricks().map(|b| b as i32);
        Self {
            grid: VoxelGrid {
                bricked: Some((bricked.voxels(), bricks)),
                ..plain.grid
            },
            avx2: Some(avx2),
            spline: None,
        }
    }

    /// A sampler over `volume` reconstructing by its tricubic B-splines, whose prefiltered
    /// `coefficients` are given ([`bspline`]'s module doc says which spline does what).
    ///
    /// # Panics
    ///
    /// When the coefficients were built for a volume of other dimensions.
    pub fn with_spline(volume: &'a Volume, coefficients: &'a BSplineCoefficients) -> Self {
        Self {
            spline: Some(Spline::new(volume, coefficients)),
            ..Self::new(volume).scalar()
        }
    }

    /// The AVX2 token where batches run on AVX2.
    pub(crate) fn avx2(&self) -> Option<Avx2> {
        self.avx2
    }

    /// The voxels and their layout (what the AVX2 batches read).
    pub(crate) fn voxel_grid(&self) -> &VoxelGrid<'a> {
        &self.grid
    }

    /// The same sampler without the AVX2 batches (to compare both paths).
    pub fn scalar(self) -> Self {
        Self { avx2: None, ..self }
    }

    /// Samples `n .. n + count` (`count` ≤ 8) of `grid`; lanes from `count` on are unspecified.
    #[inline]
    pub fn grid8(&self, grid: &SampleGrid, n: i32, count: usize) -> Lanes {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.avx2 {
            return avx2.grid8(&self.grid, grid, n);
        }
        let mut out = [0.0; 8];
        for (lane, value) in (n..).zip(out.iter_mut().take(count)) {
            *value = self.value(grid.at(grid.t_of(lane)));
        }
        out
    }

    /// The values at eight positions given as their x, y and z lanes.
    #[inline]
    pub fn points8(&self, [x, y, z]: &[Lanes; 3]) -> Lanes {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.avx2 {
            return avx2.points8(&self.grid, [x, y, z]);
        }
        std::array::from_fn(|k| self.value(Vec3::new(x[k], y[k], z[k])))
    }

    /// The values at `line.at(t[k])` for the eight distances `t`.
    #[inline]
    pub fn along8(&self, line: &SampleGrid, t: &Lanes) -> Lanes {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.avx2 {
            return avx2.along8(&self.grid, line, t);
        }
        t.map(|t| self.value(line.at(t)))
    }

    /// The reconstructed stored value at voxel position `p`: trilinear, or the spline's.
    #[inline(always)]
    pub fn value(&self, p: Vec3) -> f32 {
        if let Some(spline) = &self.spline {
            return spline.value(p);
        }
        let grid = &self.grid;
        let p = p.clamp(Vec3::ZERO, grid.extent);
        // p ≥ 0, so truncation is the floor; `as i32` saturates and maps NaN to 0.
        let bx = (p.x as i32).min(grid.max_base[0]);
        let by = (p.y as i32).min(grid.max_base[1]);
        let bz = (p.z as i32).min(grid.max_base[2]);
        let (fx, fy, fz) = (p.x - bx as f32, p.y - by as f32, p.z - bz as f32);
        let [_, sy, sz] = grid.stride;
        // bx, by, bz lie in [0, max_base]: the casts are exact.
        let index = bx as usize + by as usize * sy + bz as usize * sz;
        let [low, high] = grid.corners(index);
        // The four lerps along x at once (SIMD lanes: the same IEEE operations as one by one),
        // giving [c00, c10, c01, c11] (c_yz); then y, then z.
        let c = low + (high - low) * fx;
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        lerp(lerp(c.x, c.y, fy), lerp(c.z, c.w, fy), fz)
    }

    /// Gradient of the stored value by central differences one voxel apart (the six samples as
    /// one batch), or the spline's own, stored units per voxel, in voxel index space.
    #[inline]
    pub fn gradient(&self, p: Vec3) -> Vec3 {
        if let Some(spline) = &self.spline {
            return spline.gradient(p);
        }
        // Lanes: +x, −x, +y, −y, +z, −z (and two unused); `p ± 1` along one axis, `p` along the
        // others.
        let plus_minus = |a: f32, lane: usize| {
            let mut lanes = [a; 8];
            lanes[lane] = a + 1.0;
            lanes[lane + 1] = a - 1.0;
            lanes
        };
        let [xp, xm, yp, ym, zp, zm, _, _] =
            self.points8(&[plus_minus(p.x, 0), plus_minus(p.y, 2), plus_minus(p.z, 4)]);
        Vec3::new(xp - xm, yp - ym, zp - zm) * 0.5
    }

    /// [`Self::gradient`] at eight points: six batches, one per stencil offset, instead of one
    /// batch (with two idle lanes) per point.
    pub fn gradients8(&self, points: &[Vec3; 8]) -> [Vec3; 8] {
        // The points as x, y and z lanes once; each stencil moves one axis's lanes.
        let mut lanes = [[0.0f32; 8]; 3];
        for (k, p) in points.iter().enumerate() {
            (lanes[0][k], lanes[1][k], lanes[2][k]) = (p.x, p.y, p.z);
        }
        let [x, y, z] = self.gradients8_lanes(&lanes);
        std::array::from_fn(|k| Vec3::new(x[k], y[k], z[k]))
    }

    /// [`Self::gradients8`] at eight points given as their x, y and z lanes, as x, y and z
    /// lanes.
    #[inline]
    pub fn gradients8_lanes(&self, lanes: &[Lanes; 3]) -> [Lanes; 3] {
        if let Some(spline) = &self.spline {
            let g: [Vec3; 8] = std::array::from_fn(|k| {
                spline.gradient(Vec3::new(lanes[0][k], lanes[1][k], lanes[2][k]))
            });
            return std::array::from_fn(|axis| g.map(|g| g[axis]));
        }
        let lanes = *lanes;
        let at = |axis: usize, offset: f32| {
            let mut moved = lanes;
            for v in &mut moved[axis] {
                *v += offset;
            }
            self.points8(&moved)
        };
        let difference = |axis: usize| {
            let (plus, minus) = (at(axis, 1.0), at(axis, -1.0));
            std::array::from_fn::<f32, 8, _>(|k| (plus[k] - minus[k]) * 0.5)
        };
        // Called in place (not through `array::map`), so that a caller compiled for AVX2
        // inlines the batches too.
        [difference(0), difference(1), difference(2)]
    }
}

/// Phong-style material and light weights (the VTK peer's: ambient 0.25, diffuse 0.7, specular
/// 0.2, exponent 20).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lighting {
    /// Share of the base colour seen without light.
    pub ambient: f32,
    /// Weight of the Lambert term.
    pub diffuse: f32,
    /// Weight of the (white) specular highlight.
    pub specular: f32,
    /// Blinn-Phong exponent.
    pub shininess: f32,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            ambient: 0.25,
            diffuse: 0.7,
            specular: 0.2,
            shininess: 20.0,
        }
    }
}

/// Turns voxel-space gradients into world-space unit normals: the gradient transforms with the
/// inverse transpose of the linear part of `world_from_voxel`, which keeps normals right on
/// sheared and anisotropic grids.
#[derive(Debug, Clone, Copy)]
pub struct Shader {
    world_from_gradient: Mat3,
    lighting: Lighting,
    /// The specular exponent when it is a whole number (the usual case).
    whole_shininess: Option<u32>,
}

impl Shader {
    /// A shader for a volume whose `world_from_voxel` linear part is `linear`.
    pub fn new(linear: DMat3, lighting: Lighting) -> Self {
        Self {
            world_from_gradient: linear.inverse().transpose().as_mat3(),
            lighting,
            whole_shininess: (lighting.shininess.fract() == 0.0 && lighting.shininess >= 0.0)
                .then_some(lighting.shininess as u32),
        }
    }

    /// World-space unit normal for a voxel-space gradient (zero where the gradient is zero).
    #[inline]
    pub fn normal(&self, gradient_vox: Vec3) -> Vec3 {
        (self.world_from_gradient * gradient_vox).normalize_or_zero()
    }

    /// Blinn-Phong with a headlight: the light sits at the eye, so the half vector is the view
    /// direction and both terms depend on |n · d| only (two-sided: the side facing the eye).
    #[inline]
    pub fn shade(&self, base: Vec3, normal: Vec3, ray_dir_world: Vec3) -> Vec3 {
        let l = &self.lighting;
        let n_dot_l = normal.dot(ray_dir_world).abs();
        let power = match self.whole_shininess {
            Some(n) => power_by_squaring(n_dot_l, n),
            None => n_dot_l.powf(l.shininess),
        };
        let specular = l.specular * power;
        (base * (l.ambient + l.diffuse * n_dot_l) + Vec3::splat(specular)).min(Vec3::ONE)
    }
}

/// `x`ⁿ by repeated squaring, inline (`powi` is a library call per hit), in the order of
/// compiler-rt's `__powisf2`, so it gives what `powi` gave.
#[inline]
fn power_by_squaring(mut x: f32, mut n: u32) -> f32 {
    let mut r = 1.0;
    loop {
        if n & 1 == 1 {
            r *= x;
        }
        n /= 2;
        if n == 0 {
            return r;
        }
        x *= x;
    }
}

/// Front-to-back compositing state: premultiplied colour accumulated so far and the
/// transmittance left (1 − opacity). Keeping the transmittance makes each sample's update of the
/// running state one multiplication (`T ← T · (1 − α)`), the only step a ray's samples wait on
/// one another for; the colour adds up beside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accum {
    /// Premultiplied colour.
    pub rgb: Vec3A,
    /// Transmittance: the share of light from behind that still gets through.
    pub transmittance: f32,
}

impl Default for Accum {
    fn default() -> Self {
        Self {
            rgb: Vec3A::ZERO,
            transmittance: 1.0,
        }
    }
}

impl Accum {
    /// Opacity accumulated so far.
    #[inline]
    pub fn alpha(&self) -> f32 {
        1.0 - self.transmittance
    }

    /// Adds a premultiplied colour `rgb` of opacity `alpha` behind what is accumulated.
    #[inline]
    pub fn under(&mut self, rgb: Vec3A, alpha: f32) {
        self.rgb += rgb * self.transmittance;
        self.transmittance *= 1.0 - alpha;
    }

    /// Adds a surface of plain colour `rgb` and opacity `alpha`.
    #[inline]
    pub fn under_surface(&mut self, rgb: Vec3, alpha: f32) {
        self.under(Vec3A::from(rgb) * alpha, alpha);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Geometry, Modality, ValueMap};
    use glam::DVec3;

    #[test]
    fn trilinear_is_exact_on_a_linear_field_and_clamps() {
        let dims = [5, 4, 3];
        let g = Geometry::axis_aligned(dims, DVec3::ONE, DVec3::ZERO).unwrap();
        let field = |i: usize, j: usize, k: usize| (3 * i + 7 * j + 11 * k) as u16;
        let voxels = (0..3)
            .flat_map(|k| (0..4).flat_map(move |j| (0..5).map(move |i| field(i, j, k))))
            .collect();
        let volume = Volume::new(g, voxels, ValueMap::IDENTITY, Modality::Unknown).unwrap();
        let s = Sampler::new(&volume);
        let p = Vec3::new(3.25, 2.5, 1.75);
        assert!((s.value(p) - (3.0 * 3.25 + 7.0 * 2.5 + 11.0 * 1.75)).abs() < 1e-4);
        assert_eq!(s.value(Vec3::new(4.0, 3.0, 2.0)), f32::from(field(4, 3, 2)));
        assert_eq!(s.value(Vec3::splat(-5.0)), 0.0);
        assert_eq!(s.value(Vec3::splat(99.0)), f32::from(field(4, 3, 2)));
        assert!((s.gradient(Vec3::new(2.0, 1.5, 1.0)) - Vec3::new(3.0, 7.0, 11.0)).length() < 1e-4);
        let flat = Volume::new(
            Geometry::axis_aligned([3, 1, 1], DVec3::ONE, DVec3::ZERO).unwrap(),
            vec![0, 10, 20],
            ValueMap::IDENTITY,
            Modality::Unknown,
        )
        .unwrap();
        assert_eq!(Sampler::new(&flat).value(Vec3::new(1.5, 0.3, -2.0)), 15.0);
    }

    #[test]
    fn batches_equal_single_samples_bit_for_bit() {
        use crate::phantom::{self, PhantomOptions};
        let options = PhantomOptions {
            size: 24,
            noise_hu: 40.0,
            ..Default::default()
        };
        let (volume, _) = phantom::sphere_shell(&options);
        let scalar = Sampler::new(&volume).scalar();
        check_batches(Sampler::new(&volume), scalar);
        // (No bricked copy where the CPU has no AVX2 batches.)
        if let Some(bricked) = BrickedVoxels::new(&volume) {
            check_batches(Sampler::with_bricks(&volume, &bricked), scalar);
        }
        // One voxel along x (no x-pairs in the linear layout) and partial bricks.
        let thin = Volume::new(
            Geometry::axis_aligned([1, 21, 35], DVec3::ONE, DVec3::ZERO).unwrap(),
            (0..21 * 35).map(|n| (n * 7919 % 1013) as u16).collect(),
            ValueMap::IDENTITY,
            Modality::Unknown,
        )
        .unwrap();
        if let Some(bricked) = BrickedVoxels::new(&thin) {
            let scalar = Sampler::new(&thin).scalar();
            check_batches(Sampler::with_bricks(&thin, &bricked), scalar);
        }
    }

    /// Asserts that `wide`'s batches equal `scalar`'s single samples bit for bit.
    fn check_batches(wide: Sampler<'_>, scalar: Sampler<'_>) {
        for k in 0..500u16 {
            let f = f32::from(k);
            // Rays from inside and outside the volume, some leaving it (clamped positions).
            let grid = SampleGrid {
                origin: Vec3::new(f % 29.0 - 3.0, f * 0.37 % 26.0 - 1.0, f * 0.71 % 27.0 - 2.0),
                direction: Vec3::new(f.sin(), (1.3 * f).cos(), 0.4).normalize() * 1.1,
                t_start: f % 3.0,
                offset: f * 0.013 % 1.0,
                step: 0.37,
            };
            for n in [0, 5, 40] {
                let lanes = wide.grid8(&grid, n, 8);
                let expected: Vec<f32> = (n..n + 8)
                    .map(|i| scalar.value(grid.at(grid.t_of(i))))
                    .collect();
                assert_eq!(lanes.to_vec(), expected, "{grid:?} {n}");
                assert_eq!(scalar.grid8(&grid, n, 8).to_vec(), expected);
            }
            let t: Lanes = std::array::from_fn(|i| grid.t_of(i as i32 * 7));
            let expected = t.map(|t| scalar.value(grid.at(t)));
            assert_eq!(wide.along8(&grid, &t), expected);
            assert_eq!(scalar.along8(&grid, &t), expected);
        }
        let points: [Vec3; 8] =
            std::array::from_fn(|k| Vec3::new(k as f32 * 2.7, 5.5, 30.1 - k as f32));
        let each = points.map(|p| wide.gradient(p).to_array().map(f32::to_bits));
        assert_eq!(
            wide.gradients8(&points)
                .map(|g| g.to_array().map(f32::to_bits)),
            each
        );
        let nan = [[f32::NAN; 8]; 3];
        assert_eq!(wide.points8(&nan), [scalar.value(Vec3::NAN); 8]);
    }

    #[test]
    fn normals_follow_the_shear() {
        // A sheared grid: the k axis leans towards +y. A field that grows with world z only has
        // a world gradient along z, whatever the voxel-space gradient looks like.
        let lean = DVec3::new(0.0, 0.5, 1.0).normalize();
        let linear = DMat3::from_cols(DVec3::X, DVec3::Y, lean * 2.0);
        let shader = Shader::new(linear, Lighting::default());
        // world z = 2 · lean.z · k, so the voxel gradient of f = world z is (0, 0, 2 lean.z).
        let n = shader.normal(Vec3::new(0.0, 0.0, (2.0 * lean.z) as f32));
        assert!((n - Vec3::Z).length() < 1e-6, "{n}");
        let lit = shader.shade(Vec3::ONE, n, -Vec3::Z);
        assert!((lit - Vec3::ONE).length() < 1e-6);
        assert_eq!(
            shader.shade(Vec3::ONE, Vec3::ZERO, Vec3::Z),
            Vec3::splat(0.25)
        );
    }

    #[test]
    fn power_by_squaring_is_powi() {
        for n in 0..70 {
            for k in 0..=100 {
                let x = k as f32 / 100.0;
                assert_eq!(
                    power_by_squaring(x, n).to_bits(),
                    x.powi(n as i32).to_bits()
                );
            }
        }
    }

    #[test]
    fn compositing_is_front_to_back() {
        let mut acc = Accum::default();
        acc.under_surface(Vec3::X, 0.5);
        acc.under_surface(Vec3::Y, 0.5);
        assert_eq!(acc.alpha(), 0.75);
        assert_eq!(acc.rgb, Vec3A::new(0.5, 0.25, 0.0));
    }
}
