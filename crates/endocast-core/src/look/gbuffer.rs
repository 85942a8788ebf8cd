//! The ray pass: one march per pixel into a [`GBuffer`] (tissue depth, hit position, normal,
//! secretion, hit mask), the only stage of a look that samples the volume.

use super::clipped::clipped_pixels;
use super::secretion::{Continuation, TissueHits};
use super::settings::{RayPassSettings, SecretionMode};
use super::LookError;
use crate::camera::Camera;
use crate::render::quality::{reduced_camera, upsample};
use crate::render::{
    Crossing, Filter, Frame, Mode, Prepared, Quality, RenderOptions, RenderSettings, RenderStats,
    Renderer,
};
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;

/// What the ray pass wrote per pixel (row 0 at the top, pixel `(x, y)` at `x + width · y`).
/// A pixel without a tissue hit has NaN depth, position and normal, and no secretion.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GBuffer {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Distance from the eye to the tissue along the ray, mm.
    pub depth_mm: Vec<f32>,
    /// World position of the tissue hit, mm.
    pub hit_mm: Vec<[f32; 3]>,
    /// Unit world normal of the tissue at the hit (central differences in the volume),
    /// pointing into the tissue.
    pub normal: Vec<[f32; 3]>,
    /// Secretion in front of the tissue along the ray, mm: the distance from the first
    /// secretion hit to the tissue ([`SecretionMode::On`]) or the length of the ray above the
    /// secretion threshold ([`SecretionMode::Accumulate`]); 0 without secretion. The tissue's
    /// own blurred edge, which passes both thresholds on the way into bare tissue too, is not
    /// counted: a last stretch into the tissue no longer than a bare edge's (from the value's
    /// slope at the hit) is left out, so bare walls carry no film of secretion.
    pub secretion_mm: Vec<f32>,
    /// Unit world normal of the secretion's upper boundary where the ray first met it (the
    /// paper's Figure 3 alternative: the surface of the viscous material found as the tissue's
    /// is), up the value gradient; NaN where the ray met no secretion. Empty without secretion
    /// and below full quality (the shading then takes the tissue's normal).
    pub secretion_normal: Vec<[f32; 3]>,
    /// Whether pixel `i`'s ray starts inside the tissue (the eye or the near plane placed in
    /// the wall): the deferred stage lays a colour overlay there. Empty when none does.
    pub clipped: Vec<bool>,
    /// The ray pass's counters (its time included).
    pub stats: RenderStats,
}

impl GBuffer {
    /// The bytes a pixel takes: depth, hit position, normal, secretion, its surface's normal
    /// and whether the tissue is clipped.
    pub const BYTES_PER_PIXEL: usize =
        2 * size_of::<f32>() + 3 * size_of::<[f32; 3]>() + size_of::<bool>();

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    /// Whether the buffer has no pixel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The hit mask: whether pixel `i`'s ray met the tissue.
    pub fn hit(&self, i: usize) -> bool {
        !self.depth_mm[i].is_nan()
    }

    /// Pixel `i`'s eight channels as the smoothing filters them: depth, hit position (x, y,
    /// z), normal (x, y, z), secretion.
    #[cfg(test)]
    pub(crate) fn texel(&self, i: usize) -> [f32; 8] {
        let ([px, py, pz], [nx, ny, nz]) = (self.hit_mm[i], self.normal[i]);
        [
            self.depth_mm[i],
            px,
            py,
            pz,
            nx,
            ny,
            nz,
            self.secretion_mm[i],
        ]
    }
}

/// The ray pass of a look over one renderer: it owns a renderer prepared in [`Mode::Iso`] at
/// the first threshold the rays meet (the secretion's, or the tissue's without secretion), and
/// carries each ray on from its secretion hit to the tissue.
#[derive(Debug)]
pub struct RayPass {
    prepared: Prepared,
    settings: RayPassSettings,
}

impl RayPass {
    /// The ray pass for `settings` over `renderer`, sampling as `base` says (step, refinement,
    /// empty-space skipping; its mode and isovalue are replaced). Fails on an out-of-range
    /// setting.
    pub fn new(
        renderer: &Arc<Renderer>,
        base: &RenderSettings,
        settings: &RayPassSettings,
    ) -> Result<Self, LookError> {
        settings.validate()?;
        let map = renderer.volume().value_map();
        let stored = |hu: f64| map.stored_from_physical(hu);
        let mut s = base.clone();
        s.mode = Mode::Iso;
        s.iso_opacity = 1.0;
        s.interleave = settings.interleave;
        s.iso_hu = settings.tissue_hu;
        if settings.secretion != SecretionMode::Off {
            s.iso_hu = settings.secretion_hu;
            // From the lumen through the secretion into the tissue, wherever the eye is.
            s.crossing = if stored(settings.tissue_hu) > stored(settings.secretion_hu) {
                Crossing::Rising
            } else {
                Crossing::Falling
            };
        }
        let prepared = renderer.prepare(&s)?;
        Ok(Self {
            prepared,
            settings: settings.clone(),
        })
    }

    /// The settings in force.
    pub fn settings(&self) -> &RayPassSettings {
        &self.settings
    }

    /// The renderer prepared for the first threshold.
    pub fn prepared(&self) -> &Prepared {
        &self.prepared
    }

    /// Marches every pixel of `camera` at `quality` (below full, the buffer is traced at the
    /// reduced size and upsampled depth-aware to the camera's).
    pub fn trace(&self, camera: &Camera, quality: Quality) -> GBuffer {
        self.trace_shifted(camera, quality, 0.0, Filter::Trilinear)
    }

