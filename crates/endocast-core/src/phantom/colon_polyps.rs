//! The colon with polyps drawn by a seed: `count` polyps of 4–10 mm (sessile, pedunculated and
//! flat in turn) at random places on the folds' crests (a third) and on the wall between folds, in place
//! of the colon's five fixed balls; with `count` 0, a colon of folds only (nothing a detector
//! should find). Sizes are in millimetres of the grid (1 mm voxels), not scaled with the
//! anatomy like the rest of the colon, so at small sizes the polyps are large for the lumen.

use super::colon::{layout, Colon, ColonField};
use super::noise::uniform;
use super::polyp::{Polyp, PolypShape};
use super::profile::{paint, REACH_VOX, TISSUE_HU};
use super::raster::{rasterize, Field};
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;
use std::f64::consts::TAU;

/// Smallest and largest polyp diameter drawn, mm.
pub const POLYP_DIAMETER_MM: (f64, f64) = (4.0, 10.0);
/// Where between two folds a polyp stands: this range of the fold spacing after the first.
const BETWEEN: (f64, f64) = (0.35, 0.65);
/// Polyps that would have to be narrower than this to fit are drawn again, mm.
const MIN_DIAMETER_MM: f64 = 3.0;
/// No polyp within this fraction of the colon's length of either end.
const END_MARGIN: f64 = 0.05;
/// A polyp stands at most this fraction of the local lumen radius high (narrower ones where
/// the lumen is narrow), so that it never closes the lumen.
const HEIGHT_LIMIT: f64 = 0.8;
/// Free wall between two polyps' bases, and between a polyp and a fold it does not stand on, mm.
const GAP_MM: f64 = 12.0;
const FOLD_GAP_MM: f64 = 1.0;
/// Draws tried for each polyp before it is left out.
const ATTEMPTS: usize = 200;

/// Truth of the colon with drawn polyps.
#[derive(Debug, Clone, PartialEq)]
pub struct PolypColon {
    /// The colon: centreline and folds (its `polyps` list is empty).
    pub colon: Colon,
    /// The polyps, in the order drawn (fewer than asked when the wall had no room).
    pub polyps: Vec<Polyp>,
}

/// The colon of `options` (size, noise, seed) with `count` polyps drawn with `options.seed`.
pub fn colon_polyps(options: &PhantomOptions, count: usize) -> (Volume, PolypColon) {
    let (dims, mut colon) = layout(options);
    colon.polyps.clear();
    let polyps = place(&colon, count, options.seed);
    let field = PolypField {
        colon: ColonField::new(&colon, dims),
        polyps: &polyps,
        bounds: polyps.iter().map(|p| p.bounds(REACH_VOX)).collect(),
    };
    let volume = rasterize(dims, options, &field);
    (volume, PolypColon { colon, polyps })
}

/// `count` polyps drawn on the wall of `colon`: of every nine, three (one of each shape) on
/// folds and six between folds.
fn place(colon: &Colon, count: usize, seed: u64) -> Vec<Polyp> {
    let mut draws = 0u64;
    let mut next = move || {
        draws += 1;
        uniform(seed, draws)
    };
    let mut placed: Vec<Polyp> = Vec::with_capacity(count);
    for n in 0..count {
        let shape = PolypShape::ALL[n % PolypShape::ALL.len()];
        let on_fold = n / PolypShape::ALL.len() % 3 == 1;
        let found = (0..ATTEMPTS)
            .filter_map(|_| {
                let draw = [next(), next(), next(), next()];
                candidate(colon, shape, on_fold, draw).filter(|p| clear_of(p, &placed))
            })
            .next();
        placed.extend(found);
    }
    placed
}

/// The polyp of `shape` that the uniform draws `[arc, place between folds, angle, size]` give,
/// on a fold's crest or between two folds (narrowed to keep clear of them), if it fits.
fn candidate(colon: &Colon, shape: PolypShape, on_fold: bool, draw: [f64; 4]) -> Option<Polyp> {
    let line = &colon.centreline;
    let spacing = colon.fold_spacing_vox();
    let s = line.length_vox() * (END_MARGIN + (1.0 - 2.0 * END_MARGIN) * draw[0]);
    let fold = colon
        .folds
        .iter()
        .min_by(|a, b| (a.arc_vox - s).abs().total_cmp(&(b.arc_vox - s).abs()))?;
    let (centre, axis, wall_radius, room) = if on_fold {
        let crest = fold.ring_radius_vox - fold.depth_vox;
        (fold.centre_vox, fold.axis, crest, f64::INFINITY)
    } else {
        let s = ((s / spacing).floor() + BETWEEN.0 + (BETWEEN.1 - BETWEEN.0) * draw[1]) * spacing;
        let to_fold = (s / spacing - (s / spacing).round()).abs() * spacing;
        let room = 2.0 * (to_fold - FOLD_GAP_MM) - 2.0 * fold.depth_vox;
        (
            line.point_at(s),
            line.tangent_at(s),
            colon.radius_vox_at(s),
            room,
        )
    };
    let (lo, hi) = POLYP_DIAMETER_MM;
    let fits = HEIGHT_LIMIT * wall_radius / shape.height_per_diameter();
    let diameter = (lo + (hi - lo) * draw[3]).min(fits).min(room);
    if diameter < MIN_DIAMETER_MM {
        return None;
    }
    let reference = axis.any_orthonormal_vector();
    let angle = TAU * draw[2];
    let outward = reference * angle.cos() + axis.cross(reference) * angle.sin();
    Some(Polyp {
        shape,
        base_vox: centre + outward * wall_radius,
        normal: -outward,
        diameter_vox: diameter,
        on_fold,
    })
}

