//! A candidate's size as a radiologist measures it: the largest diameter of what stands out of
//! the local wall (of the head for a pedunculated polyp, whose stalk is narrower), rather than
//! of its cap region, which the wall's concavity narrows and which misses a flat polyp's rim.
//!
//! The local wall is the quadric height field over the plane across the candidate's normal
//! fitted (least squares) to the isosurface in a ring around the candidate's axis, beyond its
//! cap region; points rising out of the fit (a fold, the polyp's own foot) are trimmed and the
//! fit repeated. The polyp is grown from its summit over 26-adjacent wall points
//! - that stand more than [`EDGE_HEIGHT_MM`] above the fitted wall,
//! - that are convex once the fitted wall's mean curvature is taken off their curvatures (the
//!   crease where a polyp meets the wall is concave, and so is a fold's flank against the
//!   polyp on its crest),
//! - whose normal leans outward no less than on the way to them (the crease again),
//! - reached outward (no nearer the candidate's axis, so that it stops at the widest of a head
//!   or of an overhanging cap, not going on down the stalk or the fold it stands on) and not
//!   uphill (so that it never climbs onto a fold);
//!
//! its edge lies between its last point and the first that fails one of the first three,
//! interpolated on that measure. The isosurface is the unsmoothed volume's (the smoothing that
//! gives the curvatures fills the crease and widens the base by about its σ).

use super::{neighbours, SurfaceShape, WallPoint};
use crate::Geometry;
use glam::{DVec2, DVec3};

/// Directions across the normal along which an extent is measured.
const EXTENT_DIRECTIONS: usize = 32;
/// The fitted ring starts this fraction of the cap region's size from the candidate's axis
/// (a cap region is at least 0.7 of its polyp's diameter) ...
const RING_START_PER_CAP: f64 = 0.8;
/// ... plus this, mm ...
const RING_MARGIN_MM: f64 = 1.0;
/// ... and is this wide, mm.
const RING_WIDTH_MM: f64 = 3.0;
/// Ring points turned from the candidate's normal by more than this cosine's angle (the
/// flanks of a fold, the lumen's far side) are not fitted as its wall.
const MIN_FACING: f64 = 0.5;
/// Rounds of trimming what rises out of the fitted wall.
const FIT_ROUNDS: usize = 4;
/// Points above the fit by more than this, or by twice the fit's rms residual if larger, are
/// trimmed, mm.
const TRIM_MM: f64 = 0.5;
/// Fewer ring points than this fit no wall.
const MIN_RING_POINTS: usize = 12;
/// The polyp ends where it stands this high above the fitted wall, mm.
const EDGE_HEIGHT_MM: f64 = 0.25;
/// The polyp ends where its (smoothed) surface stops being convex over the fitted wall: where
/// its shape index, the wall's mean curvature taken off, falls below this (at 0.6 a flat
/// polyp on a fold's crest runs on down the fold's flanks, a ridge: up to 1.9 mm too wide on
/// the test's phantoms) ...
const CONVEX_SHAPE_INDEX: f64 = 0.7;
/// ... or where its (unsmoothed) surface's outward lean (its normal's component away from the
/// summit) has fallen by this much from the most it reached on the way out from the summit.
const LEAN_DROP: f64 = 0.03;
/// A point joins the polyp when no higher (along the candidate's normal) than the point it is
/// reached from by this, mm.
const CLIMB_MM: f64 = 0.05;

/// The largest diameter across `normal` of what stands out of the wall around the cap region
/// of size `cap_mm` whose tip is `wall[tip]`; `None` where no wall can be fitted or the tip
/// does not stand out of it.
pub(super) fn diameter_mm(
    geometry: &Geometry,
    wall: &[WallPoint],
    tip: usize,
    normal: DVec3,
    cap_mm: f64,
) -> Option<f64> {
    if normal == DVec3::ZERO {
        return None;
    }
    let frame = Frame::new(wall[tip].surface_mm, normal);
    let ring_start = RING_START_PER_CAP * cap_mm + RING_MARGIN_MM;
    let ring_end = ring_start + RING_WIDTH_MM;
    let mut near = nearby(geometry, wall, tip, &frame, ring_end);
    let ring: Vec<DVec3> = near
        .iter()
        .filter(|n| n.facing >= MIN_FACING && n.local.x.hypot(n.local.y) >= ring_start)
        .map(|n| n.local)
        .collect();
    let wall_fit = fit_wall(&ring)?;
    near.retain(|n| n.local.x.hypot(n.local.y) < ring_start);
    let wall_mean_curvature = wall_fit.mean_curvature();
    for n in &mut near {
        n.height = n.local.z - wall_fit.at(n.local.x, n.local.y);
        n.shape_index = shape_index_over(n.shape, wall_mean_curvature);
    }
    let tip = near.iter().position(|n| n.index == wall[tip].index)?;
    let summit = summit(geometry.dims(), &near, tip);
    if near[summit].height <= EDGE_HEIGHT_MM {
        return None;
    }
    let outline = outline(geometry.dims(), &near, summit);
    Some(width(&outline))
}

