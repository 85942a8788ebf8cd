//! The shape of the wall at a voxel: principal curvatures of the isosurface of the
//! Gaussian-smoothed volume through the voxel, from the smoothed volume's gradient and Hessian
//! (the implicit-surface formulas of Thirion & Gourdon, as Yoshida & Näppi 2001 use them), and
//! from them the shape index and the curvedness.

use crate::navigate::LumenSide;
use crate::Volume;
use glam::{DMat3, DVec3};

/// Smoothing kernels reach this many standard deviations on each side.
const KERNEL_SIGMAS: f64 = 3.0;
/// How far from a wall voxel toward the lumen its surface point is sought, voxels (a wall
/// voxel touches a lumen voxel: the isosurface lies within a voxel's diagonal of it).
const SURFACE_SEARCH_VOX: f64 = 1.75;

/// The surface shape at one wall voxel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceShape {
    /// Shape index in [0, 1]: 1 a cap (a bump into the lumen), 0.75 a ridge, 0.5 a saddle,
    /// 0.25 a rut (the wall of a tube seen from inside), 0 a cup; 0.5 where the surface is flat.
    pub shape_index: f64,
    /// Curvedness, 1/mm: √((k1² + k2²)/2), the inverse radius of a sphere for a cap.
    pub curvedness: f64,
    /// Unit normal into the lumen, world (LPS) axes; zero where the smoothed volume is flat.
    pub normal: DVec3,
}

/// Gaussian derivative filters (orders 0, 1, 2) along each index axis, for a smoothing of
/// `sigma_mm` on the volume's spacing.
pub(crate) struct Kernels {
    /// Per axis, the three filters (value, first and second derivative per mm and mm²).
    taps: [[Vec<f64>; 3]; 3],
    /// Per axis, the filters' half width, voxels.
    reach: [usize; 3],
}

impl Kernels {
    /// Filters for `sigma_mm` (positive, finite) on a grid of `spacing_mm`.
    pub(crate) fn new(sigma_mm: f64, spacing_mm: DVec3) -> Self {
        let axis = |a: usize| {
            let sigma = sigma_mm / spacing_mm[a];
            let reach = (KERNEL_SIGMAS * sigma).ceil().max(1.0) as usize;
            (filters(sigma, reach, spacing_mm[a]), reach)
        };
        let (x, y, z) = (axis(0), axis(1), axis(2));
        Self {
            taps: [x.0, y.0, z.0],
            reach: [x.1, y.1, z.1],
        }
    }
}

/// The three filters of standard deviation `sigma` voxels over `-reach..=reach`, with the
/// discrete moments that make them exact on polynomials: the value filter sums to 1, the first
/// derivative gives 1/mm on `x` mm, the second 1/mm² on `x²/2` and 0 on a constant.
fn filters(sigma: f64, reach: usize, spacing_mm: f64) -> [Vec<f64>; 3] {
    let xs: Vec<f64> = (-(reach as isize)..=reach as isize)
        .map(|x| x as f64)
        .collect();
    let g: Vec<f64> = xs
        .iter()
        .map(|x| (-x * x / (2.0 * sigma * sigma)).exp())
        .collect();
    let total: f64 = g.iter().sum();
    let g: Vec<f64> = g.iter().map(|w| w / total).collect();
    let moment = |p: i32| -> f64 { xs.iter().zip(&g).map(|(x, w)| x.powi(p) * w).sum() };
    let (m2, m4) = (moment(2), moment(4));
    let first = xs
        .iter()
        .zip(&g)
        .map(|(x, w)| x * w / (m2 * spacing_mm))
        .collect();
    let second = xs
        .iter()
        .zip(&g)
        .map(|(x, w)| (x * x - m2) * w / ((m4 - m2 * m2) / 2.0 * spacing_mm * spacing_mm))
        .collect();
    [g, first, second]
}

