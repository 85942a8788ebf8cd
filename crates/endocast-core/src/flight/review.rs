//! The review of what a flight missed: the unseen wall split into patches
//! ([`UnseenPatch`]), a camera that sees each ([`PatchView`]), and the views rendered and added
//! to the coverage ([`review`]): "coverage recomputed with them".
//!
//! **The pose** of a patch is chosen among candidate eyes: the route's points (the reader stays
//! on the path) and points in the lumen near the patch — along the wall's normal at the centroid
//! and on the way from the centroid to the nearest route point — at least [`SAFE_MM`] from the
//! wall (or half the lumen's radius there, when that is less). An eye qualifies when the ray from
//! it to the centroid runs through the lumen; among those, the one that sees the largest share
//! of the patch's voxels (each checked by its own ray), facing the wall most squarely, wins. The
//! field of view holds the patch's visible voxels seen from there, with a margin, between
//! [`MIN_FOV_DEG`] and [`MAX_FOV_DEG`].

use super::error::FlightError;
use super::frames::{Flight, FlightOptions, Layout};
use super::wall::{wall_coverage_near, BackwardPass, WallSeen};
use super::{Route, Shot};
use crate::coverage::{Coverage, UnseenPatch};
use crate::look::Look;
use crate::navigate::{DistanceField, Lumen};
use crate::pose::Pose;
use crate::render::{RenderSettings, Renderer};
use crate::views::slices::Window;
use crate::views::{Image, Rgb};
use crate::Geometry;
use glam::DVec3;
use std::sync::Arc;

/// The reviewed area Pickhardt et al. report on: missed regions of this many mm² or more.
pub const REVIEW_AREA_MM2: f64 = 300.0;
/// Patches smaller than this are not listed by default, mm² (a few voxels of noise on a CT).
pub const DEFAULT_MIN_AREA_MM2: f64 = 10.0;
/// Colour and strength of the tint on the wall the flight never saw in each patch's view: the
/// patch (and any other unseen wall in sight) stands out while its shape stays readable.
pub const VIEW_TINT: (Rgb, f32) = ([230, 40, 40], 0.45);
/// Distance between a review flight's frames along the route by default, mm.
pub const REVIEW_STEP_MM: f64 = 1.0;
/// Size of a review flight's frames and its patches' views by default, pixels.
pub const REVIEW_FRAME_PX: [usize; 2] = [256, 256];
/// How far a review eye off the route keeps from the wall, mm (less in a narrower lumen).
pub const SAFE_MM: f64 = 3.0;
/// Narrowest field of view of a patch's view, degrees.
pub const MIN_FOV_DEG: f64 = 30.0;
/// Widest field of view of a patch's view, degrees.
pub const MAX_FOV_DEG: f64 = 120.0;
/// How far a listed patch reaches from where it starts, in the lumen's largest radius: wider
/// regions are listed in pieces, each with its own view.
const PATCH_EXTENT_RADII: f64 = 1.5;
/// Margin added to the angle a patch spans, degrees.
const FOV_MARGIN_DEG: f64 = 10.0;
/// Patch voxels checked for visibility from a candidate eye (spread over the patch).
const SAMPLES: usize = 24;
/// Distances from the centroid along the wall's normal tried as eyes, in local lumen radii.
const NORMAL_STEPS: [f64; 4] = [0.5, 1.0, 1.5, 2.0];
/// Fractions of the way from the centroid to the nearest route point tried as eyes.
const TOWARDS_ROUTE: [f64; 3] = [0.4, 0.6, 0.8];

/// A patch of unseen wall and the camera that shows it.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchView {
    /// The patch.
    pub patch: UnseenPatch,
    /// The camera: eye in the lumen, looking at the patch's centroid.
    pub pose: Pose,
    /// Vertical field of view that holds the patch, degrees.
    pub fov_deg: f64,
    /// Whether the ray from the eye to the centroid runs through the lumen; `false` when no
    /// candidate eye has such a ray (the pose is then the nearest route point's, looking at it).
    pub clear: bool,
}

