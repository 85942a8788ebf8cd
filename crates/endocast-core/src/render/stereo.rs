//! A stereo pair that costs less than two frames: both eyes share the prepared state (brick
//! classification, transfer-function table) and the second eye's isosurface searches start
//! where the first eye has shown the space to be empty.
//!
//! VIVENDI shares visibility by culling once for a frustum moved back to contain both eyes.
//! The ray-casting equivalent used here shares *emptiness*: the first (left) eye's rays found
//! no surface in front of their hits, so every point in front of the left depth image lies on
//! the eye's side of the isovalue. For an off-axis pinhole pair the eyes share their image plane
//! and rows, so a right ray at column `x` of row `y` sweeps row `y` of the left image: at depth
//! `z` (along the view axis) it passes left column `x_L = x + ½ − K/f + K/z`, with
//! `K = e / tan(fov/2) · h/2` pixel·mm. Writing `g_j = j − K/Z_j` for left column `j` with
//! (conservative, see below) depth `Z_j`, the ray leaves the known-empty region at the first
//! column `j`, walking left from the image's right edge, with `g_j ≤ x + ½ − K/f`: a
//! suffix-minimum search, `O(log w)` per pixel. The part of the right ray nearer than where
//! it enters the left image's field (`x_L = w`, a fraction of a millimetre for most pixels)
//! needs no check where it lies in a ball around the eye whose samples all lie on the eye's
//! side (no iso-active brick in it, or its voxels all on that side: `clear`), and is checked
//! sample by sample elsewhere; the search then starts a margin before the end of the empty
//! part, on the ray's own sample grid, so it finds the crossing it would have found from the
//! eye. The start-up itself (`starts`) is two parallel passes over the image.
//!
//! Conservative depth: `Z_j` is the smallest forward depth of the left hits in the 3×3 pixels
//! around `(j, y)`, less a margin of half a voxel and two sample steps (the refined hit's error,
//! and surfaces bulging between neighbouring rays). The images are the same as two separate
//! renders (tested bit for bit on phantoms and scans); where the conditions do not hold —
//! not a pinhole with an ideal lens, a near plane, an eye outside the volume or on the far side
//! of the isovalue, or a mode that composites in front of the surface (DVR, two-iso, MIP) —
//! the eyes share only the prepared state.

mod clear;
mod starts;

pub(super) use starts::forward_depths as forward_depths_f32;

#[cfg(target_arch = "x86_64")]
use super::simd::rays4::LateStarts;
use super::{Filter, Frame, Mode, Prepared, RenderOptions, BRICK_VOX};

use crate::camera::{Camera, CameraError, Projection, StereoRig};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// How many bricks around the eye [`Prepared::clear_radius_vox`] looks at.
const CLEAR_BRICKS: usize = 3;

/// A stereo pair's two frames, and the buffers the second eye's start-up reuses from pair to
/// pair (fresh buffers cost page faults every frame).
#[derive(Debug, Clone, Default)]
pub struct StereoFrames {
    /// The left and the right eye's frames.
    pub eyes: [Frame; 2],
    starts: SearchStarts,
}

impl StereoFrames {
    /// The bytes a pixel of the second eye's start-up takes besides the two frames: its
    /// search starts and the first eye's depths.
    pub const SCRATCH_BYTES_PER_PIXEL: usize = size_of::<[f32; 2]>() + size_of::<f32>();
}

/// Where each pixel's isosurface search of the second eye may start (see the module doc).
#[derive(Debug, Clone, Default)]
pub(crate) struct SearchStarts {
    /// The eye in voxel space, and the radius (voxels) of a ball around it in which every
    /// sample lies on the eye's side of the isovalue (it holds no iso-active brick, or its
    /// voxels all lie on that side, see `clear`): samples inside it need no check.
    pub clear: (Vec3, f32),
    width: usize,
    /// Per pixel: the distance along the ray (mm) up to which samples must be checked one by
    /// one, and the distance from which the search may start; NaN where it starts at the eye.
    starts: Vec<[f32; 2]>,
    /// The start-up's working buffers.
    buffers: starts::Buffers,
}

impl SearchStarts {
    /// The late starts of pixels `x0 .. x0 + 4` of row `y` for the four-ray set-up, with the
    /// sample step `step` (mm); columns past the image have none.
    #[cfg(target_arch = "x86_64")]
    pub fn lanes(&self, x0: usize, y: usize, step: f32) -> LateStarts {
        let (mut check, mut start) = ([f32::NAN; 4], [f32::NAN; 4]);
        for k in 0..4 {
            if let Some(&[c, s]) = self.starts.get(x0 + k + self.width * y) {
                if x0 + k < self.width {
                    (check[k], start[k]) = (c, s);
                }
            }
        }
        LateStarts {
            check,
            start,
            clear: self.clear.1,
            step,
        }
    }

