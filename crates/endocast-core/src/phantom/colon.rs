//! The colon: a winding air tube with haustral folds and polyps, for fly-through and navigation.
//!
//! Its anatomy is laid out at the "paper size" 512 (512 × 512 × 478 voxels of 1 mm, like the
//! abdominal CT the method was published on) and scaled by `size / 512`: the lumen radius varies
//! slowly between 12 and 20 mm, a fold every 35 mm narrows it by a quarter, and five polyps of
//! 3–8 mm sit on the wall between folds.

use super::bins::BinGrid;
use super::centreline::Centreline;
use super::profile::{paint, ramp, AIR_HU, REACH_VOX, TISSUE_HU};
use super::raster::{rasterize, Field};
use super::shape::{torus, Ball};
use super::tagged_pool::{self, Pool};
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;
use std::f64::consts::TAU;

/// Size at which the anatomy below is given in millimetres (= voxels).
const PAPER_SIZE: f64 = 512.0;
/// Slices at paper size (the CT this phantom stands in for has 478).
const PAPER_SLICES: f64 = 478.0;
/// Mean lumen radius and the amplitude of its slow variation, mm at paper size.
const RADIUS_MEAN_MM: f64 = 16.0;
const RADIUS_SWING_MM: f64 = 4.0;
/// Arc length over which the radius goes through one full swing, mm at paper size.
const RADIUS_PERIOD_MM: f64 = 350.0;
/// Distance between haustral folds along the centreline, mm at paper size.
const FOLD_SPACING_MM: f64 = 35.0;
/// How far a fold reaches into the lumen, as a fraction of the local radius.
const FOLD_DEPTH: f64 = 0.25;
/// Polyps: where (fraction of the centreline's length), how big (radius, mm at paper size) and
/// where around the wall (radians from a reference direction perpendicular to the axis).
const POLYPS: [(f64, f64, f64); 5] = [
    (0.14, 5.0, 0.0),
    (0.33, 8.0, 2.0),
    (0.52, 3.0, 4.0),
    (0.70, 6.5, 1.0),
    (0.88, 4.0, 3.0),
];
/// Control polygon of the centreline (a B-spline's) as fractions of the grid (i to the patient's left, j
/// posterior, k superior): rectum, sigmoid loop, descending colon up the left side, splenic
/// flexure, transverse colon sagging forward, hepatic flexure, ascending colon, caecum.
const CONTROL: [[f64; 3]; 17] = [
    [0.50, 0.70, 0.08],
    [0.52, 0.71, 0.18],
    [0.57, 0.62, 0.28],
    [0.45, 0.54, 0.33],
    [0.45, 0.40, 0.37],
    [0.57, 0.33, 0.40],
    [0.69, 0.40, 0.41],
    [0.80, 0.56, 0.45],
    [0.83, 0.60, 0.70],
    [0.78, 0.50, 0.88],
    [0.62, 0.28, 0.74],
    [0.45, 0.22, 0.68],
    [0.30, 0.30, 0.76],
    [0.20, 0.45, 0.84],
    [0.17, 0.60, 0.70],
    [0.18, 0.60, 0.38],
    [0.24, 0.52, 0.20],
];
/// Spline samples per control-point span before resampling by arc length.
const SAMPLES_PER_SPAN: usize = 256;
/// Edge of the bins that list nearby shapes, voxels.
const BIN_VOX: usize = 4;

/// A haustral fold: a ring-shaped ridge of tissue, the torus swept by a circle of radius
/// `depth_vox` centred on the wall circle of radius `ring_radius_vox` around `axis`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fold {
    /// Arc length of the fold's centre along the centreline, voxels.
    pub arc_vox: f64,
    /// Centre of the ring (on the centreline), voxel index.
    pub centre_vox: DVec3,
    /// Unit axis of the ring (the centreline's tangent there).
    pub axis: DVec3,
    /// Radius of the ring: the lumen radius at the fold, voxels.
    pub ring_radius_vox: f64,
    /// How far the fold reaches into the lumen (and its half thickness along the axis), voxels.
    pub depth_vox: f64,
}

