//! The deferred stage over a whole G-buffer: smoothing ([`super::smooth`]) and shading
//! ([`Shading`]) fused band by band, eight pixels at a time, each smoothed row shaded while it
//! is in the cache.

use super::clipped::overlay;
use super::footprint::Footprints;
use super::gbuffer::GBuffer;
use super::lanes::{load, map, map3, Lanes, LANES};
use super::lit_sphere::TipView;
use super::shading::{Shading, Surface8};
use super::smooth::{Planes, SmoothBands, BAND_ROWS, DEPTH, HIT, NORMAL, SECRETION};
use super::LookError;
use crate::camera::Camera;
use crate::render::{Frame, Layers, Premultiplied};
use rayon::prelude::*;

/// Shades `gbuffer` (traced by `camera`) as `shading` says, into a frame: colour, opaque where
/// the rays hit and transparent (background) elsewhere, the smoothed depth, the camera's
/// vignetting, and the colour overlay where the tissue is clipped. Reads no volume: a new `shading` on the same G-buffer marches no ray. Fails
/// when a setting is out of range or the G-buffer's size is not the camera's.
pub fn shade(gbuffer: &GBuffer, camera: &Camera, shading: &Shading) -> Result<Frame, LookError> {
    shading.validate()?;
    let size = camera.size();
    if [gbuffer.width, gbuffer.height] != size {
        return Err(LookError::SizeMismatch {
            gbuffer: [gbuffer.width, gbuffer.height],
            camera: size,
        });
    }
    let mut frame = Frame::default();
    frame.resize(size, Layers::NONE);
    frame.stats = gbuffer.stats;
    if gbuffer.is_empty() {
        return Ok(frame);
    }
    let w = size[0];
    let bands = SmoothBands::new(gbuffer, shading.smoothing_px);
    let band = bands.band_pixels();
    let rows = Rows {
        shading,
        camera,
        footprints: Footprints::of(camera),
        secretion_normal: &gbuffer.secretion_normal,
    };
    frame
        .color
        .par_chunks_mut(band)
        .zip(frame.depth_mm.par_chunks_mut(band))
        .enumerate()
        .for_each_init(
            || bands.scratch(),
            |scratch, (b, (color, depth))| {
                bands.run(
                    b,
                    scratch,
                    #[inline(always)]
                    |row, planes| {
                        let at = row * w;
                        let y = b * BAND_ROWS + row;
                        rows.shade(y, planes, &mut color[at..at + w], &mut depth[at..at + w]);
                    },
                );
            },
        );
    overlay(&mut frame, &gbuffer.clipped);
    Ok(frame)
}

/// What shading a row needs besides the row.
struct Rows<'a> {
    shading: &'a Shading,
    camera: &'a Camera,
    /// The camera's pixel footprints (for the texture's mip levels).
    footprints: Footprints,
    /// The G-buffer's secretion surface normals, unsmoothed (empty: none).
    secretion_normal: &'a [[f32; 3]],
}

impl Rows<'_> {
    /// Shades smoothed row `y` (its `planes`) into `color` and `depth`.
    #[inline(always)]
    fn shade(&self, y: usize, planes: &Planes, color: &mut [Premultiplied], depth: &mut [f32]) {
        let w = color.len();
        depth.copy_from_slice(&planes[DEPTH][..w]);
        let tip = TipView::of(self.camera);
        let vignetting = self.camera.lens().darkens();
        for x0 in (0..w).step_by(LANES) {
            let lanes = |c: usize| load(&planes[c], x0);
            let depth = lanes(DEPTH);
            let surface = Surface8 {
                footprint: self.footprints.row8(x0, y, &depth),
                depth,
                hit: [lanes(HIT), lanes(HIT + 1), lanes(HIT + 2)],
                normal: [lanes(NORMAL), lanes(NORMAL + 1), lanes(NORMAL + 2)],
                secretion: lanes(SECRETION),
                secretion_normal: self.secretion_normals(y * w, x0, w),
            };
            let out = &mut color[x0..(x0 + LANES).min(w)];
            if surface.depth.iter().all(|d| d.is_nan()) {
                out.fill(Premultiplied::default());
                continue;
            }
            let mut rgb = self.shading.colors8(&surface, &tip);
            if vignetting {
                let x = |k: usize| (x0 + k) as f64 + 0.5;
                let v = map(|k| self.camera.vignetting(x(k), y as f64 + 0.5) as f32);
                rgb = map3(|c, k| rgb[c][k] * v[k]);
            }
            // Black and transparent without a hit.
            let hit = map(|k| if surface.depth[k].is_nan() { 0.0 } else { 1.0 });
            let rgb = map3(|c, k| {
                if hit[k] > 0.0 {
                    rgb[c][k].min(1.0)
                } else {
                    0.0
                }
            });
            for (k, out) in out.iter_mut().enumerate() {
                *out = Premultiplied {
                    rgb: [rgb[0][k], rgb[1][k], rgb[2][k]],
                    transmittance: 1.0 - hit[k],
                };
            }
        }
    }

    /// The secretion surface normals of pixels `x0 ..` of the row starting at pixel `row` of a
    /// `w` pixels wide G-buffer, by axis (NaN past the row's end or without any).
    #[inline(always)]
    fn secretion_normals(&self, row: usize, x0: usize, w: usize) -> [Lanes; 3] {
        let normals = self.secretion_normal;
        map3(|a, k| {
            let x = x0 + k;
            let normal = normals.get(row + x).filter(|_| x < w);
            normal.map_or(f32::NAN, |n| n[a])
        })
    }
}