/// Where review cameras can stand: the lumen, its distance field and the route.
#[derive(Debug)]
pub struct ReviewSite<'a> {
    lumen: &'a Lumen,
    field: DistanceField,
    geometry: Geometry,
    route_mm: Vec<DVec3>,
}

/// A candidate eye and how well it sees a patch.
struct Candidate {
    eye: DVec3,
    score: f64,
    fov_deg: f64,
}

impl<'a> ReviewSite<'a> {
    /// The site of `lumen` in a volume of `geometry`, along the route through `route_mm`
    /// (world mm, about a point per millimetre).
    pub fn new(lumen: &'a Lumen, geometry: &Geometry, route_mm: Vec<DVec3>) -> Self {
        Self {
            lumen,
            field: DistanceField::new(lumen, geometry),
            geometry: *geometry,
            route_mm,
        }
    }

    /// The view of `patch` (see the module documentation).
    pub fn view_of(&self, patch: UnseenPatch) -> PatchView {
        let target = patch.centroid_mm;
        let nearest = self.nearest_route_point(target);
        let best = self
            .candidates(&patch, nearest)
            .filter(|&eye| self.clear(eye, target))
            .map(|eye| self.judge(eye, &patch))
            .fold(None::<Candidate>, |best, c| match best {
                Some(b) if b.score >= c.score => Some(b),
                _ => Some(c),
            });
        let (eye, fov_deg, clear) = match best {
            Some(c) => (c.eye, c.fov_deg, true),
            None => (nearest, MAX_FOV_DEG, false),
        };
        PatchView {
            pose: Pose {
                eye_mm: eye,
                look_at_mm: target,
                up: up_for(target - eye),
            },
            fov_deg,
            clear,
            patch,
        }
    }

    /// The route's point nearest `p_mm` (the route has at least one point).
    fn nearest_route_point(&self, p_mm: DVec3) -> DVec3 {
        let by_distance = |a: &&DVec3, b: &&DVec3| a.distance(p_mm).total_cmp(&b.distance(p_mm));
        *self.route_mm.iter().min_by(by_distance).unwrap_or(&p_mm)
    }

    /// Candidate eyes for `patch`: the route's points, then points in the lumen near the
    /// patch that keep a safe distance from the wall.
    fn candidates<'s>(
        &'s self,
        patch: &UnseenPatch,
        nearest: DVec3,
    ) -> impl Iterator<Item = DVec3> + 's {
        let target = patch.centroid_mm;
        let radius = self.field.distance_mm(nearest).max(self.spacing());
        let safe = SAFE_MM.min(0.5 * radius);
        let along_normal = NORMAL_STEPS.map(|r| target + patch.normal * r * radius);
        let towards = TOWARDS_ROUTE.map(|t| target.lerp(nearest, t));
        let off_route = along_normal.into_iter().chain(towards);
        let off_route = off_route.filter(move |&eye| self.field.distance_mm(eye) >= safe);
        self.route_mm.iter().copied().chain(off_route)
    }

    /// The largest voxel spacing, mm.
    fn spacing(&self) -> f64 {
        self.geometry.spacing_mm().max_element()
    }

    /// Whether the segment from `eye` to the wall point `target` runs through the lumen up to
    /// a voxel and a half before the target (the wall voxel and the surface crossing before it).
    fn clear(&self, eye: DVec3, target: DVec3) -> bool {
        let length = eye.distance(target);
        let stop = 1.5 * self.spacing();
        let step = 0.5 * self.geometry.spacing_mm().min_element();
        let steps = ((length - stop) / step).ceil().max(0.0) as usize;
        let to_voxel = self.geometry.voxel_from_world();
        (0..=steps).all(|n| {
            let p = eye.lerp(target, (n as f64 * step / length).min(1.0));
            let v = to_voxel.transform_point3(p).round();
            v.min_element() >= 0.0 && self.lumen.contains([v.x, v.y, v.z].map(|x| x as usize))
        })
    }

    /// How well `eye` sees `patch`: the share of its sampled voxels in clear sight, weighted by
    /// how squarely the eye faces the wall at the centroid; and the field that holds them.
    fn judge(&self, eye: DVec3, patch: &UnseenPatch) -> Candidate {
        let axis = (patch.centroid_mm - eye).normalize_or_zero();
        let stride = patch.voxels.len().div_ceil(SAMPLES).max(1);
        let (mut visible, mut total, mut widest) = (0_usize, 0_usize, 0.0_f64);
        for v in patch.voxels.iter().step_by(stride) {
            let p = self.geometry.world_of(DVec3::from(v.map(|x| x as f64)));
            total += 1;
            if self.clear(eye, p) {
                visible += 1;
                widest = widest.max(axis.angle_between((p - eye).normalize_or_zero()));
            }
        }
        let fov_deg = (2.0 * widest.to_degrees() + FOV_MARGIN_DEG).clamp(MIN_FOV_DEG, MAX_FOV_DEG);
        let facing = patch.normal.dot(-axis).max(0.0);
        // A patch wider than the widest field is seen only in part.
        let fits = (MAX_FOV_DEG / (2.0 * widest.to_degrees())).min(1.0);
        let score = visible as f64 / total as f64 * (0.3 + 0.7 * facing) * fits;
        Candidate {
            eye,
            score,
            fov_deg,
        }
    }
}