/// Truth of the colon phantom. The lumen is the set of points closer to the centreline than the
/// radius ([`Colon::radius_vox_at`]) at the arc length of their closest centreline point, less the
/// folds and the polyps.
#[derive(Debug, Clone, PartialEq)]
pub struct Colon {
    /// The lumen's axis from the rectum (arc length 0) to the caecum.
    pub centreline: Centreline,
    /// Haustral folds, in order along the centreline.
    pub folds: Vec<Fold>,
    /// Polyps: tissue balls centred just outside the wall, bulging into the lumen.
    pub polyps: Vec<Ball>,
    /// Pools of tagged fluid under the air (none unless [`PhantomOptions::tagged_fluid`]).
    pub pools: Vec<Pool>,
    /// Voxels per millimetre of the paper-size anatomy (`size / 512`).
    scale: f64,
}

impl Colon {
    /// The lumen's radius (wall without folds) at arc length `s_vox`, voxels.
    pub fn radius_vox_at(&self, s_vox: f64) -> f64 {
        let s_mm = s_vox / self.scale;
        self.scale
            * (RADIUS_MEAN_MM + RADIUS_SWING_MM * (TAU * s_mm / RADIUS_PERIOD_MM + 0.7).sin())
    }

    /// The largest lumen radius anywhere, voxels.
    pub fn max_radius_vox(&self) -> f64 {
        self.scale * (RADIUS_MEAN_MM + RADIUS_SWING_MM)
    }

    /// The layout for a grid of `dims` at `scale` voxels per paper millimetre.
    fn new(dims: [usize; 3], scale: f64) -> Self {
        Self::around(Centreline::new(Self::axis_points(dims, scale)), scale)
    }

    /// The vertices of the centreline of the layout for a grid of `dims` at `scale`.
    pub(super) fn axis_points(dims: [usize; 3], scale: f64) -> Vec<DVec3> {
        let last = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) - 1.0;
        let control: Vec<DVec3> = CONTROL.iter().map(|c| DVec3::from(*c) * last).collect();
        let step_vox = (2.0 * scale).max(0.5);
        resample(&b_spline(&control), step_vox)
    }

    /// The colon along `centreline` at `scale` voxels per paper millimetre: its radius, folds
    /// and polyps placed by arc length along it.
    pub(super) fn around(centreline: Centreline, scale: f64) -> Self {
        let mut colon = Self {
            centreline,
            folds: Vec::new(),
            polyps: Vec::new(),
            pools: Vec::new(),
            scale,
        };
        colon.folds = colon.place_folds();
        colon.polyps = colon.place_polyps();
        colon
    }

    /// Distance between folds along the centreline, voxels.
    pub(crate) fn fold_spacing_vox(&self) -> f64 {
        FOLD_SPACING_MM * self.scale
    }

    fn place_folds(&self) -> Vec<Fold> {
        let spacing = self.fold_spacing_vox();
        let count = (self.centreline.length_vox() / spacing - 0.5)
            .floor()
            .max(0.0) as usize;
        (1..=count)
            .map(|n| {
                let s = n as f64 * spacing;
                let ring = self.radius_vox_at(s);
                Fold {
                    arc_vox: s,
                    centre_vox: self.centreline.point_at(s),
                    axis: self.centreline.tangent_at(s),
                    ring_radius_vox: ring,
                    depth_vox: FOLD_DEPTH * ring,
                }
            })
            .collect()
    }

    /// Polyps halfway between two folds, their centres a fifth of their radius beyond the wall.
    fn place_polyps(&self) -> Vec<Ball> {
        let spacing = self.fold_spacing_vox();
        POLYPS
            .iter()
            .map(|&(fraction, radius_mm, angle)| {
                let s =
                    ((fraction * self.centreline.length_vox() / spacing).floor() + 0.5) * spacing;
                let tangent = self.centreline.tangent_at(s);
                let reference = if tangent.cross(DVec3::Z).length() > 0.1 {
                    tangent.cross(DVec3::Z).normalize()
                } else {
                    tangent.cross(DVec3::X).normalize()
                };
                let outward = reference * angle.cos() + tangent.cross(reference) * angle.sin();
                let radius_vox = radius_mm * self.scale;
                Ball {
                    centre_vox: self.centreline.point_at(s)
                        + outward * (self.radius_vox_at(s) + 0.2 * radius_vox),
                    radius_vox,
                }
            })
            .collect()
    }
}