/// The smoothed volume's gradient (per mm) and Hessian (per mm²) at voxel `v`, along the index
/// axes (scaled to mm), by separable Gaussian derivative filters; the grid's edges are repeated.
pub(crate) fn derivatives(volume: &Volume, kernels: &Kernels, v: [usize; 3]) -> (DVec3, DMat3) {
    let dims = volume.dims();
    let voxels = volume.voxels();
    let [rx, ry, rz] = kernels.reach;
    let at =
        |a: usize, offset: isize| (v[a] as isize + offset).clamp(0, dims[a] as isize - 1) as usize;
    // Along x: three filters for each (z, y) row; along y: the six (x, y) orders needed.
    let mut xy = vec![[0.0f64; 6]; 2 * rz + 1];
    for (zn, row_z) in xy.iter_mut().enumerate() {
        let k = at(2, zn as isize - rz as isize);
        for yn in 0..=2 * ry {
            let j = at(1, yn as isize - ry as isize);
            let row = (k * dims[1] + j) * dims[0];
            let mut x = [0.0f64; 3];
            for xn in 0..=2 * rx {
                let value = f64::from(voxels[row + at(0, xn as isize - rx as isize)]);
                for (order, sum) in x.iter_mut().enumerate() {
                    *sum += kernels.taps[0][order][xn] * value;
                }
            }
            let wy = |order: usize| kernels.taps[1][order][yn];
            // Orders (x, y): (0,0) (1,0) (2,0) (0,1) (1,1) (0,2).
            let terms = [
                x[0] * wy(0),
                x[1] * wy(0),
                x[2] * wy(0),
                x[0] * wy(1),
                x[1] * wy(1),
                x[0] * wy(2),
            ];
            for (sum, term) in row_z.iter_mut().zip(terms) {
                *sum += term;
            }
        }
    }
    let along_z = |xy_order: usize, z_order: usize| -> f64 {
        xy.iter()
            .zip(&kernels.taps[2][z_order])
            .map(|(row, w)| row[xy_order] * w)
            .sum()
    };
    let scale = volume.value_map().scale();
    let gradient = DVec3::new(along_z(1, 0), along_z(3, 0), along_z(0, 1)) * scale;
    let (hxy, hxz, hyz) = (along_z(4, 0), along_z(1, 1), along_z(3, 1));
    let hessian = DMat3::from_cols(
        DVec3::new(along_z(2, 0), hxy, hxz),
        DVec3::new(hxy, along_z(5, 0), hyz),
        DVec3::new(hxz, hyz, along_z(0, 2)),
    ) * scale;
    (gradient, hessian)
}

/// Where the isosurface at `threshold` of the unsmoothed volume crosses the segment from voxel
/// `v` [`SURFACE_SEARCH_VOX`] toward the lumen along `toward_lumen` (index axes), by linear
/// interpolation of the trilinear values at its ends, voxel index; the voxel itself where the
/// segment does not cross it.
pub(crate) fn surface_vox(
    volume: &Volume,
    v: [usize; 3],
    threshold: f64,
    toward_lumen: DVec3,
) -> DVec3 {
    let here = DVec3::from(v.map(|c| c as f64));
    let end = here + toward_lumen.normalize_or_zero() * SURFACE_SEARCH_VOX;
    match (volume.sample_physical(here), volume.sample_physical(end)) {
        (Some(a), Some(b)) if (a - threshold) * (b - threshold) <= 0.0 && a != b => {
            here.lerp(end, (a - threshold) / (a - b))
        }
        _ => here,
    }
}

/// The unit normal into the lumen (on `side` of the wall) of the unsmoothed isosurface at `p`
/// (voxel index), world axes: from the trilinear values' central differences half a voxel
/// either side; zero where they are flat or leave the grid.
pub(crate) fn raw_normal(volume: &Volume, p: DVec3, side: LumenSide) -> DVec3 {
    let geometry = volume.geometry();
    let spacing = geometry.spacing_mm();
    let difference = |a: usize| {
        let e = DVec3::AXES[a] * 0.5;
        Some((volume.sample_physical(p + e)? - volume.sample_physical(p - e)?) / spacing[a])
    };
    match (difference(0), difference(1), difference(2)) {
        (Some(x), Some(y), Some(z)) => {
            let rising = geometry.direction() * DVec3::new(x, y, z);
            (rising * -rising_away(side)).normalize_or_zero()
        }
        _ => DVec3::ZERO,
    }
}

/// 1 where the value rises away from a lumen on `side` of the wall (a dark lumen), else −1.
pub(crate) fn rising_away(side: LumenSide) -> f64 {
    match side {
        LumenSide::Below => 1.0,
        LumenSide::Above => -1.0,
    }
}