    /// [`Self::trace`] with every ray's sample grid shifted by `grid_shift` steps (a still
    /// frame's jitter), the volume reconstructed as `filter` says.
    pub(crate) fn trace_shifted(
        &self,
        camera: &Camera,
        quality: Quality,
        shift: f32,
        filter: Filter,
    ) -> GBuffer {
        let start = Instant::now();
        let full = camera.size();
        let small = match quality {
            Quality::Full => *camera,
            reduced => reduced_camera(camera, reduced.reduced_size(full)),
        };
        let mut frame = Frame::default();
        // Nothing cancels it.
        let _ = self
            .prepared
            .render_with(&small, &self.first_options(shift, filter), &mut frame);
        let mut gbuffer = self.finish(&small, frame, camera, filter);
        gbuffer.stats.time = start.elapsed();
        gbuffer
    }

    /// The renderer's options of the first threshold's search, every sample grid shifted by
    /// `shift` steps, the volume reconstructed as `filter` says: the look shades the G-buffer
    /// itself, the renderer only finds the surfaces.
    pub(super) fn first_options(&self, shift: f32, filter: Filter) -> RenderOptions<'static> {
        let layers = self.settings.traced_layers();
        RenderOptions {
            grid_shift: shift,
            ..RenderOptions::new().layers(layers).unlit().filter(filter)
        }
    }

    /// The G-buffer of `frame`, the first threshold's search from `camera` (with
    /// [`Self::first_options`]): each ray carried on to the tissue, upsampled to the size of
    /// `full` (the camera at full size) where `camera` is smaller, and the pixels of `full`
    /// whose rays start inside the tissue marked; the continuation samples as `filter` says.
    pub(super) fn finish(
        &self,
        camera: &Camera,
        mut frame: Frame,
        full: &Camera,
        filter: Filter,
    ) -> GBuffer {
        let (secretion, surface) = if self.settings.secretion != SecretionMode::Off {
            self.continue_to_tissue(camera, &mut frame, filter)
        } else {
            (vec![0.0; frame.len()], Vec::new())
        };
        let mut gbuffer = if camera.size() == full.size() {
            GBuffer {
                secretion_normal: surface,
                ..into_gbuffer(frame, secretion)
            }
        } else {
            // The value layer (NaN in iso mode) carries the secretion through the upsampling.
            frame.value = secretion;
            let mut upsampled = Frame::default();
            upsample(&frame, full.size(), &mut upsampled);
            let secretion = std::mem::take(&mut upsampled.value);
            into_gbuffer(upsampled, secretion)
        };
        gbuffer.clipped = clipped_pixels(self.prepared.renderer(), full, &self.settings);
        gbuffer
    }

    /// Carries every ray of `frame` (traced by `camera` to its secretion hit) on to the tissue:
    /// replaces its depth with the tissue's, fills its hit positions and normals, and returns
    /// the secretion per pixel and the normals of the secretion's surface at the secretion hits
    /// (NaN where no tissue lies behind), sampling as `filter` says.
    fn continue_to_tissue(
        &self,
        camera: &Camera,
        frame: &mut Frame,
        filter: Filter,
    ) -> (Vec<f32>, Vec<[f32; 3]>) {
        let renderer = self.prepared.renderer();
        let on = Continuation::new(renderer, &self.settings, filter);
        let (w, n) = (frame.width, frame.len());
        // Zeroed (the allocator's fresh pages), then every pixel written in parallel.
        (frame.hit_mm, frame.normal) = (vec![[0.0; 3]; n], vec![[0.0; 3]; n]);
        let mut surface = vec![[0.0; 3]; n];
        let mut secretion = vec![0.0; n];
        frame
            .depth_mm
            .par_chunks_mut(w)
            .zip(frame.hit_mm.par_chunks_mut(w))
            .zip(frame.normal.par_chunks_mut(w))
            .zip(secretion.par_chunks_mut(w))
            .zip(surface.par_chunks_mut(w))
            .enumerate()
            .for_each(|(y, ((((depth, hit), normal), secretion), surface))| {
                for x0 in (0..w).step_by(8) {
                    let lanes = x0..(x0 + 8).min(w);
                    let rays: [_; 8] = std::array::from_fn(|k| {
                        // No ray for a pixel without a secretion hit: it has no tissue hit.
                        let x = Some(x0 + k).filter(|x| *x < w && !depth[*x].is_nan())?;
                        let ray = camera.pixel_ray(x, y)?;
                        Some((ray.origin, ray.dir, depth[x]))
                    });
                    let found = on.tissue_after8(&rays);
                    let vector = TissueHits::vector;
                    for (k, x) in lanes.enumerate() {
                        (depth[x], hit[x], normal[x], secretion[x], surface[x]) = if found.found[k]
                        {
                            (
                                found.depth_mm[k],
                                found.hit_mm[k],
                                vector(&found.normal, k),
                                found.secretion_mm[k],
                                vector(&found.secretion_normal, k),
                            )
                        } else {
                            (f32::NAN, [f32::NAN; 3], [f32::NAN; 3], 0.0, [f32::NAN; 3])
                        };
                    }
                }
            });
        frame.stats.iso_hits = frame.depth_mm.iter().filter(|d| !d.is_nan()).count() as u64;
        (secretion, surface)
    }
}

/// The G-buffer of a traced `frame` and its `secretion`.
fn into_gbuffer(frame: Frame, secretion_mm: Vec<f32>) -> GBuffer {
    GBuffer {
        width: frame.width,
        height: frame.height,
        depth_mm: frame.depth_mm,
        hit_mm: frame.hit_mm,
        normal: frame.normal,
        secretion_mm,
        secretion_normal: Vec::new(),
        clipped: Vec::new(),
        stats: frame.stats,
    }
}