/// One centreline segment, with what the per-voxel distance needs precomputed.
struct Segment {
    start: DVec3,
    delta: DVec3,
    length: f64,
    inv_length2: f64,
    arc_start: f64,
}

impl Segment {
    /// Squared distance from `p` to the segment, and the arc length of the closest point.
    #[inline]
    fn closest(&self, p: DVec3) -> (f64, f64) {
        let t = ((p - self.start).dot(self.delta) * self.inv_length2).clamp(0.0, 1.0);
        let d2 = p.distance_squared(self.start + self.delta * t);
        (d2, self.arc_start + t * self.length)
    }
}

/// The colon's value function: its truth, its segments and the bins that list, per bin of voxels,
/// the segments that can be closest there and the folds and polyps that can reach it.
pub(crate) struct ColonField<'a> {
    colon: &'a Colon,
    segments: Vec<Segment>,
    bins: BinGrid,
}

impl Field for ColonField<'_> {
    /// The noiseless value at `p`: the lumen around the closest segment, then folds and polyps.
    fn hu_at(&self, p: DVec3) -> f64 {
        let near = self.bins.near(p);
        if near.is_empty() {
            return TISSUE_HU;
        }
        let n_seg = self.segments.len();
        let n_fold = self.colon.folds.len();
        let first_fold = near.partition_point(|&id| (id as usize) < n_seg);
        let first_polyp = near.partition_point(|&id| (id as usize) < n_seg + n_fold);
        let (mut best_d2, mut best_s) = (f64::INFINITY, 0.0);
        for &id in &near[..first_fold] {
            let (d2, s) = self.segments[id as usize].closest(p);
            if d2 < best_d2 {
                (best_d2, best_s) = (d2, s);
            }
        }
        let mut hu = if best_d2.is_finite() {
            let d = best_d2.sqrt() - self.colon.radius_vox_at(best_s);
            let lumen = Pool::lumen_hu(&self.colon.pools, AIR_HU, p.y, best_s);
            ramp(d, lumen, TISSUE_HU)
        } else {
            TISSUE_HU
        };
        for &id in &near[first_fold..first_polyp] {
            let f = &self.colon.folds[id as usize - n_seg];
            let d = torus(p, f.centre_vox, f.axis, f.ring_radius_vox, f.depth_vox);
            hu = paint(hu, d, TISSUE_HU);
        }
        for &id in &near[first_polyp..] {
            let ball = &self.colon.polyps[id as usize - n_seg - n_fold];
            hu = paint(hu, ball.signed_distance(p), TISSUE_HU);
        }
        hu
    }

    fn uniform_run(&self, i: usize, j: usize, k: usize) -> Option<(usize, f64)> {
        let p = DVec3::new(i as f64, j as f64, k as f64);
        self.bins
            .near(p)
            .is_empty()
            .then(|| (self.bins.run_end(i), TISSUE_HU))
    }
}

impl<'a> ColonField<'a> {
    /// The field of `colon` on a grid of `dims`.
    pub(crate) fn new(colon: &'a Colon, dims: [usize; 3]) -> Self {
        let points = colon.centreline.points();
        let segments: Vec<Segment> = points
            .windows(2)
            .zip(colon.centreline.arc_vox())
            .map(|(pair, &arc_start)| {
                // Consecutive centreline points are distinct: a resampling step apart, the
                // last pair at least a quarter step.
                let length = pair[0].distance(pair[1]);
                Segment {
                    start: pair[0],
                    delta: pair[1] - pair[0],
                    length,
                    inv_length2: 1.0 / (length * length),
                    arc_start,
                }
            })
            .collect();
        let bins = Self::bin(colon, &segments, dims);
        Self {
            colon,
            segments,
            bins,
        }
    }

