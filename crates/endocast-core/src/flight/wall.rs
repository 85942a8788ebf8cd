//! How much of a lumen's wall a flight showed: the wall's [`Coverage`] recorded flying the route
//! forward (the video's own frames), then flying it back with the endoscope alone
//! ([`BackwardPass`]), and the two passes together ([`WallSeen`]): the figures, the mask volume
//! and an overview with the unseen wall tinted.

use super::error::FlightError;
use super::frames::{Flight, FlightOptions, Layout};
use super::overview::{lumen_overview, Overview};
use super::{Route, Shot};
use crate::coverage::{Coverage, CoverageError, MASK_SEEN, MASK_UNSEEN};
use crate::navigate::{DistanceField, Lumen};
use crate::path::PathError;
use crate::render::{RenderSettings, Renderer};
use crate::views::slices::Window;
use crate::views::Rgb;
use crate::Geometry;
use glam::DVec3;
use std::ops::Range;
use std::sync::Arc;

/// Sample step of the spline through the reversed route's samples, mm.
const REVERSE_STEP_MM: f64 = 0.5;

/// Colour and strength of the tint on wall never seen (neither flying forward nor back) in the
/// coverage report's overview ([`WallSeen::overview`]; the dashboard tints more lightly, over
/// its live overview).
pub const REPORT_TINT: (Rgb, f32) = ([230, 40, 40], 0.8);
/// Colour and strength of the tint on wall seen only flying back, in the report's overview.
pub const BACK_ONLY_TINT: (Rgb, f32) = ([240, 170, 20], 0.7);

/// Label of the coverage mask ([`WallSeen::mask_volume`]): wall seen flying forward.
pub const LABEL_SEEN_FORWARD: u16 = 1;
/// Label of the coverage mask: wall seen only flying back.
pub const LABEL_SEEN_BACK_ONLY: u16 = 2;
/// Label of the coverage mask: wall seen on neither pass.
pub const LABEL_UNSEEN: u16 = 3;
/// The mask's labels and what each means, for the report.
pub const MASK_LABELS: [(u16, &str); 3] = [
    (LABEL_SEEN_FORWARD, "seen flying forward"),
    (LABEL_SEEN_BACK_ONLY, "seen only flying back"),
    (LABEL_UNSEEN, "never seen"),
];

/// The wall voxels around `lumen` (its bounding box grown by one voxel, where the wall is, and
/// clipped to `geometry`'s grid), none seen yet.
pub fn wall_coverage(lumen: &Lumen, geometry: &Geometry) -> Result<Coverage, CoverageError> {
    Coverage::new(geometry, |v| lumen.is_wall(v), &wall_box(lumen, geometry))
}

/// How far from the route wall counts, in lumen radii (the largest distance from the route to
/// the wall): a wall a flight passes lies about one radius from it.
const NEAR_RADII: f64 = 2.0;

/// The wall voxels of `lumen` near the route through `points_mm` (world mm, a point every
/// millimetre or so), none seen yet: those within [`NEAR_RADII`] lumen radii of a point, the
/// radius being the largest distance from a point to the wall, plus two voxels. A route through
/// part of a lumen is measured on the wall it passes, not on the rest of the lumen. Also
/// returns that reach, mm.
pub fn wall_coverage_near(
    lumen: &Lumen,
    geometry: &Geometry,
    points_mm: &[DVec3],
) -> Result<(Coverage, f64), CoverageError> {
    let field = DistanceField::new(lumen, geometry);
    let radius = points_mm
        .iter()
        .map(|&p| field.distance_mm(p))
        .fold(0.0, f64::max);
    let reach = NEAR_RADII * radius + 2.0 * geometry.spacing_mm().max_element();
    let bbox = wall_box(lumen, geometry);
    let near = Near::around(geometry, &bbox, points_mm, reach);
    let coverage = Coverage::new(geometry, |v| near.holds(v) && lumen.is_wall(v), &bbox)?;
    Ok((coverage, reach))
}

/// The lumen's bounding box grown by one voxel, clipped to the grid.
fn wall_box(lumen: &Lumen, geometry: &Geometry) -> [Range<usize>; 3] {
    let (lo, hi) = lumen.bounds();
    let dims = geometry.dims();
    [0, 1, 2].map(|a| lo[a].saturating_sub(1)..(hi[a] + 2).min(dims[a]))
}