/// True when `polyp` leaves [`GAP_MM`] of wall to each of `placed`.
fn clear_of(polyp: &Polyp, placed: &[Polyp]) -> bool {
    placed.iter().all(|p| {
        p.base_vox.distance(polyp.base_vox) >= (p.diameter_vox + polyp.diameter_vox) / 2.0 + GAP_MM
    })
}

/// The colon's field with the polyps painted over it.
struct PolypField<'a> {
    colon: ColonField<'a>,
    polyps: &'a [Polyp],
    /// Each polyp's box grown by the boundary ramp's reach.
    bounds: Vec<(DVec3, DVec3)>,
}

impl Field for PolypField<'_> {
    fn hu_at(&self, p: DVec3) -> f64 {
        let beneath = self.colon.hu_at(p);
        self.polyps
            .iter()
            .zip(&self.bounds)
            .filter(|(_, (lo, hi))| p.cmpge(*lo).all() && p.cmple(*hi).all())
            .fold(beneath, |hu, (polyp, _)| {
                paint(hu, polyp.signed_distance(p), TISSUE_HU)
            })
    }

    /// The colon's uniform runs are tissue far from the lumen, where polyps only paint tissue.
    fn uniform_run(&self, i: usize, j: usize, k: usize) -> Option<(usize, f64)> {
        self.colon.uniform_run(i, j, k)
    }
}

#[cfg(test)]
mod tests {
    use super::super::profile::AIR_HU;
    use super::super::tests::{iso_crossing, small};
    use super::*;

    #[test]
    fn polyps_stand_on_the_wall_a_third_on_folds_apart_and_sized_as_drawn() {
        let (_, colon) = layout(&small(512));
        let polyps = place(&colon, 18, 7);
        assert_eq!(polyps.len(), 18);
        assert_eq!(polyps.iter().filter(|p| p.on_fold).count(), 6);
        assert_ne!(polyps, place(&colon, 18, 8), "the seed changes the draw");
        let line = &colon.centreline;
        for (n, p) in polyps.iter().enumerate() {
            assert_eq!(p.shape, PolypShape::ALL[n % 3]);
            assert!((MIN_DIAMETER_MM..=POLYP_DIAMETER_MM.1).contains(&p.diameter_vox));
            // The base is on the wall (or a fold's crest) and the normal points to the axis.
            let (s, distance) = line.closest(p.base_vox);
            let wall = if p.on_fold {
                let fold = colon
                    .folds
                    .iter()
                    .find(|f| (f.arc_vox - s).abs() < 1.0)
                    .unwrap();
                fold.ring_radius_vox - fold.depth_vox
            } else {
                colon.radius_vox_at(s)
            };
            assert!((distance - wall).abs() < 0.5, "{p:?}: {distance} vs {wall}");
            assert!(line.closest(p.tip_vox()).1 < distance - 0.1 * p.diameter_vox);
            for q in &polyps[..n] {
                assert!(q.base_vox.distance(p.base_vox) >= GAP_MM);
            }
        }
    }

    /// A polyp's surface is where its truth says, with tissue under the tip and air above it.
    /// The test reads the −480 HU isosurface along the normal rather than a fixed value under
    /// the tip: a pedunculated head of 3.3 voxels (the height limit narrows them where the lumen
    /// is narrow) is mostly ramp, and trilinear interpolation of its curved ramp reads −211 HU
    /// 0.8 voxel under the tip where the voxels' own field is −64 HU (its centre reads 7 HU);
    /// that lowers its isosurface by only 0.15 voxel (12 seeds at 192³ and 256³).
    #[test]
    fn polyps_are_tissue_into_the_air_and_folds_only_has_none() {
        let options = PhantomOptions {
            size: 192,
            seed: 3,
            ..PhantomOptions::default()
        };
        let (volume, truth) = colon_polyps(&options, 6);
        assert!(!truth.polyps.is_empty() && truth.colon.polyps.is_empty());
        let mid_hu = 0.5 * (AIR_HU + TISSUE_HU);
        for p in &truth.polyps {
            let above = p.tip_vox() + p.normal * 1.5;
            let surface = 1.5 - iso_crossing(&volume, above, -p.normal, (0.0, 2.5), mid_hu);
            let below = volume
                .sample_physical(p.tip_vox() - p.normal * 0.8)
                .unwrap();
            let air = volume.sample_physical(above).unwrap();
            assert!(
                surface.abs() < 0.2 && below > mid_hu && air < -900.0,
                "{p:?}: surface {surface} voxel from the tip, {below} / {air} HU"
            );
        }
        let (_, none) = colon_polyps(&options, 0);
        assert!(none.polyps.is_empty() && none.colon.polyps.is_empty());
    }
}
