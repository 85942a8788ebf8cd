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
//! it enters the left image's field (`x_L = w`, a fraction of a millimetre for most pixels) is
//! checked sample by sample; the search then starts a margin before the end of the empty part,
//! on the ray's own sample grid, so it finds the crossing it would have found from the eye.
//!
//! Conservative depth: `Z_j` is the smallest forward depth of the left hits in the 3×3 pixels
//! around `(j, y)`, less a margin of half a voxel and two sample steps (the refined hit's error,
//! and surfaces bulging between neighbouring rays). The images are the same as two separate
//! renders (tested bit for bit on phantoms and scans); where the conditions do not hold —
//! not a pinhole with an ideal lens, a near plane, an eye outside the volume or on the far side
//! of the isovalue, or a mode that composites in front of the surface (DVR, two-iso, MIP) —
//! the eyes share only the prepared state.

use super::{Frame, Mode, Prepared};
use crate::camera::{Camera, CameraError, Projection, StereoRig};
use glam::DVec3;
use rayon::prelude::*;

/// Where each pixel's isosurface search of the second eye may start (see the module doc).
#[derive(Debug, Clone, Default)]
pub(crate) struct SearchStarts {
    width: usize,
    /// Per pixel: the distance along the ray (mm) up to which samples must be checked one by
    /// one, and the distance from which the search may start; NaN where it starts at the eye.
    starts: Vec<[f32; 2]>,
}

impl SearchStarts {
    /// The check distance and the start of pixel `(x, y)`, if it has a start past the eye.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> Option<(f32, f32)> {
        let [check, start] = self.starts[x + self.width * y];
        (!start.is_nan()).then_some((check, start))
    }
}

impl Prepared<'_> {
    /// Renders the left and right eyes of `camera` under `rig` into `frames` (their buffers
    /// reused), the right eye's searches starting past the space the left eye showed empty
    /// where that is exact (see the module doc). The images are those of two independent
    /// renders of [`StereoRig::eyes`].
    pub fn render_stereo_into(
        &self,
        camera: &Camera,
        rig: &StereoRig,
        frames: &mut [Frame; 2],
    ) -> Result<(), CameraError> {
        let [left, right] = rig.eyes(camera)?;
        let [left_frame, right_frame] = frames;
        self.render_into(&left, left_frame);
        match self.shares_emptiness(&left, &right) {
            true => {
                let starts = self.search_starts(&left, &right, rig, left_frame);
                self.render_with_starts(&right, right_frame, Some(&starts));
            }
            false => self.render_into(&right, right_frame),
        }
        Ok(())
    }

    /// [`Self::render_stereo_into`] into new frames.
    pub fn render_stereo(
        &self,
        camera: &Camera,
        rig: &StereoRig,
    ) -> Result<[Frame; 2], CameraError> {
        let mut frames = [Frame::default(), Frame::default()];
        self.render_stereo_into(camera, rig, &mut frames)?;
        Ok(frames)
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

    /// Whether the right eye's searches may start from the left eye's emptiness.
    fn shares_emptiness(&self, left: &Camera, right: &Camera) -> bool {
        let pinhole = |c: &Camera| c.projection() == Projection::Pinhole && c.lens().is_ideal();
        let surface_first = matches!(self.settings.mode, Mode::Iso | Mode::Hybrid);
        if !(surface_first && pinhole(left) && left.near_mm() == 0.0) {
            return false;
        }
        let integrator = self.integrator(left);
        let iso = self.params.lower.iso;
        let dims = self.renderer.volume.dims();
        let extent = DVec3::from(dims.map(|n| (n - 1) as f64));
        [left, right].into_iter().all(|camera| {
            let Some(eye) = camera.shared_origin() else {
                return false;
            };
            let eye = self.voxel_from_world.transform_point3(eye);
            let inside = eye.cmpge(DVec3::ZERO).all() && eye.cmple(extent).all();
            // The search's crossing direction is the one the eye's own value implies.
            inside && {
                let eye = eye.as_vec3();
                integrator.rising_at(eye, iso) == (integrator.sampler.value(eye) < iso)
            }
        })
    }

    /// The right eye's per-pixel search starts from the left eye's depth image.
    fn search_starts(
        &self,
        left: &Camera,
        right: &Camera,
        rig: &StereoRig,
        left_frame: &Frame,
    ) -> SearchStarts {
        let [w, h] = right.size();
        let tan_half = (right.fov_deg().to_radians() / 2.0).tan();
        let k = rig.eye_separation_mm / tan_half * h as f64 / 2.0;
        let spacing = self.renderer.volume.geometry().spacing_mm().max_element();
        let margin = 0.5 * spacing + 2.0 * self.step_mm;
        let forward_depth = forward_depths(left, left_frame);
        let mut starts = vec![[f32::NAN; 2]; w * h];
        starts.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            let columns = RowBounds::new(&forward_depth, [w, h], y, k, margin);
            for (x, start) in row.iter_mut().enumerate() {
                let q = x as f64 + 0.5 - k / rig.focus_mm;
                let Some((z_enter, z_safe)) = columns.empty_span(q, k) else {
                    continue;
                };
                let Some(ray) = right.pixel_ray(x, y) else {
                    continue;
                };
                let cos = ray.dir.dot(right.forward());
                let (check, skip) = (z_enter / cos, z_safe / cos);
                if skip > check + 2.0 * self.step_mm {
                    *start = [check as f32, skip as f32];
                }
            }
        });
        SearchStarts { width: w, starts }
    }
}