/// The voxels of a box within a distance of a set of points.
struct Near {
    bbox: [Range<usize>; 3],
    near: Vec<bool>,
}

impl Near {
    /// Marks the voxels of `bbox` within `reach_mm` of a point of `points_mm`, the points
    /// thinned to a tenth of the reach apart (a ball's worth of voxels per point is costly).
    fn around(
        geometry: &Geometry,
        bbox: &[Range<usize>; 3],
        points_mm: &[DVec3],
        reach_mm: f64,
    ) -> Self {
        let size = bbox.clone().map(|r| r.len());
        let mut near = vec![false; size.iter().product()];
        let to_voxel = geometry.voxel_from_world();
        let spacing = geometry.spacing_mm();
        let span = [spacing.x, spacing.y, spacing.z].map(|s| (reach_mm / s).ceil() as i64);
        let mut last: Option<DVec3> = None;
        for &p in points_mm {
            if last.is_some_and(|q| q.distance(p) < 0.1 * reach_mm) {
                continue;
            }
            last = Some(p);
            let c = to_voxel.transform_point3(p).round();
            let lo = [0, 1, 2].map(|a| (c[a] as i64 - span[a]).max(bbox[a].start as i64));
            let hi = [0, 1, 2].map(|a| (c[a] as i64 + span[a]).min(bbox[a].end as i64 - 1));
            for k in lo[2]..=hi[2] {
                for j in lo[1]..=hi[1] {
                    for i in lo[0]..=hi[0] {
                        let v = [i, j, k].map(|x| x as usize);
                        let w = geometry.world_of(DVec3::new(i as f64, j as f64, k as f64));
                        if w.distance(p) <= reach_mm {
                            let r = [0, 1, 2].map(|a| v[a] - bbox[a].start);
                            near[r[0] + size[0] * (r[1] + size[1] * r[2])] = true;
                        }
                    }
                }
            }
        }
        Self {
            bbox: bbox.clone(),
            near,
        }
    }

    fn holds(&self, v: [usize; 3]) -> bool {
        let size = self.bbox.clone().map(|r| r.len());
        let r = [0, 1, 2].map(|a| v[a] - self.bbox[a].start);
        self.near[r[0] + size[0] * (r[1] + size[1] * r[2])]
    }
}

/// The backward pass of a coverage measurement: the route flown the other way, with the
/// endoscope view alone at the forward flight's image size and field of view, recording into a
/// coverage of its own.
#[derive(Debug)]
pub struct BackwardPass {
    flight: Flight,
    shots: Vec<Shot>,
}

impl BackwardPass {
    /// The pass back along `route`, filmed like the `forward` flight (its image size and field
    /// of view), shots every `step_mm` looking `look_ahead_mm` ahead, recording into a fresh
    /// coverage of the wall `forward_seen` covers. `Ok(None)` for key frames, whose views have
    /// no natural reverse.
    pub fn new(
        renderer: Arc<Renderer>,
        route: &Route,
        forward: &FlightOptions,
        step_mm: f64,
        look_ahead_mm: f64,
        forward_seen: &Coverage,
    ) -> Result<Option<Self>, PathError> {
        let Some(back) = route.reversed(REVERSE_STEP_MM) else {
            return Ok(None);
        };
        let shots = back?.shots(step_mm, look_ahead_mm)?;
        let options = FlightOptions {
            size: forward.size,
            optics: forward.optics,
            stereo: None,
            layout: Layout::Endoscope,
            window: Window::AIR_TISSUE,
        };
        let flight = Flight::new(renderer, options).with_coverage(forward_seen.cleared());
        Ok(Some(Self { flight, shots }))
    }

    /// The shots of the pass, in the order they are flown.
    pub fn shots(&self) -> &[Shot] {
        &self.shots
    }

    /// Flies the pass with `settings`, calling `after_frame` after each frame (for progress);
    /// returns the wall it saw.
    pub fn fly(
        mut self,
        settings: &RenderSettings,
        mut after_frame: impl FnMut(),
    ) -> Result<Coverage, FlightError> {
        for (n, shot) in self.shots.iter().enumerate() {
            self.flight.frame(n, shot, settings)?;
            after_frame();
        }
        Ok(self
            .flight
            .into_coverage()
            .expect("the backward flight was made with a coverage"))
    }
}