/// The surface shape from the gradient and Hessian of the value along orthonormal axes (mm),
/// for a lumen on `side` of the wall, the normal turned to world axes by `direction`.
/// Curvatures are positive where the surface is convex seen from the lumen.
pub(crate) fn shape(
    gradient: DVec3,
    hessian: DMat3,
    side: LumenSide,
    direction: DMat3,
) -> SurfaceShape {
    // Make the value rise away from the lumen: then a bump into the lumen has positive mean
    // curvature in the formulas below.
    let sign = rising_away(side);
    let (g, h) = (gradient * sign, hessian * sign);
    let g2 = g.length_squared();
    if !(g2.is_finite() && g2 > 0.0) {
        return SurfaceShape {
            shape_index: 0.5,
            curvedness: 0.0,
            normal: DVec3::ZERO,
        };
    }
    let norm = g2.sqrt();
    let mean = (g.dot(h * g) - g2 * (h.x_axis.x + h.y_axis.y + h.z_axis.z)) / (2.0 * g2 * norm);
    let gauss = g.dot(adjugate(h) * g) / (g2 * g2);
    let spread = (mean * mean - gauss).max(0.0).sqrt();
    let (k1, k2) = (mean + spread, mean - spread);
    SurfaceShape {
        shape_index: 0.5 + (k1 + k2).atan2(k1 - k2) / std::f64::consts::PI,
        curvedness: ((k1 * k1 + k2 * k2) / 2.0).sqrt(),
        normal: (direction * -g).normalize_or_zero(),
    }
}

/// The adjugate of a symmetric matrix (det(h) · h⁻¹ where h is invertible).
fn adjugate(h: DMat3) -> DMat3 {
    let (a, b, c) = (h.x_axis, h.y_axis, h.z_axis);
    DMat3::from_cols(b.cross(c), c.cross(a), a.cross(b)).transpose()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The value of a ball of radius `r` (high inside) near its surface: its gradient and Hessian
    /// at `p` for f = −|p|².
    fn ball_at(p: DVec3) -> (DVec3, DMat3) {
        (-2.0 * p, DMat3::from_diagonal(DVec3::splat(-2.0)))
    }

    #[test]
    fn a_ball_of_tissue_is_a_cap_and_a_tube_of_air_a_rut() {
        let p = DVec3::new(0.0, 0.0, 4.0);
        let (g, h) = ball_at(p);
        let cap = shape(g, h, LumenSide::Below, DMat3::IDENTITY);
        assert!((cap.shape_index - 1.0).abs() < 1e-9, "{cap:?}");
        assert!((cap.curvedness - 0.25).abs() < 1e-9);
        assert!((cap.normal - DVec3::Z).length() < 1e-9);
        // Tissue outside a cylinder of air along z, radius 5: f = x² + y² rises outward.
        let p = DVec3::new(5.0, 0.0, 1.0);
        let (g, h) = (
            DVec3::new(10.0, 0.0, 0.0),
            DMat3::from_diagonal(DVec3::new(2.0, 2.0, 0.0)),
        );
        let rut = shape(g, h, LumenSide::Below, DMat3::IDENTITY);
        assert!((rut.shape_index - 0.25).abs() < 1e-9, "{rut:?} at {p}");
        assert!((rut.curvedness - 0.2 / 2f64.sqrt()).abs() < 1e-9);
        // The same ball seen from a bright lumen around it is a cup.
        let (g, h) = ball_at(DVec3::new(3.0, 0.0, 0.0));
        let cup = shape(-g, -h, LumenSide::Above, DMat3::IDENTITY);
        assert!((cup.shape_index - 1.0).abs() < 1e-9);
        let cup = shape(g, h, LumenSide::Above, DMat3::IDENTITY);
        assert!(cup.shape_index.abs() < 1e-9);
    }

    #[test]
    fn filters_are_exact_on_low_polynomials() {
        for (sigma, spacing) in [(1.0, 1.0), (1.4, 0.7)] {
            let [g, d1, d2] = filters(sigma, 5, spacing);
            let on = |w: &[f64], f: &dyn Fn(f64) -> f64| -> f64 {
                w.iter()
                    .enumerate()
                    .map(|(n, w)| w * f((n as f64 - 5.0) * spacing))
                    .sum()
            };
            assert!((on(&g, &|_| 1.0) - 1.0).abs() < 1e-12);
            assert!((on(&d1, &|x| x) - 1.0).abs() < 1e-12);
            assert!(on(&d1, &|_| 1.0).abs() < 1e-12);
            assert!((on(&d2, &|x| x * x / 2.0) - 1.0).abs() < 1e-12);
            assert!(on(&d2, &|_| 1.0).abs() < 1e-12);
            assert!(on(&d2, &|x| x).abs() < 1e-12);
        }
    }
}