    /// Bins the segments, folds and polyps (in that id order). A segment is kept in a bin only
    /// if it lies within the lumen's reach of some voxel there and might be the closest segment
    /// to one: not when another segment is nearer to every voxel of the bin. With 4-voxel bins
    /// that leaves a handful of segments per voxel.
    fn bin(colon: &Colon, segments: &[Segment], dims: [usize; 3]) -> BinGrid {
        let reach = colon.max_radius_vox() + REACH_VOX;
        let grown = |lo: DVec3, hi: DVec3, by: f64| (lo - DVec3::splat(by), hi + DVec3::splat(by));
        let bounds: Vec<_> = segments
            .iter()
            .map(|s| {
                grown(
                    s.start.min(s.start + s.delta),
                    s.start.max(s.start + s.delta),
                    reach,
                )
            })
            .chain(colon.folds.iter().map(|f| {
                grown(
                    f.centre_vox,
                    f.centre_vox,
                    f.ring_radius_vox + f.depth_vox + REACH_VOX,
                )
            }))
            .chain(colon.polyps.iter().map(|b| b.bounds(REACH_VOX)))
            .collect();
        let n_seg = segments.len();
        let n_fold = colon.folds.len();
        BinGrid::new(dims, BIN_VOX, &bounds, |ball, ids, kept| {
            let first_fold = ids.partition_point(|&id| (id as usize) < n_seg);
            let distances: Vec<f64> = ids[..first_fold]
                .iter()
                .map(|&id| segments[id as usize].closest(ball.centre).0.sqrt())
                .collect();
            let nearest = distances.iter().copied().fold(f64::INFINITY, f64::min);
            // Every voxel of the bin is within `nearest + radius` of some segment; a segment
            // farther than that from all of them is never the closest, and beyond `reach` it is
            // never inside the lumen's ramp.
            let limit = (nearest + 2.0 * ball.radius).min(reach + ball.radius);
            kept.extend(
                ids[..first_fold]
                    .iter()
                    .zip(&distances)
                    .filter(|&(_, &d)| d <= limit)
                    .map(|(&id, _)| id),
            );
            kept.extend(ids[first_fold..].iter().filter(|&&id| {
                let id = id as usize;
                let d = if id < n_seg + n_fold {
                    let f = &colon.folds[id - n_seg];
                    torus(
                        ball.centre,
                        f.centre_vox,
                        f.axis,
                        f.ring_radius_vox,
                        f.depth_vox,
                    )
                } else {
                    colon.polyps[id - n_seg - n_fold].signed_distance(ball.centre)
                };
                d <= REACH_VOX + ball.radius
            }));
        })
    }
}

/// A `size × size × (size · 478 / 512)` volume of tissue holding the colon's air lumen, with
/// pools of tagged fluid when the options ask for them.
pub fn colon(options: &PhantomOptions) -> (Volume, Colon) {
    let (dims, truth) = layout(options);
    (raster(&truth, dims, options), truth)
}

/// The colon phantom's grid for `options` and the scale of its anatomy (voxels per paper mm).
pub(super) fn grid(options: &PhantomOptions) -> ([usize; 3], f64) {
    let size = options.size_vox();
    let slices = (size * PAPER_SLICES / PAPER_SIZE).round() as usize;
    ([size as usize, size as usize, slices], size / PAPER_SIZE)
}

/// The volume of `truth` on a `dims` grid, with the noise of `options`.
pub(super) fn raster(truth: &Colon, dims: [usize; 3], options: &PhantomOptions) -> Volume {
    rasterize(dims, options, &ColonField::new(truth, dims))
}

/// The grid and the colon's layout (with its five polyps, and its pools of tagged fluid when
/// `options` ask for them) for `options`.
pub(crate) fn layout(options: &PhantomOptions) -> ([usize; 3], Colon) {
    let (dims, scale) = grid(options);
    let mut truth = Colon::new(dims, scale);
    if options.tagged_fluid {
        truth.pools = tagged_pool::place(&truth);
    }
    (dims, truth)
}

