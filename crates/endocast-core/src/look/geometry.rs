//! Scene geometry (meshes, overlays, the grid, markers, the endoscope's instruments) in a
//! look's frame, composited by depth after the deferred stage — Krüger et al., "Sinus
//! Endoscopy" §4.4, "Integration of Polygonal Data": the geometry's depth against the tissue's
//! decides what overlaps, the secretion is reduced where a mesh is nearer than the tissue, and
//! a stipple shows what lies behind the wall.
//!
//! Per pixel, the camera's ray for it (the ray the ray pass marched) is traced through the
//! scene ([`crate::scene::PlacedScene::trace_many`], square blocks of pixels together):
//! - surfaces nearer than the tissue are drawn over it, lit from the tip as the tissue is
//!   (ambient plus diffuse, the same fall-off with distance, the vignetting), translucent ones
//!   composited in depth order; each is veiled by the part of the secretion in front of it
//!   (the secretion taken as lying against the tissue, as [`SecretionMode::On`] finds it);
//! - surfaces behind the tissue show through a stipple: on every other pixel (a 2×2
//!   checkerboard fixed on the screen) they are composited over the tissue, unveiled, so a
//!   vessel behind the wall shows without hiding the wall;
//! - where the ray meets no tissue, the geometry is drawn solid;
//! - a closed mesh around the eye is not drawn (its inside would hide the view) but tints the
//!   whole view with its colour (the paper's "colour overlay ... if one is inside a polygonal
//!   mesh").
//!
//! The frame's depth becomes the nearest opaque surface's (the geometry's or the tissue's);
//! pixels whose ray meets no geometry keep their colour and depth, bit for bit (but for the
//! tint of a mesh around the eye).
//!
//! [`SecretionMode::On`]: super::SecretionMode::On

use super::deferred::shade;
use super::gbuffer::GBuffer;
use super::shading::Shading;
use super::LookError;
use crate::camera::{Camera, Ray};
use crate::render::{Frame, Premultiplied};
use crate::scene::bvh::PACKET;
use crate::scene::{Hit, PlacedScene, Scene, Traced};
use glam::Vec3;
use rayon::prelude::*;

/// Edge of the square blocks of pixels whose rays walk the scene together (one packet).
const BLOCK: usize = 8;
const _: () = assert!(BLOCK * BLOCK <= PACKET);

/// [`shade`] with `scene` (placed for `camera`) composited by depth, as the module says;
/// without a scene (or an empty one), [`shade`] alone. Fails as [`shade`] does.
pub fn shade_with_scene(
    gbuffer: &GBuffer,
    camera: &Camera,
    shading: &Shading,
    scene: Option<&Scene>,
) -> Result<Frame, LookError> {
    let mut frame = shade(gbuffer, camera, shading)?;
    if let Some(scene) = scene.filter(|s| !s.is_empty()) {
        let (outside, around) = scene.without_enclosing(camera.eye_mm());
        let compositor = Compositor {
            shading,
            camera,
            tip: camera.eye_mm().as_vec3(),
            secretion_mm: &gbuffer.secretion_mm,
        };
        compositor.run(&outside.placed(camera), &mut frame);
        for material in around {
            tint(&mut frame, material.color, INSIDE_TINT * material.opacity);
        }
    }
    Ok(frame)
}

/// Share of the colour a mesh around the eye takes in the tint it lays over the view (times
/// the mesh's opacity).
const INSIDE_TINT: f32 = 0.3;

/// Blends everything drawn in `frame` toward `color` by `share`: the colour overlay of a mesh
/// around the eye, whose inside is not drawn (it would hide the view).
fn tint(frame: &mut Frame, color: [f32; 3], share: f32) {
    frame.color.par_iter_mut().for_each(|p| {
        let drawn = 1.0 - p.transmittance;
        for (c, tinted) in p.rgb.iter_mut().zip(color) {
            *c += share * (tinted * drawn - *c);
        }
    });
}

/// Whether pixel `(x, y)` shows the geometry behind the tissue: the stipple, a checkerboard.
pub(super) fn shows_behind(x: usize, y: usize) -> bool {
    (x + y).is_multiple_of(2)
}

/// What compositing the geometry into a shaded frame needs.
struct Compositor<'a> {
    shading: &'a Shading,
    camera: &'a Camera,
    /// The light, at the endoscope's tip (the eye).
    tip: Vec3,
    /// The G-buffer's secretion per pixel, mm.
    secretion_mm: &'a [f32],
}

/// A block's rays, their pixels (column, row in the band) and their hits, kept per thread.
#[derive(Default)]
struct Scratch {
    rays: Vec<Traced>,
    pixels: Vec<(usize, usize)>,
    hits: Vec<Vec<Hit>>,
}