/// The left eye's hit depths along its view axis (mm); `+∞` where a ray hit nothing.
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

/// One row of the left image as the right rays of that row see it.
struct RowBounds {
    /// Per left column `j`: the conservative empty depth `Z_j` (mm).
    depth: Vec<f64>,
    /// Suffix minima of `g_j = j − K/Z_j`: `suffix[j] = min over i ≥ j`, non-decreasing.
    suffix: Vec<f64>,
}

impl RowBounds {
    /// Row `y` of `depths` (`[w, h]`), each column's depth the 3×3 minimum less `margin`.
    fn new(depths: &[f64], [w, h]: [usize; 2], y: usize, k: f64, margin: f64) -> Self {
        let rows = y.saturating_sub(1)..=(y + 1).min(h - 1);
        let column_min: Vec<f64> = (0..w)
            .map(|j| {
                rows.clone()
                    .map(|r| depths[r * w + j])
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        let depth: Vec<f64> = (0..w)
            .map(|j| {
                let around = &column_min[j.saturating_sub(1)..=(j + 1).min(w - 1)];
                around.iter().copied().fold(f64::INFINITY, f64::min) - margin
            })
            .collect();
        let mut suffix = vec![f64::INFINITY; w];
        let mut running = f64::INFINITY;
        for j in (0..w).rev() {
            let g = if depth[j] > 0.0 {
                j as f64 - k / depth[j]
            } else {
                f64::NEG_INFINITY
            };
            running = running.min(g);
            suffix[j] = running;
        }
        Self { depth, suffix }
    }

    /// For the right ray with `q = x + ½ − K/f`: the depth where it enters the left image
    /// (`x_L = w`) and the depth where it leaves the known-empty region; `None` where it never
    /// enters or leaves at once.
    fn empty_span(&self, q: f64, k: f64) -> Option<(f64, f64)> {
        let w = self.depth.len();
        if w as f64 - q <= 0.0 {
            return None;
        }
        let z_enter = k / (w as f64 - q);
        let lo = q.floor().max(0.0) as usize;
        // The largest column j ≥ lo with g_j ≤ q: the last suffix minimum ≤ q.
        let count = self.suffix[lo.min(w)..].partition_point(|&m| m <= q);
        let z_safe = if count > 0 {
            let j = lo + count - 1;
            let z_entry = k / (j as f64 + 1.0 - q);
            z_entry.max(self.depth[j])
        } else if q < 0.0 {
            // Leaves the left image through its left edge.
            k / -q
        } else {
            f64::INFINITY
        };
        (z_safe > z_enter).then_some((z_enter, z_safe))
    }
}