/// The uniform cubic B-spline of the control polygon `control`, densely sampled. The curve does
/// not pass through the control points but follows them, C² smooth and inside their convex hull;
/// tripled end points make it start and end on the first and last.
fn b_spline(control: &[DVec3]) -> Vec<DVec3> {
    let n = control.len();
    let at = |i: usize| control[i.saturating_sub(2).min(n - 1)];
    let spans = n + 1;
    let mut dense = Vec::with_capacity(spans * SAMPLES_PER_SPAN + 1);
    for span in 0..spans {
        let (p0, p1, p2, p3) = (at(span), at(span + 1), at(span + 2), at(span + 3));
        for step in 0..SAMPLES_PER_SPAN {
            let t = step as f64 / SAMPLES_PER_SPAN as f64;
            let (t2, t3) = (t * t, t * t * t);
            let u = 1.0 - t;
            dense.push(
                (p0 * (u * u * u)
                    + p1 * (3.0 * t3 - 6.0 * t2 + 4.0)
                    + p2 * (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0)
                    + p3 * t3)
                    / 6.0,
            );
        }
    }
    dense.push(control[n - 1]);
    dense
}

/// Points every `step_vox` of arc length along the polyline `dense`, both ends included (the last
/// step is shortened).
fn resample(dense: &[DVec3], step_vox: f64) -> Vec<DVec3> {
    let mut out = vec![dense[0]];
    let mut next = step_vox;
    let mut walked = 0.0;
    for pair in dense.windows(2) {
        let len = pair[0].distance(pair[1]);
        while len > 0.0 && walked + len >= next {
            out.push(pair[0].lerp(pair[1], (next - walked) / len));
            next += step_vox;
        }
        walked += len;
    }
    let end = dense[dense.len() - 1];
    if out[out.len() - 1].distance(end) > 0.25 * step_vox {
        out.push(end);
    } else if let Some(last) = out.last_mut() {
        *last = end;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::tests::{iso_crossing, perpendicular, small};
    use super::*;

    const MID_HU: f64 = 0.5 * (AIR_HU + TISSUE_HU);

    /// The layout at paper size, without generating the volume.
    fn paper() -> Colon {
        Colon::new([512, 512, 478], 1.0)
    }

    #[test]
    fn the_tube_stays_inside_the_grid_and_apart_from_itself() {
        let colon = paper();
        let line = &colon.centreline;
        let last = DVec3::new(511.0, 511.0, 477.0);
        let length = line.length_vox();
        assert!((1000.0..2500.0).contains(&length), "length {length} mm");
        for (&p, &s) in line.points().iter().zip(line.arc_vox()) {
            let margin = p.min(last - p).min_element();
            assert!(
                margin > colon.radius_vox_at(s) + 5.0,
                "too close to a face at s = {s}"
            );
        }
        // Parts of the colon far apart along it are far apart in space: walls never merge.
        let wall = 2.0 * colon.max_radius_vox() + 10.0;
        for (a, &sa) in line.points().iter().zip(line.arc_vox()) {
            for (b, &sb) in line.points().iter().zip(line.arc_vox()) {
                if sb - sa > 2.0 * wall {
                    assert!(
                        a.distance(*b) > wall,
                        "s = {sa} and {sb} are {}",
                        a.distance(*b)
                    );
                }
            }
        }
        // Bends are gentle enough that every point of the lumen has one closest axis point.
        let step = line.arc_vox()[1];
        for w in line.points().windows(3) {
            let turn = (w[1] - w[0]).angle_between(w[2] - w[1]);
            assert!(step / turn.max(1e-9) > 1.5 * colon.max_radius_vox());
        }
    }

    #[test]
    fn folds_and_polyps_have_paper_sizes_and_leave_the_lumen_open() {
        let colon = paper();
        assert!(colon.folds.len() > 30);
        assert!(colon
            .folds
            .windows(2)
            .all(|f| (f[1].arc_vox - f[0].arc_vox - 35.0).abs() < 1e-9));
        assert_eq!(colon.polyps.len(), 5);
        for polyp in &colon.polyps {
            assert!((3.0..=8.0).contains(&polyp.radius_vox));
            let (s, distance) = colon.centreline.closest(polyp.centre_vox);
            let wall = colon.radius_vox_at(s);
            // Centred just beyond the wall, bulging into the lumen by 80 % of its radius.
            assert!(
                (distance - wall - 0.2 * polyp.radius_vox).abs() < 0.1,
                "{polyp:?}"
            );
            assert!(wall - 0.8 * polyp.radius_vox > 5.0);
            let nearest_fold = colon
                .folds
                .iter()
                .map(|f| (f.arc_vox - s).abs())
                .fold(f64::MAX, f64::min);
            assert!(nearest_fold > polyp.radius_vox + colon.folds[0].depth_vox + 2.0);
        }
    }

    #[test]
    fn centreline_is_air_from_end_to_end_and_polyps_are_tissue() {
        let (volume, colon) = colon(&small(128));
        let line = &colon.centreline;
        let samples = (line.length_vox() * 2.0) as usize;
        for n in 0..=samples {
            let s = line.length_vox() * n as f64 / samples as f64;
            let hu = volume.sample_physical(line.point_at(s)).unwrap();
            assert!(hu < -900.0, "{hu} HU on the centreline at s = {s}");
        }
        for polyp in &colon.polyps {
            let hu = volume.sample_physical(polyp.centre_vox).unwrap();
            assert!(hu > MID_HU, "{hu} HU at polyp {polyp:?}");
        }
    }

    #[test]
    fn lumen_and_fold_isosurfaces_sit_on_their_analytic_radii() {
        let (volume, colon) = colon(&small(256));
        let line = &colon.centreline;
        let clear_of_polyps = |p: DVec3| colon.polyps.iter().all(|b| b.signed_distance(p) > 3.0);
        let (mut worst_wall, mut worst_fold) = (0.0f64, 0.0f64);
        for (n, fold) in colon.folds.iter().enumerate() {
            let angle = n as f64 * 1.3;
            let dir = perpendicular(fold.axis, angle);
            let narrowed = fold.ring_radius_vox - fold.depth_vox;
            if clear_of_polyps(fold.centre_vox + dir * narrowed) {
                let r = iso_crossing(&volume, fold.centre_vox, dir, (0.0, narrowed + 0.7), MID_HU);
                worst_fold = worst_fold.max((r - narrowed).abs());
            }
            // Halfway to the next fold the lumen has its full radius.
            let s = fold.arc_vox + 0.5 * colon.fold_spacing_vox();
            let (from, radius) = (line.point_at(s), colon.radius_vox_at(s));
            let dir = perpendicular(line.tangent_at(s), angle);
            if clear_of_polyps(from + dir * radius) {
                let r = iso_crossing(&volume, from, dir, (0.0, radius + 1.5), MID_HU);
                worst_wall = worst_wall.max((r - radius).abs());
            }
        }
        assert!(
            worst_wall < 0.05,
            "worst wall radius error {worst_wall} voxel"
        );
        assert!(
            worst_fold < 0.15,
            "worst fold radius error {worst_fold} voxel"
        );
    }

    /// Generation time at paper size, without and with noise; run with
    /// `cargo test --release -p endocast-core -- --ignored --nocapture`.
    #[test]
    #[ignore = "timing at paper size (125 M voxels): run in release"]
    fn paper_size_generation_time() {
        for noise_hu in [0.0, 20.0] {
            let options = PhantomOptions {
                size: 512,
                noise_hu,
                ..Default::default()
            };
            let start = std::time::Instant::now();
            let (volume, _) = colon(&options);
            let seconds = start.elapsed().as_secs_f64();
            eprintln!(
                "colon {:?}, noise {noise_hu} HU: {seconds:.2} s",
                volume.dims()
            );
            assert_eq!(volume.dims(), [512, 512, 478]);
            assert!(seconds < 10.0, "{seconds:.2} s");
        }
    }
}