impl Compositor<'_> {
    /// Composites `scene` into `frame` (shaded by the look), band by band in parallel.
    fn run(&self, scene: &PlacedScene<'_>, frame: &mut Frame) {
        let band = BLOCK * frame.width;
        frame
            .color
            .par_chunks_mut(band)
            .zip(frame.depth_mm.par_chunks_mut(band))
            .enumerate()
            .for_each_init(Scratch::default, |scratch, (b, (color, depth))| {
                let rows = color.len() / self.camera.size()[0];
                for x0 in (0..self.camera.size()[0]).step_by(BLOCK) {
                    let block = Block {
                        xs: x0..(x0 + BLOCK).min(self.camera.size()[0]),
                        y0: b * BLOCK,
                        rows,
                    };
                    self.block(scene, &block, (&mut *color, &mut *depth), scratch);
                }
            });
    }

    /// Traces the rays of `block` of a band (its `color` and `depth`) and composites their hits.
    fn block(
        &self,
        scene: &PlacedScene<'_>,
        block: &Block,
        (color, depth): (&mut [Premultiplied], &mut [f32]),
        scratch: &mut Scratch,
    ) {
        let w = self.camera.size()[0];
        self.block_rays(block, depth, scratch);
        let n = scratch.rays.len();
        if scratch.hits.len() < n {
            scratch.hits.resize_with(n, Vec::new);
        }
        scene.trace_many(&scratch.rays, &mut scratch.hits);
        let traced = scratch.pixels.iter().zip(&scratch.rays).zip(&scratch.hits);
        for ((&(x, row), traced), hits) in traced {
            if hits.is_empty() {
                continue;
            }
            let at = x + w * row;
            let pixel = (x, block.y0 + row);
            self.pixel(pixel, &traced.ray, hits, (&mut color[at], &mut depth[at]));
        }
    }

    /// The rays of `block`'s pixels into `scratch` (cleared first): from the near plane on,
    /// up to the tissue (`depth` of the band) where the pixel shows nothing behind it.
    fn block_rays(&self, block: &Block, depth: &[f32], scratch: &mut Scratch) {
        let w = self.camera.size()[0];
        scratch.rays.clear();
        scratch.pixels.clear();
        for row in 0..block.rows {
            for x in block.xs.clone() {
                let y = block.y0 + row;
                let Some(ray) = self.camera.pixel_ray(x, y) else {
                    continue;
                };
                let tissue_mm = depth[x + w * row];
                let t_max = if tissue_mm.is_nan() || shows_behind(x, y) {
                    f64::INFINITY
                } else {
                    f64::from(tissue_mm)
                };
                scratch.rays.push(Traced {
                    ray,
                    t_min: self.camera.near_distance_along(ray.dir),
                    t_max,
                });
                scratch.pixels.push((x, row));
            }
        }
    }

    /// Composites `hits` (depth order) of pixel `(x, y)`'s `ray` with the shaded tissue in
    /// `color`, at `depth` (NaN: none), and sets the depth to the nearest opaque surface's.
    fn pixel(
        &self,
        (x, y): (usize, usize),
        ray: &Ray,
        hits: &[Hit],
        (color, depth): (&mut Premultiplied, &mut f32),
    ) {
        let tissue_mm = *depth;
        let in_front = hits.partition_point(|h| tissue_mm.is_nan() || h.t_mm < tissue_mm);
        let (front, behind) = hits.split_at(in_front);
        let show_behind = !behind.is_empty() && shows_behind(x, y);
        if front.is_empty() && !show_behind {
            return;
        }
        let brightness = self.camera.vignetting(x as f64 + 0.5, y as f64 + 0.5) as f32;
        let secretion_mm = self.secretion_mm[x + self.camera.size()[0] * y];
        let mut out = Premultiplied::default();
        for hit in front {
            // The secretion lies against the tissue: the part of it nearer than the hit.
            let veil = self.shading.fog(secretion_mm - (tissue_mm - hit.t_mm));
            under(&mut out, self.lit(hit, ray, veil) * brightness, hit.opacity);
        }
        let mut wall = *color;
        if show_behind {
            let mut seen = Premultiplied::default();
            for hit in behind {
                under(&mut seen, self.lit(hit, ray, 0.0) * brightness, hit.opacity);
            }
            wall = over(&seen, &wall);
        }
        *color = over(&out, &wall);
        if let Some(opaque) = front.last().filter(|h| h.opacity >= 1.0) {
            *depth = opaque.t_mm;
        }
    }

    /// The colour of `hit` on `ray`, lit from the tip as the tissue is and veiled by a share
    /// `veil` (0–1) of secretion, each channel at most 1.
    fn lit(&self, hit: &Hit, ray: &Ray, veil: f32) -> Vec3 {
        let s = self.shading;
        let at = ray.at(f64::from(hit.t_mm)).as_vec3();
        let cos = hit.normal.dot((self.tip - at).normalize_or_zero()).abs();
        let light = (s.ambient + s.diffuse * cos.min(1.0)) * s.falloff(hit.t_mm);
        let color = hit.color.lerp(Vec3::from(s.secretion_color), veil);
        (color * light).min(Vec3::ONE)
    }
}

/// A block of pixels: its columns, and its rows from the band's first (`y0`, in the image).
struct Block {
    xs: std::ops::Range<usize>,
    y0: usize,
    rows: usize,
}

/// Composites a surface of colour `rgb` and opacity `alpha` under `out` (front to back).
fn under(out: &mut Premultiplied, rgb: Vec3, alpha: f32) {
    for (o, c) in out.rgb.iter_mut().zip(rgb.to_array()) {
        *o += out.transmittance * alpha * c;
    }
    out.transmittance *= 1.0 - alpha;
}

/// `front` over `back`.
fn over(front: &Premultiplied, back: &Premultiplied) -> Premultiplied {
    let t = front.transmittance;
    Premultiplied {
        rgb: std::array::from_fn(|c| front.rgb[c] + t * back.rgb[c]),
        transmittance: t * back.transmittance,
    }
}
