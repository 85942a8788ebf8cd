//! Frame-to-frame reuse in a flight or a moving view: the previous frame's depths bound where
//! the next frame's isosurface searches may start, as the second eye of a stereo pair starts
//! from the first eye's (see `render::stereo`) — the images unchanged.
//!
//! Every point in front of the previous frame's depth image lies on the eye's side of the
//! isovalue (the rays found no crossing there): with the stereo pair's conservative depth —
//! the smallest forward depth of the 3×3 pixels around, less half a voxel and two sample steps
//! — a point that projects into pixel `j` of the previous camera at a forward depth below
//! `Z_j` is known to be empty. A ray of the new camera, `p(t) = e₁ + t·d`, projects into the
//! previous image along a straight line: from its point at distance `T` towards the vanishing
//! point of `d`, the projection `u(t)` of every later point lies on the segment from `u(T)` to
//! `u(∞)`. Its forward depth grows linearly in `t`. So where the smallest `Z` over a box
//! around that segment (a min-pyramid of the previous depths answers it in four reads, see
//! `pyramid`) is `Z_box`, the ray is empty from `T` up to the `t` where its forward depth
//! reaches `Z_box`; taken again from there (a shorter segment, a smaller box), a few rounds
//! converge on the start.
//!
//! The first `T` is the clear ball around the new eye (every sample within it lies on the eye's
//! side: no iso-active brick, or all voxels on that side, see `stereo::clear`), so a ray needs
//! the previous frame only beyond it; where the previous frame says nothing (a ray leaving its
//! field, a turn, a jump, the first frame) the search still starts at the ball's edge. Starts
//! keep the ray's own sample grid, so every search finds the crossing it would have found from
//! the eye. Reuse applies where the stereo pair's sharing does (iso and hybrid with sampled
//! hits, an ideal pinhole without a near plane, the eye inside the volume) and the previous
//! frame had the same settings, size and crossing side, no scene and no per-pixel limit.

mod pyramid;
mod starts;
#[cfg(test)]
mod tests;

use super::stereo::{forward_depths_f32, SearchStarts};
use super::{Cancelled, Frame, Prepared, Quality, RenderOptions, RenderSettings, Renderer};
use crate::camera::Camera;
use glam::{DMat3, Vec3};
use pyramid::MinPyramid;
use std::sync::{Arc, Weak};

/// What a flight or a view keeps from frame to frame for [`Prepared::render_reusing`]: the
/// previous frame's camera and its depths as a min-pyramid, and the buffers of the starts.
#[derive(Debug, Clone, Default)]
pub struct FrameReuse {
    previous: Option<Previous>,
    starts: SearchStarts,
    /// The previous frame's forward depths (a buffer reused from frame to frame).
    depths: Vec<f32>,
    /// How many pixels of the last frame started late, of how many.
    late: usize,
    pixels: usize,
    /// Test only: scales the clear ball around the eye (a mutation the tests must catch).
    #[cfg(test)]
    ball_scale: f32,
}

/// The frame the next one starts from.
#[derive(Debug, Clone)]
struct Previous {
    /// Its renderer (weak: a kept frame does not keep a volume alive, and while the weak
    /// share lives no other renderer can take its address).
    renderer: Weak<Renderer>,
    settings: RenderSettings,
    camera: Camera,
    /// Whether its searches looked for a rising crossing.
    rising: bool,
    /// Its conservative forward depths (mm), as a min-pyramid.
    depths: MinPyramid,
}

impl FrameReuse {
    /// A reuse state with no previous frame.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets the previous frame: the next one starts its searches at the clear ball only.
    pub fn forget(&mut self) {
        self.previous = None;
    }

    /// The fraction of the last frame's pixels whose search started past the eye (0 where
    /// reuse did not apply).
    pub fn late_fraction(&self) -> f64 {
        if self.pixels == 0 {
            0.0
        } else {
            self.late as f64 / self.pixels as f64
        }
    }

    /// The clear ball's radius scaled by `scale` (test only: a start made too optimistic).
    #[cfg(test)]
    fn with_ball_scale(scale: f32) -> Self {
        Self {
            ball_scale: scale,
            ..Self::default()
        }
    }
}

