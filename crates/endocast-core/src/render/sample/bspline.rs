//! Tricubic B-spline reconstruction for stills (Krüger et al. §4.3, after Sigg & Hadwiger,
//! "Fast Third-Order Texture Filtering"): the value at a position is a cubic B-spline over the
//! 4×4×4 voxels around it, and its gradient is a spline's own derivative — smooth normals where
//! trilinear central differences show the voxel facets.
//!
//! Two splines, each where it measured best on balls of 2.5–11 voxels' radius with the
//! phantoms' two-voxel edge ramp (`bspline_tests`; docs/benchmark-log.md):
//! - **values** (the surface search, its refinement, DVR samples): the *interpolating* spline
//!   (Unser's prefilter of the coefficients), exact at the voxels — radius error 0.016–0.017
//!   voxel RMS at every radius, where trilinear has 0.016–0.072 and the *approximating* spline
//!   (the voxels as coefficients, as Sigg & Hadwiger filter on the GPU) shrinks every convex
//!   surface by about a third of a voxel over its radius (0.031–0.141) and lowers thin walls;
//! - **gradients** (normals): the *approximating* spline's derivative, 0.59–0.67° RMS from
//!   the true normal, where trilinear central differences have 1.7–2.2° and the interpolating
//!   spline's derivative, which rings at the ramp's kinks, 2.9–3.0°.
//!
//! The prefiltered coefficients are a second copy of the volume in `f32` (4 bytes a voxel),
//! built once per renderer when a spline still is first asked for; the gradients read the
//! voxels themselves.

use crate::Volume;
use glam::Vec3;
use rayon::prelude::*;

/// The coefficients of a volume's interpolating tricubic B-spline, in `f32`, in the volume's
/// layout (x fastest).
#[derive(Debug, Clone)]
pub struct BSplineCoefficients {
    dims: [usize; 3],
    coefficients: Vec<f32>,
}

impl BSplineCoefficients {
    /// Bytes the coefficients take per voxel.
    pub const BYTES_PER_VOXEL: usize = size_of::<f32>();

    /// Prefilters `volume`'s voxels (lines along each axis in parallel).
    pub fn new(volume: &Volume) -> Self {
        let dims = volume.dims();
        let mut coefficients: Vec<f32> =
            volume.voxels().par_iter().map(|&v| f32::from(v)).collect();
        prefilter(&mut coefficients, dims);
        Self { dims, coefficients }
    }

    /// The voxel counts the coefficients were built for.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }
}

/// A still's reconstruction of one volume: values from the interpolating spline, gradients
/// from the approximating one (see the module doc).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Spline<'a> {
    footprint: Footprint,
    coefficients: &'a [f32],
    voxels: &'a [u16],
}

impl<'a> Spline<'a> {
    /// The spline of `volume` with its prefiltered `coefficients`.
    ///
    /// # Panics
    ///
    /// When the coefficients were built for a volume of other dimensions.
    pub fn new(volume: &'a Volume, coefficients: &'a BSplineCoefficients) -> Self {
        assert_eq!(
            volume.dims(),
            coefficients.dims,
            "coefficients of another volume"
        );
        Self {
            footprint: Footprint::new(volume.dims()),
            coefficients: &coefficients.coefficients,
            voxels: volume.voxels(),
        }
    }

    /// The interpolating spline's value at voxel position `p` (clamped to the voxel centres'
    /// hull).
    #[inline]
    pub fn value(&self, p: Vec3) -> f32 {
        let (at, t) = self.footprint.at(p);
        let w = t.map(weights);
        at.sum(self.coefficients, |i, j, k| w[0][i] * w[1][j] * w[2][k])
    }

    /// The approximating spline's gradient at voxel position `p` (clamped as [`Self::value`]),
    /// stored units per voxel, voxel index space.
    #[inline]
    pub fn gradient(&self, p: Vec3) -> Vec3 {
        let (at, t) = self.footprint.at(p);
        let (w, d) = (t.map(weights), t.map(derivatives));
        let v = self.voxels;
        Vec3::new(
            at.sum(v, |i, j, k| d[0][i] * w[1][j] * w[2][k]),
            at.sum(v, |i, j, k| w[0][i] * d[1][j] * w[2][k]),
            at.sum(v, |i, j, k| w[0][i] * w[1][j] * d[2][k]),
        )
    }
}

/// A volume's layout as the splines read it.
#[derive(Debug, Clone, Copy)]
struct Footprint {
    dims: [usize; 3],
    /// Memory strides to the next voxel per axis.
    stride: [usize; 3],
    /// Largest position per axis (`n − 1`).
    extent: Vec3,
}

/// The memory offsets of the four voxels per axis around a position.
struct Offsets([[usize; 4]; 3]);

impl Footprint {
    fn new(dims: [usize; 3]) -> Self {
        Self {
            dims,
            stride: [1, dims[0], dims[0] * dims[1]],
            extent: Vec3::from(dims.map(|n| (n - 1) as f32)),
        }
    }