/// An orthonormal frame: `a`, `b` across the normal `n`, at an origin.
struct Frame {
    origin: DVec3,
    axes: [DVec3; 3],
}

impl Frame {
    fn new(origin: DVec3, n: DVec3) -> Self {
        let (a, b) = n.any_orthonormal_pair();
        Self {
            origin,
            axes: [a, b, n],
        }
    }

    /// `p` in the frame: across the normal (x, y) and along it (z).
    fn local(&self, p: DVec3) -> DVec3 {
        let d = p - self.origin;
        DVec3::new(
            d.dot(self.axes[0]),
            d.dot(self.axes[1]),
            d.dot(self.axes[2]),
        )
    }
}

/// A wall point near the candidate.
struct Near {
    /// Its voxel's linear index.
    index: usize,
    /// Its voxel.
    voxel: [usize; 3],
    /// Its surface point in the candidate's frame, mm.
    local: DVec3,
    /// The cosine of its normal's angle to the candidate's.
    facing: f64,
    /// Its (unsmoothed) normal's component across the candidate's normal.
    across: DVec2,
    /// Its surface shape.
    shape: SurfaceShape,
    /// Its shape index once the fitted wall's mean curvature is taken off its curvatures.
    shape_index: f64,
    /// Its height above the fitted wall, mm.
    height: f64,
}

/// The wall points within `radius_mm` of the candidate's axis (and along it), by ascending
/// index.
fn nearby(
    geometry: &Geometry,
    wall: &[WallPoint],
    tip: usize,
    frame: &Frame,
    radius_mm: f64,
) -> Vec<Near> {
    let dims = geometry.dims();
    let centre = wall[tip].voxel;
    let reach = geometry.spacing_mm().recip() * radius_mm;
    let range = |a: usize| {
        let r = reach[a].ceil() as usize + 1;
        centre[a].saturating_sub(r)..=(centre[a] + r).min(dims[a] - 1)
    };
    let (xs, ys) = (range(0), range(1));
    let mut near = Vec::new();
    for k in range(2) {
        for j in ys.clone() {
            let row = dims[0] * (j + dims[1] * k);
            let first = wall.partition_point(|w| w.index < row + xs.start());
            let last = wall.partition_point(|w| w.index <= row + xs.end());
            for w in &wall[first..last] {
                let local = frame.local(w.surface_mm);
                let within = local.x.hypot(local.y) < radius_mm && local.z.abs() < radius_mm;
                if within {
                    near.push(Near {
                        index: w.index,
                        voxel: w.voxel,
                        local,
                        facing: w.shape.normal.dot(frame.axes[2]),
                        across: DVec2::new(
                            w.surface_normal.dot(frame.axes[0]),
                            w.surface_normal.dot(frame.axes[1]),
                        ),
                        shape: w.shape,
                        shape_index: w.shape.shape_index,
                        height: 0.0,
                    });
                }
            }
        }
    }
    near
}

/// A height field z = c · (1, x, y, x², xy, y²).
struct Quadric([f64; 6]);

impl Quadric {
    fn at(&self, x: f64, y: f64) -> f64 {
        terms(x, y).iter().zip(&self.0).map(|(t, c)| t * c).sum()
    }

    /// Its mean curvature at the origin, positive where it is convex seen from above (the
    /// lumen), 1/mm (its slopes there are small: the frame's normal is the candidate's).
    fn mean_curvature(&self) -> f64 {
        -(self.0[3] + self.0[5])
    }
}

/// The shape index of `shape` with `mean_curvature` taken off both its principal curvatures:
/// the shape of what stands on a wall of that mean curvature (a polyp's rim on the colon's
/// concave wall is a cap again, not a rut).
fn shape_index_over(shape: SurfaceShape, mean_curvature: f64) -> f64 {
    let angle = std::f64::consts::PI * (shape.shape_index - 0.5);
    // k1 + k2 and k1 − k2 from the shape index and the curvedness.
    let sum = 2.0 * shape.curvedness * angle.sin() - 2.0 * mean_curvature;
    let difference = 2.0 * shape.curvedness * angle.cos();
    0.5 + sum.atan2(difference) / std::f64::consts::PI
}