/// What a coverage measurement found: the wall seen flying forward, and forward plus backward.
#[derive(Debug, Clone, PartialEq)]
pub struct WallSeen {
    forward: Coverage,
    both: Coverage,
}

impl WallSeen {
    /// The forward pass alone (key frames, which are not flown back): forward plus backward is
    /// the forward pass.
    pub fn forward_only(forward: Coverage) -> Self {
        Self {
            both: forward.clone(),
            forward,
        }
    }

    /// The forward pass and the backward one, merged. Both must cover the same wall.
    pub fn with_backward(forward: Coverage, backward: &Coverage) -> Result<Self, CoverageError> {
        let mut both = forward.clone();
        both.merge(backward)?;
        Ok(Self { forward, both })
    }

    /// The forward pass.
    pub fn forward(&self) -> &Coverage {
        &self.forward
    }

    /// Forward plus backward.
    pub fn both(&self) -> &Coverage {
        &self.both
    }

    /// Number of wall voxels.
    pub fn wall_voxels(&self) -> usize {
        self.forward.total()
    }

    /// Wall voxels seen flying forward.
    pub fn seen_forward(&self) -> usize {
        self.forward.seen_count()
    }

    /// Wall voxels seen flying forward or backward.
    pub fn seen_forward_backward(&self) -> usize {
        self.both.seen_count()
    }

    /// Fraction of the wall seen flying forward, 0–1.
    pub fn fraction_forward(&self) -> f64 {
        self.forward.seen_fraction()
    }

    /// Fraction of the wall seen flying forward or backward, 0–1.
    pub fn fraction_forward_backward(&self) -> f64 {
        self.both.seen_fraction()
    }

    /// The label volume on the scan's grid of what the figures count: [`LABEL_SEEN_FORWARD`]
    /// ([`WallSeen::seen_forward`] voxels), [`LABEL_SEEN_BACK_ONLY`] (with them,
    /// [`WallSeen::seen_forward_backward`]), [`LABEL_UNSEEN`] on the rest of the wall, 0 off it.
    pub fn mask_volume(&self) -> Result<crate::Volume, crate::VolumeError> {
        let both = self.both.mask();
        let voxels = self
            .forward
            .mask()
            .into_iter()
            .zip(both)
            .map(|labels| match labels {
                (MASK_SEEN, _) => LABEL_SEEN_FORWARD,
                (_, MASK_SEEN) => LABEL_SEEN_BACK_ONLY,
                (_, MASK_UNSEEN) => LABEL_UNSEEN,
                _ => 0,
            })
            .collect();
        let map = crate::ValueMap::new(1.0, 0.0)?;
        crate::Volume::new(
            *self.forward.geometry(),
            voxels,
            map,
            crate::Modality::Unknown,
        )
    }

    /// The lumen seen from the front ([`lumen_overview`], `size` pixels) with the wall never
    /// seen tinted in [`REPORT_TINT`] and the wall seen only flying back in
    /// [`BACK_ONLY_TINT`], and a legend naming them.
    pub fn overview(
        &self,
        lumen: &Lumen,
        geometry: &Geometry,
        size: [usize; 2],
    ) -> Result<Overview, FlightError> {
        let mut overview = lumen_overview(lumen, geometry, size)?;
        let [w, _] = size;
        for (n, depth) in overview.depth_mm.iter().enumerate() {
            let (x, y) = (n % w, n / w);
            let Some(hit) = depth
                .is_finite()
                .then(|| overview.camera.point_at(x, y, f64::from(*depth)))
                .flatten()
            else {
                continue;
            };
            let tint = if self.both.unseen_near(hit) {
                Some(REPORT_TINT)
            } else if self.forward.unseen_near(hit) {
                Some(BACK_ONLY_TINT)
            } else {
                None
            };
            if let Some((color, amount)) = tint {
                overview.image.blend(x as i64, y as i64, color, amount);
            }
        }
        legend(&mut overview.image);
        Ok(overview)
    }
}

/// Writes the two tints' meanings in the overview's top-left corner.
fn legend(image: &mut crate::views::Image) {
    let scale = (image.width() / 256).max(1);
    let line = 9 * scale as i64;
    image.text_shadowed(2, 2, "red: never seen", scale, REPORT_TINT.0);
    image.text_shadowed(
        2,
        2 + line,
        "orange: seen only flying back",
        scale,
        BACK_ONLY_TINT.0,
    );
}