/// Superior (+z, LPS) made perpendicular to `view`, else anterior when looking up or down.
pub(crate) fn up_for(view: DVec3) -> DVec3 {
    let view = view.normalize_or(DVec3::Y);
    let up = DVec3::Z - view * view.z;
    if up.length() > 0.1 {
        up.normalize()
    } else {
        (-DVec3::Y - view * -view.y).normalize_or(DVec3::X)
    }
}

/// What a review is asked to do.
#[derive(Debug, Clone)]
pub struct ReviewRequest {
    /// The render settings of the flight and the views.
    pub settings: RenderSettings,
    /// The look of the views (`None`: the renderer's own image); the flight, whose frames only
    /// count the wall, is rendered plain.
    pub look: Option<Look>,
    /// How the flight and the views are filmed (the views keep the size and optics, with the
    /// field of view their patch needs; the layout is the endoscope's).
    pub flight: FlightOptions,
    /// Distance between the flight's frames along the route, mm.
    pub step_mm: f64,
    /// How far ahead the flight looks, mm.
    pub look_ahead_mm: f64,
    /// Fly the route back too (a two-way flight) before listing what was missed.
    pub both_ways: bool,
    /// Smallest patch listed and visited, mm².
    pub min_area_mm2: f64,
}

/// What a review found.
#[derive(Debug, Clone)]
pub struct Review {
    /// The flight's coverage (forward, and back when flown back).
    pub flight: WallSeen,
    /// How far from the route the wall is counted, mm.
    pub reach_mm: f64,
    /// The patches missed (at least the smallest area asked for), largest first, with the
    /// camera that sees each.
    pub views: Vec<PatchView>,
    /// How many of each view's patch voxels its own frame saw (same order as `views`).
    pub seen_by_view: Vec<usize>,
    /// Every unseen patch after the flight, however small: how many (regions wider than
    /// 1.5 lumen radii counted in pieces of that reach).
    pub patches_total: usize,
    /// The flight's coverage with the views' frames added.
    pub after: Coverage,
    /// The coverage (0–1) once the views `0..=n` are added, for each `n` (same order as
    /// `views`): what a reader who has visited the first patches has seen.
    pub after_each: Vec<f64>,
}

impl Review {
    /// The coverage the flight reached (both ways when flown back).
    pub fn before(&self) -> &Coverage {
        self.flight.both()
    }
}