fn terms(x: f64, y: f64) -> [f64; 6] {
    [1.0, x, y, x * x, x * y, y * y]
}

/// The wall fitted to `ring` (local points), trimming what rises out of it.
fn fit_wall(ring: &[DVec3]) -> Option<Quadric> {
    let mut kept = ring.to_vec();
    let mut fit = least_squares(&kept)?;
    for _ in 0..FIT_ROUNDS {
        let residual = |p: &DVec3| p.z - fit.at(p.x, p.y);
        let rms =
            (kept.iter().map(|p| residual(p).powi(2)).sum::<f64>() / kept.len() as f64).sqrt();
        let limit = TRIM_MM.max(2.0 * rms);
        kept.retain(|p| residual(p) <= limit);
        fit = least_squares(&kept)?;
    }
    Some(fit)
}

/// The least-squares quadric through `points`; `None` with too few or degenerate points.
fn least_squares(points: &[DVec3]) -> Option<Quadric> {
    if points.len() < MIN_RING_POINTS {
        return None;
    }
    let mut normal = [[0.0; 7]; 6];
    for p in points {
        let t = terms(p.x, p.y);
        for (row, ti) in normal.iter_mut().zip(t) {
            for (cell, tj) in row.iter_mut().zip(t.iter().chain([&p.z])) {
                *cell += ti * tj;
            }
        }
    }
    solve(normal).map(Quadric)
}

/// The solution of the augmented 6 × 6 system `m` (Gauss–Jordan with partial pivoting);
/// `None` when it is singular.
fn solve(mut m: [[f64; 7]; 6]) -> Option<[f64; 6]> {
    for col in 0..6 {
        let pivot = (col..6).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        m.swap(col, pivot);
        let p = m[col][col];
        if p.abs() < 1e-9 || !p.is_finite() {
            return None;
        }
        let row = m[col].map(|v| v / p);
        for (r, other) in m.iter_mut().enumerate() {
            let factor = if r == col { 0.0 } else { other[col] };
            for (cell, v) in other.iter_mut().zip(row) {
                *cell -= factor * v;
            }
        }
        m[col] = row;
    }
    Some(m.map(|row| row[6]))
}

/// The point of `near` reached from `near[start]` by climbing (along the candidate's normal) to
/// ever higher neighbours until none is higher.
fn summit(dims: [usize; 3], near: &[Near], start: usize) -> usize {
    let mut at = start;
    loop {
        let higher = neighbours_in(dims, near, at)
            .max_by(|&a, &b| near[a].local.z.total_cmp(&near[b].local.z))
            .filter(|&n| near[n].local.z > near[at].local.z);
        match higher {
            Some(n) => at = n,
            None => return at,
        }
    }
}

/// The positions in `near` of the 26 neighbours of `near[at]` that are in it.
fn neighbours_in(dims: [usize; 3], near: &[Near], at: usize) -> impl Iterator<Item = usize> + '_ {
    neighbours(dims, near[at].voxel).filter_map(move |v| {
        let index = v[0] + dims[0] * (v[1] + dims[1] * v[2]);
        near.binary_search_by_key(&index, |n| n.index).ok()
    })
}

/// The local points, across the normal, of the polyp grown from its summit `near[start]` (see
/// the module doc) and of its edge.
fn outline(dims: [usize; 3], near: &[Near], start: usize) -> Vec<DVec2> {
    let centre = near[start].local.truncate();
    let outward = |n: &Near| n.local.truncate() - centre;
    let lean = |n: &Near| n.across.dot(outward(n).normalize_or_zero());
    // Per point, the most lean on the way to it.
    let mut peak = vec![f64::NAN; near.len()];
    peak[start] = lean(&near[start]);
    let mut queue = vec![start];
    let mut points = vec![centre];
    while let Some(at) = queue.pop() {
        let here = &near[at];
        for next in neighbours_in(dims, near, at) {
            let there = &near[next];
            let farther = outward(there).length() >= outward(here).length();
            if !peak[next].is_nan() || there.local.z > here.local.z + CLIMB_MM || !farther {
                continue;
            }
            let floor = peak[at] - LEAN_DROP;
            let margins = |n: &Near| {
                [
                    n.height - EDGE_HEIGHT_MM,
                    lean(n) - floor,
                    n.shape_index - CONVEX_SHAPE_INDEX,
                ]
            };
            match edge_at(margins(here), margins(there)) {
                None => {
                    peak[next] = peak[at].max(lean(there));
                    queue.push(next);
                    points.push(there.local.truncate());
                }
                Some(t) => points.push(here.local.truncate().lerp(there.local.truncate(), t)),
            }
        }
    }
    points
}

