//! The colon: a winding air tube with haustral folds and polyps, for fly-through and navigation.
//!
//! Its anatomy is laid out at the "paper size" 512 (512 × 512 × 478 voxels of 1 mm, like the
//! abdominal CT the method was published on) and scaled by `size / 512`: the lumen radius varies
//! slowly between 12 and 20 mm, a fold every 35 mm narrows it by a quarter, and five polyps of
//! 3–8 mm sit on the wall between folds.

use super::bins::BinGrid;
use super::centreline::Centreline;
use super::profile::{paint, ramp, AIR_HU, REACH_VOX, TISSUE_HU};
use super::raster::rasterize;
use super::shape::{segment_closest, torus, Ball};
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
/// Control points of the centreline as fractions of the grid (i to the patient's left, j
/// posterior, k superior): rectum, sigmoid loop, descending colon up the left side, splenic
/// flexure, transverse colon sagging forward, hepatic flexure, ascending colon, caecum.
const CONTROL: [[f64; 3]; 16] = [
    [0.50, 0.72, 0.08],
    [0.50, 0.74, 0.22],
    [0.56, 0.62, 0.32],
    [0.42, 0.45, 0.40],
    [0.55, 0.30, 0.42],
    [0.75, 0.40, 0.36],
    [0.82, 0.58, 0.45],
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
const BIN_VOX: usize = 8;

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

/// Truth of the colon phantom. The lumen is the set of points whose distance to the centreline
/// is below [`Colon::radius_vox_at`] the arc length of their closest centreline point, minus the
/// folds and the polyps.
#[derive(Debug, Clone, PartialEq)]
pub struct Colon {
    /// The lumen's axis from the rectum (arc length 0) to the caecum.
    pub centreline: Centreline,
    /// Haustral folds, in order along the centreline.
    pub folds: Vec<Fold>,
    /// Polyps: tissue balls centred just outside the wall, bulging into the lumen.
    pub polyps: Vec<Ball>,
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
        let last = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) - 1.0;
        let control: Vec<DVec3> = CONTROL.iter().map(|c| DVec3::from(*c) * last).collect();
        let step_vox = (2.0 * scale).max(0.5);
        let centreline = Centreline::new(resample(&catmull_rom(&control), step_vox));
        let mut colon = Self {
            centreline,
            folds: Vec::new(),
            polyps: Vec::new(),
            scale,
        };
        colon.folds = colon.place_folds();
        colon.polyps = colon.place_polyps();
        colon
    }

    fn fold_spacing_vox(&self) -> f64 {
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

    /// The noiseless value at `p`, given the shapes binned near it.
    fn hu_at(&self, bins: &BinGrid, p: DVec3) -> f64 {
        let near = bins.near(p);
        if near.is_empty() {
            return TISSUE_HU;
        }
        let points = self.centreline.points();
        let arc = self.centreline.arc_vox();
        let segments = points.len() - 1;
        let first_fold = near.partition_point(|&id| (id as usize) < segments);
        let first_polyp = near.partition_point(|&id| (id as usize) < segments + self.folds.len());
        let (mut best_d2, mut best_s) = (f64::INFINITY, 0.0);
        for &id in &near[..first_fold] {
            let seg = id as usize;
            let (t, d2) = segment_closest(points[seg], points[seg + 1], p);
            if d2 < best_d2 {
                best_d2 = d2;
                best_s = arc[seg] + t * (arc[seg + 1] - arc[seg]);
            }
        }
        let mut hu = ramp(
            best_d2.sqrt() - self.radius_vox_at(best_s),
            AIR_HU,
            TISSUE_HU,
        );
        for &id in &near[first_fold..first_polyp] {
            let f = &self.folds[id as usize - segments];
            let d = torus(p, f.centre_vox, f.axis, f.ring_radius_vox, f.depth_vox);
            hu = paint(hu, d, TISSUE_HU);
        }
        for &id in &near[first_polyp..] {
            let ball = &self.polyps[id as usize - segments - self.folds.len()];
            hu = paint(hu, ball.signed_distance(p), TISSUE_HU);
        }
        hu
    }

    /// Bins the segments, folds and polyps (in that id order) by the boxes they can change.
    fn bins(&self, dims: [usize; 3]) -> BinGrid {
        let reach = self.max_radius_vox() + REACH_VOX;
        let segments = self.centreline.points().windows(2).map(|pair| {
            let r = DVec3::splat(reach);
            (pair[0].min(pair[1]) - r, pair[0].max(pair[1]) + r)
        });
        let folds = self.folds.iter().map(|f| {
            let r = DVec3::splat(f.ring_radius_vox + f.depth_vox + REACH_VOX);
            (f.centre_vox - r, f.centre_vox + r)
        });
        let polyps = self.polyps.iter().map(|b| b.bounds(REACH_VOX));
        let bounds: Vec<_> = segments.chain(folds).chain(polyps).collect();
        BinGrid::new(dims, BIN_VOX, &bounds)
    }
}

/// A `size × size × (size · 478 / 512)` volume of tissue holding the colon's air lumen.
pub fn colon(options: &PhantomOptions) -> (Volume, Colon) {
    let size = options.size_vox();
    let slices = (size * PAPER_SLICES / PAPER_SIZE).round() as usize;
    let dims = [size as usize, size as usize, slices];
    let truth = Colon::new(dims, size / PAPER_SIZE);
    let bins = truth.bins(dims);
    let volume = rasterize(dims, options, |p| truth.hu_at(&bins, p));
    (volume, truth)
}

/// A uniform Catmull–Rom spline through `control`, densely sampled (ends extrapolated linearly).
fn catmull_rom(control: &[DVec3]) -> Vec<DVec3> {
    let n = control.len();
    let at = |i: isize| -> DVec3 {
        match i {
            -1 => 2.0 * control[0] - control[1],
            i if i as usize >= n => 2.0 * control[n - 1] - control[n - 2],
            i => control[i as usize],
        }
    };
    let mut dense = Vec::with_capacity((n - 1) * SAMPLES_PER_SPAN + 1);
    for span in 0..n as isize - 1 {
        let (p0, p1, p2, p3) = (at(span - 1), at(span), at(span + 1), at(span + 2));
        for step in 0..SAMPLES_PER_SPAN {
            let t = step as f64 / SAMPLES_PER_SPAN as f64;
            let (t2, t3) = (t * t, t * t * t);
            dense.push(
                0.5 * (2.0 * p1
                    + (p2 - p0) * t
                    + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
                    + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3),
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