/// Flies `route` through `lumen` as `request` says, lists the patches it missed and renders a
/// view of each (handed to `on_view` with its index; the wall the flight never saw tinted in
/// [`VIEW_TINT`]), adding the views to the coverage.
/// `after_frame` is called after each frame of the flight (for progress).
pub fn review<E: From<FlightError>>(
    renderer: &Arc<Renderer>,
    lumen: &Lumen,
    route: &Route,
    request: &ReviewRequest,
    mut after_frame: impl FnMut(),
    mut on_view: impl FnMut(usize, &PatchView, &Image) -> Result<(), E>,
) -> Result<Review, E> {
    let geometry = *renderer.volume().geometry();
    let route_mm = route.points_mm(1.0).map_err(FlightError::from)?;
    let (wall, reach_mm) =
        wall_coverage_near(lumen, &geometry, &route_mm).map_err(FlightError::from)?;
    let settings = &request.settings;
    let flight = fly(renderer, route, request, wall, &mut after_frame)?;
    let site = ReviewSite::new(lumen, &geometry, route_mm);
    let before = flight.both();
    let extent = PATCH_EXTENT_RADII * site.field.max_mm();
    let patches = before.unseen_patches(|v| lumen.contains(v), extent);
    let patches_total = patches.len();
    let views: Vec<PatchView> = patches
        .into_iter()
        .take_while(|p| p.area_mm2 >= request.min_area_mm2)
        .map(|p| site.view_of(p))
        .collect();
    let options = FlightOptions {
        layout: Layout::Endoscope,
        stereo: None,
        ..request.flight.clone()
    };
    let mut camera = Flight::new(Arc::clone(renderer), options);
    camera.set_look(request.look.clone());
    let mut after = before.clone();
    let mut seen_by_view = Vec::with_capacity(views.len());
    let mut after_each = Vec::with_capacity(views.len());
    for (n, view) in views.iter().enumerate() {
        camera.set_coverage(Some(after.cleared()));
        let (mut image, _) = camera.frame(n, &view_shot(view), settings)?;
        if let Some((seen_from, depth)) = camera.last_view() {
            let (color, amount) = VIEW_TINT;
            before
                .tint_unseen(&mut image, &seen_from, depth, color, amount)
                .map_err(FlightError::from)?;
        }
        let own = camera
            .set_coverage(None)
            .expect("the view was given a coverage");
        seen_by_view.push(view.patch.seen_in(&own));
        after.merge(&own).map_err(FlightError::from)?;
        after_each.push(after.seen_fraction());
        on_view(n, view, &image)?;
    }
    Ok(Review {
        flight,
        reach_mm,
        views,
        seen_by_view,
        patches_total,
        after,
        after_each,
    })
}

/// The shot of a patch's view.
fn view_shot(view: &PatchView) -> Shot {
    Shot {
        pose: view.pose,
        arc_mm: 0.0,
        tangent: (view.pose.look_at_mm - view.pose.eye_mm).normalize_or(DVec3::Z),
        fov_deg: Some(view.fov_deg),
        look: None,
    }
}

/// Flies `route` forward recording into `wall`, and back when asked.
fn fly(
    renderer: &Arc<Renderer>,
    route: &Route,
    request: &ReviewRequest,
    wall: Coverage,
    after_frame: &mut impl FnMut(),
) -> Result<WallSeen, FlightError> {
    let settings = &request.settings;
    let options = FlightOptions {
        layout: Layout::Endoscope,
        stereo: None,
        window: Window::AIR_TISSUE,
        ..request.flight.clone()
    };
    let (step, ahead) = (request.step_mm, request.look_ahead_mm);
    let mut flight = Flight::new(Arc::clone(renderer), options.clone()).with_coverage(wall);
    for (n, shot) in route.shots(step, ahead)?.iter().enumerate() {
        flight.frame(n, shot, settings)?;
        after_frame();
    }
    let forward = flight
        .into_coverage()
        .expect("the flight was given a coverage");
    if !request.both_ways {
        return Ok(WallSeen::forward_only(forward));
    }
    let back = BackwardPass::new(Arc::clone(renderer), route, &options, step, ahead, &forward)?;
    let Some(back) = back else {
        return Ok(WallSeen::forward_only(forward));
    };
    let backward = back.fly(settings, after_frame)?;
    Ok(WallSeen::with_backward(forward, &backward)?)
}

#[cfg(test)]
mod tests;