/// How far from a point inside the polyp, of `margins` (all positive), toward a neighbour of
/// `next` margins the polyp ends (where the first margin to fall to zero does, interpolated),
/// as a fraction of the way; `None` when the neighbour is inside too.
fn edge_at<const N: usize>(margins: [f64; N], next: [f64; N]) -> Option<f64> {
    margins
        .iter()
        .zip(next)
        .filter(|(_, b)| *b <= 0.0)
        .map(|(a, b)| a / (a - b))
        .reduce(f64::min)
}

/// The largest extent of the plane's `points` over [`EXTENT_DIRECTIONS`] directions (within
/// 0.5 % of the true width).
fn width(points: &[DVec2]) -> f64 {
    (0..EXTENT_DIRECTIONS)
        .map(|n| {
            let d = DVec2::from_angle(std::f64::consts::PI * n as f64 / EXTENT_DIRECTIONS as f64);
            let (lo, hi) = points.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                (lo.min(p.dot(d)), hi.max(p.dot(d)))
            });
            hi - lo
        })
        .fold(0.0, f64::max)
}

/// The largest extent of `points` perpendicular to `normal` (see [`width`]).
pub(super) fn extent_across(points: &[DVec3], normal: DVec3) -> f64 {
    let (u, v) = if normal == DVec3::ZERO {
        (DVec3::X, DVec3::Y)
    } else {
        normal.any_orthonormal_pair()
    };
    let across: Vec<DVec2> = points
        .iter()
        .map(|p| DVec2::new(p.dot(u), p.dot(v)))
        .collect();
    width(&across)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    #[test]
    fn the_wall_fit_recovers_a_quadric_under_a_fold_it_trims() {
        let wall = |x: f64, y: f64| 0.3 - 0.1 * x + 0.05 * x * x - 0.02 * x * y + 0.04 * y * y;
        let mut ring: Vec<DVec3> = (0..72)
            .flat_map(|n| {
                let (sin, cos) = (TAU * f64::from(n) / 72.0).sin_cos();
                [5.0, 6.5, 8.0].map(|r| DVec3::new(r * cos, r * sin, wall(r * cos, r * sin)))
            })
            .collect();
        // A fold across the ring stands 2 mm out of the wall.
        for p in ring.iter_mut().filter(|p| p.x.abs() < 1.0) {
            p.z += 2.0;
        }
        let fit = fit_wall(&ring).unwrap();
        for (x, y) in [(0.0, 0.0), (2.0, -1.0), (-3.0, 3.0)] {
            assert!((fit.at(x, y) - wall(x, y)).abs() < 1e-6, "at {x}, {y}");
        }
        assert!((fit.mean_curvature() + 0.09).abs() < 1e-6);
        assert!(fit_wall(&ring[..MIN_RING_POINTS - 1]).is_none());
    }

    /// The shape of principal curvatures `k1` ≥ `k2`.
    fn shape(k1: f64, k2: f64) -> SurfaceShape {
        SurfaceShape {
            shape_index: 0.5 + (k1 + k2).atan2(k1 - k2) / PI,
            curvedness: ((k1 * k1 + k2 * k2) / 2.0).sqrt(),
            normal: DVec3::Z,
        }
    }

    #[test]
    fn the_wall_taken_off_a_rut_on_a_tube_leaves_a_saddle_and_a_rim_a_cap() {
        // A tube of radius 10 mm seen from inside: a rut of mean curvature −0.05 /mm.
        let tube = shape(0.0, -0.1);
        assert!((tube.shape_index - 0.25).abs() < 1e-9);
        assert!((shape_index_over(tube, -0.05) - 0.5).abs() < 1e-9);
        // A low dome's rim on it, convex by 0.05 /mm both ways, is a saddle until the wall's
        // curvature is taken off.
        let rim = shape(0.05, -0.05);
        assert!((rim.shape_index - 0.5).abs() < 1e-9);
        assert!((shape_index_over(rim, -0.05) - 0.75).abs() < 1e-9);
        // On a flat wall nothing changes.
        let cap = shape(0.2, 0.1);
        assert!((shape_index_over(cap, 0.0) - cap.shape_index).abs() < 1e-9);
    }
}