    /// Starts for an image `width` pixels wide, every pixel's set by `fill` (over the rows in
    /// parallel: the row's index and its `[check, start]`, NaN where the search starts at the
    /// eye), and the clear ball `clear` around the eye.
    pub(super) fn fill_rows(
        &mut self,
        [width, height]: [usize; 2],
        clear: (Vec3, f32),
        fill: impl Fn(usize, &mut [[f32; 2]]) + Sync,
    ) {
        self.clear = clear;
        self.width = width;
        self.starts.resize(width * height, [f32::NAN; 2]);
        self.starts
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(y, row)| fill(y, row));
    }

    /// The check distance and the start of pixel `(x, y)`, if it has a start past the eye.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> Option<(f32, f32)> {
        let [check, start] = self.starts[x + self.width * y];
        (!start.is_nan()).then_some((check, start))
    }
}

impl Prepared {
    /// Renders the left and right eyes of `camera` under `rig` into `pair` (its frames and
    /// working buffers reused), the right eye's searches starting past the space the left eye
    /// showed empty where that is exact (see the module doc). The images are those of two
    /// independent renders of [`StereoRig::eyes`].
    pub fn render_stereo_into(
        &self,
        camera: &Camera,
        rig: &StereoRig,
        pair: &mut StereoFrames,
    ) -> Result<(), CameraError> {
        self.render_stereo_with(camera, rig, &RenderOptions::new(), pair)
    }

    /// [`Self::render_stereo_into`] with each eye rendered as `options` ask (their layers,
    /// grid shift, unlit; a cancel flag in them is not watched): a look's ray pass shares the
    /// right eye's search starts this way.
    pub(crate) fn render_stereo_with(
        &self,
        camera: &Camera,
        rig: &StereoRig,
        options: &RenderOptions<'_>,
        pair: &mut StereoFrames,
    ) -> Result<(), CameraError> {
        let [left, right] = rig.eyes(camera)?;
        let [left_frame, right_frame] = &mut pair.eyes;
        let options = RenderOptions {
            cancel: None,
            ..*options
        };
        // Without a cancel flag nothing can cancel them.
        let _ = self.render_with(&left, &options, left_frame);
        if self.shares_emptiness(&left, &right) {
            let starts = &mut pair.starts;
            self.search_starts((&left, left_frame), &right, rig, starts);
            let _ = self.render_with(&right, &options.search_starts(starts), right_frame);
        } else {
            let _ = self.render_with(&right, &options, right_frame);
        }
        Ok(())
    }

    /// [`Self::render_stereo_into`] into new frames: the left and the right eye's.
    pub fn render_stereo(
        &self,
        camera: &Camera,
        rig: &StereoRig,
    ) -> Result<[Frame; 2], CameraError> {
        let mut pair = StereoFrames::default();
        self.render_stereo_into(camera, rig, &mut pair)?;
        Ok(pair.eyes)
    }

    /// The distance along the view axis (mm) of the nearest surface `camera` sees — the 5th
    /// percentile of the hit depths of a render 64 pixels high — a focus distance that puts
    /// the scene behind the screen; `None` where nothing is hit (or in a mode without hits).
    pub fn nearest_surface_mm(&self, camera: &Camera) -> Option<f64> {
        let [w, h] = camera.size();
        let small_h = h.min(64);
        let small_w = (w * small_h / h).max(1);
        let small = camera.with_size([small_w, small_h]).ok()?;
        let frame = self.render(&small);
        let mut depths = forward_depths(&small, &frame);
        depths.retain(|d| d.is_finite());
        if depths.is_empty() {
            return None;
        }
        let k = depths.len() / 20;
        let (_, nth, _) = depths.select_nth_unstable_by(k, f64::total_cmp);
        Some(*nth)
    }

    /// The distance (voxels) from `eye` to the nearest brick that may hold the isosurface,
    /// looked for up to [`CLEAR_BRICKS`] bricks away (0 where the eye's own brick may).
    fn clear_radius_vox(&self, eye: Vec3) -> f32 {
        let grid = &self.renderer.grid;
        let bricks = grid.bricks();
        let edge = BRICK_VOX as f32;
        let home = grid.brick_at(eye);
        if self.activity.iso.get(home) {
            return 0.0;
        }
        let centre = (eye / edge).floor().as_ivec3();
        let reach = CLEAR_BRICKS as i32;
        let mut nearest = edge * reach as f32;
        for k in -reach..=reach {
            for j in -reach..=reach {
                for i in -reach..=reach {
                    let b = centre + glam::IVec3::new(i, j, k);
                    let inside = (0..3).all(|a| b[a] >= 0 && (b[a] as usize) < bricks[a]);
                    if !inside {
                        continue;
                    }
                    let index = grid.index(b.to_array().map(|c| c as usize));
                    if self.activity.iso.get(index) {
                        let lo = b.as_vec3() * edge;
                        let gap = (lo - eye).max(eye - (lo + edge)).max(Vec3::ZERO);
                        nearest = nearest.min(gap.length());
                    }
                }
            }
        }
        nearest
    }