impl Prepared {
    /// Renders `camera` into `frame` as [`Self::render_into`] does — the same image — with its
    /// isosurface searches starting past the space `reuse`'s previous frame and the clear
    /// ball around the eye show empty (see the module doc), and keeps this frame's depths in
    /// `reuse` for the next.
    pub fn render_reusing(&self, camera: &Camera, reuse: &mut FrameReuse, frame: &mut Frame) {
        // Without a cancel flag nothing can cancel it.
        let _ = self.render_reusing_with(camera, &RenderOptions::new(), reuse, frame);
    }

    /// [`Self::render_with`] with `reuse` (see [`Self::render_reusing`]) where `options` ask
    /// for a plain full-quality frame (layers, cancel flag and progress allowed); otherwise a
    /// plain render that forgets `reuse`'s previous frame. A cancelled frame is not kept (the
    /// previous one stays).
    pub fn render_reusing_with(
        &self,
        camera: &Camera,
        options: &RenderOptions<'_>,
        reuse: &mut FrameReuse,
        frame: &mut Frame,
    ) -> Result<(), Cancelled> {
        let plain = options.quality == Quality::Full
            && options.max_distance_mm.is_none()
            && options.grid_shift == 0.0
            && options.starts.is_none();
        let scene = self.scene.as_ref().is_some_and(|s| !s.is_empty());
        if !plain || scene || !self.eye_starts_late(camera) {
            reuse.forget();
            (reuse.late, reuse.pixels) = (0, 0);
            return self.render_with(camera, options, frame);
        }
        let start = std::time::Instant::now();
        let ball = self.clear_ball(camera);
        let rising = self
            .integrator(camera, options.filter)
            .rising_at(ball.0, self.params.lower.iso);
        self.fill_starts(camera, ball, rising, reuse);
        let result = self.render_with(camera, &options.search_starts(&reuse.starts), frame);
        if result.is_ok() {
            self.keep(camera, rising, frame, reuse);
            frame.stats.time = start.elapsed();
        }
        result
    }

    /// Keeps `camera`'s `frame` (its searches looked for a `rising` crossing) in `reuse` as the
    /// previous frame of the next.
    fn keep(&self, camera: &Camera, rising: bool, frame: &Frame, reuse: &mut FrameReuse) {
        let mut pyramid = reuse.previous.take().map(|p| p.depths).unwrap_or_default();
        forward_depths_f32(camera, frame, &mut reuse.depths);
        let margin = self.emptiness_margin_mm() as f32;
        pyramid.rebuild(&reuse.depths, camera.size(), margin);
        reuse.previous = Some(Previous {
            renderer: Arc::downgrade(&self.renderer),
            settings: self.settings.clone(),
            camera: *camera,
            rising,
            depths: pyramid,
        });
    }

    /// The starts of `camera`'s searches (looking for a `rising` crossing) into `reuse`: past
    /// the clear `ball` around its eye (see [`Self::clear_ball`]), and further where its
    /// previous frame was rendered as this one will be.
    fn fill_starts(
        &self,
        camera: &Camera,
        (eye, radius): (Vec3, f32),
        rising: bool,
        reuse: &mut FrameReuse,
    ) {
        #[cfg(test)]
        let radius = radius * reuse.ball_scale.max(1.0);
        let previous = reuse.previous.as_ref().filter(|p| {
            std::ptr::eq(p.renderer.as_ptr(), Arc::as_ptr(&self.renderer))
                && p.settings == self.settings
                && p.camera.size() == camera.size()
                && p.rising == rising
        });
        let scale = starts::Scale {
            voxels_per_mm: largest_stretch(&self.voxel_from_world.matrix3),
            step_mm: self.step_mm,
        };
        let previous = previous.map(|p| (&p.camera, &p.depths));
        reuse.late = match starts::Plan::new(camera, previous, (radius, scale)) {
            Some(plan) => plan.fill(&mut reuse.starts, (eye, radius)),
            None => 0,
        };
        reuse.pixels = camera.size().iter().product();
    }
}

/// An upper bound of `|m·v|` over unit vectors `v`: the square root of the largest absolute
/// row sum of `mᵀm` (which bounds its largest eigenvalue).
fn largest_stretch(m: &DMat3) -> f64 {
    let g = m.transpose() * *m;
    let rows = [g.row(0), g.row(1), g.row(2)];
    rows.iter()
        .map(|r| r.abs().element_sum())
        .fold(0.0, f64::max)
        .sqrt()
}