    /// The four voxels per axis around voxel position `p` (clamped to the hull; the ones past
    /// the border mirrored back into the volume) and `p`'s place past the second, per axis
    /// (0–1).
    #[inline]
    fn at(&self, p: Vec3) -> (Offsets, [f32; 3]) {
        let p = p.clamp(Vec3::ZERO, self.extent);
        // p ≥ 0 (or NaN, which `as` maps to 0): truncation is the floor.
        let base = [p.x as i64, p.y as i64, p.z as i64];
        let offsets = std::array::from_fn(|axis| {
            let n = self.dims[axis] as i64;
            std::array::from_fn(|m| mirror(base[axis] - 1 + m as i64, n) * self.stride[axis])
        });
        (
            Offsets(offsets),
            std::array::from_fn(|axis| p[axis] - base[axis] as f32),
        )
    }
}

impl Offsets {
    /// Σ weight(i, j, k) · value over the 4×4×4 voxels (or coefficients) of `values`.
    #[inline]
    fn sum<T: Copy + Into<f32>>(
        &self,
        values: &[T],
        weight: impl Fn(usize, usize, usize) -> f32,
    ) -> f32 {
        let [ix, iy, iz] = &self.0;
        let mut total = 0.0;
        for (k, z) in iz.iter().enumerate() {
            for (j, y) in iy.iter().enumerate() {
                for (i, x) in ix.iter().enumerate() {
                    total += weight(i, j, k) * values[x + y + z].into();
                }
            }
        }
        total
    }
}

/// Index `i` mirrored into `0..n` (whole-sample symmetry: −1 → 1, n → n − 2).
#[inline]
fn mirror(i: i64, n: i64) -> usize {
    if n == 1 {
        return 0;
    }
    let period = 2 * (n - 1);
    let i = i.rem_euclid(period);
    (if i < n { i } else { period - i }) as usize
}

/// The cubic B-spline's weights of the four voxels around a position `t` (0–1) past the
/// second.
#[inline]
fn weights(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    let (t2, t3) = (t * t, t * t * t);
    [
        s * s * s / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
    ]
}

/// The derivatives of [`weights`] by `t`.
#[inline]
fn derivatives(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [
        -0.5 * s * s,
        1.5 * t * t - 2.0 * t,
        -1.5 * t * t + t + 0.5,
        0.5 * t * t,
    ]
}

/// The cubic B-spline's pole, √3 − 2 (Unser's prefilter).
const POLE: f64 = -0.267_949_192_431_122_7;

/// Turns samples into the coefficients of their interpolating cubic B-spline, in place: the
/// causal and anti-causal recursive filters along each axis (Unser 1999, mirror boundaries).
fn prefilter(c: &mut [f32], [nx, ny, nz]: [usize; 3]) {
    // x: rows are contiguous; y: strided lines within a slab.
    c.par_chunks_mut(nx)
        .for_each(|row| filter_strided(row, 0, 1, nx));
    c.par_chunks_mut(nx * ny).for_each(|slab| {
        for i in 0..nx {
            filter_strided(slab, i, nx, ny);
        }
    });
    // z: lines across slabs, filtered a slab column at a time and written back.
    let slab = nx * ny;
    let columns: Vec<Vec<f32>> = (0..slab)
        .into_par_iter()
        .map(|ij| {
            let mut line: Vec<f32> = (0..nz).map(|k| c[ij + slab * k]).collect();
            filter_strided(&mut line, 0, 1, nz);
            line
        })
        .collect();
    for (ij, line) in columns.iter().enumerate() {
        for (k, &v) in line.iter().enumerate() {
            c[ij + slab * k] = v;
        }
    }
}

/// [`filter_line`] on the `n` values `data[start + stride · m]`, in `f64`.
fn filter_strided(data: &mut [f32], start: usize, stride: usize, n: usize) {
    let mut line: Vec<f64> = (0..n)
        .map(|m| f64::from(data[start + stride * m]))
        .collect();
    filter_line(&mut line);
    for (m, v) in line.iter().enumerate() {
        data[start + stride * m] = *v as f32;
    }
}

/// The interpolating prefilter of one line (gain 6, one pole, mirror boundaries).
fn filter_line(c: &mut [f64]) {
    let n = c.len();
    if n < 2 {
        return;
    }
    let z = POLE;
    for v in c.iter_mut() {
        *v *= 6.0;
    }
    c[0] = causal_start(c, z);
    for k in 1..n {
        c[k] += z * c[k - 1];
    }
    c[n - 1] = (z / (z * z - 1.0)) * (z * c[n - 2] + c[n - 1]);
    for k in (0..n - 1).rev() {
        c[k] = z * (c[k + 1] - c[k]);
    }
}

/// The causal filter's first coefficient under mirror boundaries (Unser; the sum truncated
/// where the pole's powers fall below 1e-10).
fn causal_start(c: &[f64], z: f64) -> f64 {
    let n = c.len();
    let horizon = (1e-10f64.ln() / z.abs().ln()).ceil() as usize;
    if horizon < n {
        let mut zn = z;
        let mut sum = c[0];
        for v in &c[1..horizon] {
            sum += zn * v;
            zn *= z;
        }
        return sum;
    }
    let mut zn = z;
    let iz = 1.0 / z;
    let mut z2n = z.powi(n as i32 - 1);
    let mut sum = c[0] + z2n * c[n - 1];
    z2n = z2n.powi(2) * iz;
    for v in &c[1..n - 1] {
        sum += (zn + z2n) * v;
        zn *= z;
        z2n *= iz;
    }
    sum / (1.0 - zn * zn)
}