    /// Whether the right eye's searches may start from the left eye's emptiness.
    fn shares_emptiness(&self, left: &Camera, right: &Camera) -> bool {
        [left, right].into_iter().all(|c| self.eye_starts_late(c))
    }

    /// Whether `camera`'s isosurface searches may start late, past space shown to be empty: the
    /// mode walks samples from the eye up to the surface (iso and hybrid; the exact search
    /// walks cells, not samples, and has no samples to start late), the camera is a pinhole
    /// with an ideal lens and no near plane, and its eye lies inside the volume on the side of
    /// the isovalue its searches start from.
    pub(super) fn eye_starts_late(&self, camera: &Camera) -> bool {
        let integrator = self.integrator(camera, Filter::Trilinear);
        let surface_first = matches!(self.settings.mode, Mode::Iso | Mode::Hybrid);
        let pinhole = camera.projection() == Projection::Pinhole && camera.lens().is_ideal();
        let sampled = surface_first && integrator.sampled_hits();
        let Some(eye) = camera
            .shared_origin()
            .filter(|_| sampled && pinhole && camera.near_mm() == 0.0)
        else {
            return false;
        };
        let iso = self.params.lower.iso;
        let dims = self.renderer.volume.dims();
        let extent = DVec3::from(dims.map(|n| (n - 1) as f64));
        let eye = self.voxel_from_world.transform_point3(eye);
        let inside = eye.cmpge(DVec3::ZERO).all() && eye.cmple(extent).all();
        // The search's crossing direction is the one the eye's own value implies.
        inside && {
            let eye = eye.as_vec3();
            integrator.rising_at(eye, iso) == (integrator.sampler.value(eye) < iso)
        }
    }

    /// The right eye's per-pixel search starts from the left eye's depth image, and the clear
    /// ball around the right eye.
    fn search_starts(
        &self,
        (left, left_frame): (&Camera, &Frame),
        right: &Camera,
        rig: &StereoRig,
        out: &mut SearchStarts,
    ) {
        let [_, h] = right.size();
        let tan_half = (right.fov_deg().to_radians() / 2.0).tan();
        let geometry = starts::Geometry {
            k: rig.eye_separation_mm / tan_half * h as f64 / 2.0,
            focus_mm: rig.focus_mm,
            margin: self.emptiness_margin_mm(),
            min_gain: 2.0 * self.step_mm,
        };
        let left = (left, left_frame);
        starts::fill(left, right, geometry, &mut out.buffers, &mut out.starts);
        out.clear = self.clear_ball(right);
        out.width = right.size()[0];
    }

    /// What the depths of a frame lose before they bound another camera's searches, mm: half a
    /// voxel and two sample steps (the refined hit's error, and surfaces bulging between
    /// neighbouring rays).
    pub(super) fn emptiness_margin_mm(&self) -> f64 {
        let spacing = self.renderer.volume.geometry().spacing_mm().max_element();
        0.5 * spacing + 2.0 * self.step_mm
    }

    /// `camera`'s eye in voxel space and the radius (voxels) of a ball around it in which every
    /// sample lies on the eye's side of the isovalue: no iso-active brick in it, or its voxels
    /// all on that side (see `clear`).
    pub(super) fn clear_ball(&self, camera: &Camera) -> (Vec3, f32) {
        let eye = camera.shared_origin().unwrap_or_else(|| camera.eye_mm());
        let eye = self.voxel_from_world.transform_point3(eye).as_vec3();
        // The eye's side: the one its searches start from (`eye_starts_late`).
        let iso = self.params.lower.iso;
        let below = self.renderer.sampler().value(eye) < iso;
        let voxels = clear::clear_radius(&self.renderer.volume, eye, iso, below);
        (eye, self.clear_radius_vox(eye).max(voxels))
    }
}

/// Any camera's hit depths along its view axis (mm); `+∞` where a ray hit nothing.
fn forward_depths(camera: &Camera, frame: &Frame) -> Vec<f64> {
    let [w, _] = camera.size();
    frame
        .depth_mm
        .par_iter()
        .enumerate()
        .map(|(i, &d)| match camera.pixel_ray(i % w, i / w) {
            Some(ray) if d.is_finite() => f64::from(d) * ray.dir.dot(camera.forward()),
            _ => f64::INFINITY,
        })
        .collect()
}
