//! The deferred stage: a [`GBuffer`] smoothed and shaded into a frame, without the volume.
//!
//! Per pixel (Krüger et al. §4.4): Phong lighting from a light at the endoscope's tip, falling
//! off with distance; a tri-planar detail texture modulating the tissue colour; wetness as a
//! low-power view-dependent darkening (wet tissue turns dark where it turns away) plus sharp
//! highlights where it faces the tip, stronger on the texture's darker texels and where there is
//! secretion; and the secretion as fog, blending the tissue toward the secretion colour with
//! its thickness.

use super::gbuffer::GBuffer;
use super::smooth::smooth;
use super::texture::Texture;
use super::{check, LookError};
use crate::camera::Camera;
use crate::render::{Frame, Layers, Premultiplied};
use glam::Vec3;
use rayon::prelude::*;
use std::borrow::Cow;
use std::sync::Arc;

/// Exponent of the wet darkening's view dependence (the paper's "low power values").
const WET_POWER: f32 = 2.0;

/// Share of the colour the full wet darkening takes away at grazing view.
const WET_DARKENING: f32 = 0.55;

/// How the G-buffer is shaded; changing any of it marches no ray.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Shading {
    /// The tissue's colour before lighting, 0–1. Default a mucosa pink.
    pub tissue_color: [f32; 3],
    /// The secretion's colour, 0–1. Default a yellowish mucus.
    pub secretion_color: [f32; 3],
    /// Light without the tip's (so that nothing is pitch black), 0–1. Default 0.12.
    pub ambient: f32,
    /// Diffuse weight of the tip's light, 0–1. Default 0.88.
    pub diffuse: f32,
    /// Strength of the wet highlights at full wetness, 0–1. Default 0.7.
    pub specular: f32,
    /// Sharpness of the wet highlights (Phong exponent), 1–1000. Default 60.
    pub shininess: f32,
    /// Wetness, 0 (dry) – 1. Default 0.
    pub wetness: f32,
    /// The detail texture; `None` (the default) for none.
    pub texture: Option<Arc<Texture>>,
    /// Edge of one texture tile on the tissue, mm, 0.1–1000. Default 12.
    pub texture_mm: f32,
    /// How much the texture changes the colour, 0–1 (±this share). Default 0.6.
    pub texture_strength: f32,
    /// Distance at which the tip's light falls to half, mm (inverse-square fall-off beyond);
    /// `None` for no fall-off. Default 40 mm.
    pub attenuation_mm: Option<f32>,
    /// Secretion thickness that veils the tissue to 1 − 1/e (63 %), mm, > 0. Default 1.5.
    pub fog_mm: f32,
    /// Radius of the depth-aware smoothing before shading, pixels, 0–8 (0: none). Default 2.
    pub smoothing_px: usize,
}

impl Default for Shading {
    fn default() -> Self {
        Self {
            tissue_color: [0.93, 0.62, 0.55],
            secretion_color: [0.92, 0.88, 0.62],
            ambient: 0.12,
            diffuse: 0.88,
            specular: 0.7,
            shininess: 60.0,
            wetness: 0.0,
            texture: None,
            texture_mm: 12.0,
            texture_strength: 0.6,
            attenuation_mm: Some(40.0),
            fog_mm: 1.5,
            smoothing_px: 2,
        }
    }
}

impl Shading {
    /// Checks every number against its range.
    pub fn validate(&self) -> Result<(), LookError> {
        let unit = |name, v: f32| {
            let v = f64::from(v);
            check(name, v, (0.0..=1.0).contains(&v), "[0, 1]")
        };
        for c in self.tissue_color.iter().chain(&self.secretion_color) {
            unit("colour component", *c)?;
        }
        unit("ambient", self.ambient)?;
        unit("diffuse", self.diffuse)?;
        unit("specular", self.specular)?;
        unit("wetness", self.wetness)?;
        unit("texture strength", self.texture_strength)?;
        let shininess = f64::from(self.shininess);
        let ok = (1.0..=1000.0).contains(&shininess);
        check("shininess", shininess, ok, "[1, 1000]")?;
        let tile = f64::from(self.texture_mm);
        let ok = (0.1..=1000.0).contains(&tile);
        check("texture scale", tile, ok, "[0.1, 1000] mm")?;
        if let Some(mm) = self.attenuation_mm {
            let mm = f64::from(mm);
            check("attenuation", mm, mm > 0.0, "positive mm")?;
        }
        let fog = f64::from(self.fog_mm);
        check("fog", fog, fog > 0.0, "positive mm")?;
        let radius = self.smoothing_px as f64;
        check("smoothing", radius, self.smoothing_px <= 8, "0..=8 pixels")
    }

    /// How far `secretion_mm` of secretion veils the tissue, 0–1: `1 − exp(−s / fog_mm)`,
    /// rising with the thickness.
    pub fn fog(&self, secretion_mm: f32) -> f32 {
        if secretion_mm > 0.0 {
            1.0 - (-secretion_mm / self.fog_mm).exp()
        } else {
            0.0
        }
    }

    /// The tip's light at `depth_mm`, 0–1.
    fn falloff(&self, depth_mm: f32) -> f32 {
        self.attenuation_mm.map_or(1.0, |half| {
            let r = depth_mm / half;
            1.0 / (1.0 + r * r)
        })
    }

    /// The colour of a hit at `depth_mm` and world position `p` with unit normal `n` (facing
    /// the tip), `to_tip` the unit direction to the light, under `secretion_mm` of secretion.
    fn color(&self, p: Vec3, n: Vec3, to_tip: Vec3, depth_mm: f32, secretion_mm: f32) -> Vec3 {
        let cos = n.dot(to_tip).clamp(0.0, 1.0);
        let texel = self
            .texture
            .as_ref()
            .map_or(0.5, |t| t.triplanar(p / self.texture_mm, n));
        let detail = 1.0 + self.texture_strength * (2.0 * texel - 1.0);
        let fog = self.fog(secretion_mm);
        let wet = (self.wetness + (1.0 - self.wetness) * fog * self.wetness.min(0.5) * 2.0)
            .clamp(0.0, 1.0);
        let lit = self.ambient + self.diffuse * cos;
        let darkening = 1.0 - wet * WET_DARKENING * (1.0 - cos.powf(WET_POWER));
        let tissue = Vec3::from(self.tissue_color) * (detail * lit * darkening);
        let mucus = Vec3::from(self.secretion_color) * (lit * darkening);
        // The reflected light's alignment with the view, for a light at the eye: 2 cos² − 1.
        let mirror = (2.0 * cos * cos - 1.0).max(0.0);
        let gloss = 1.3 - 0.6 * texel;
        let strength = wet * self.specular * gloss;
        let highlight = if strength > 0.0 && mirror > 0.0 {
            strength * mirror.powf(self.shininess)
        } else {
            0.0
        };
        (tissue.lerp(mucus, fog) + Vec3::splat(highlight)) * self.falloff(depth_mm)
    }
}

/// Shades `gbuffer` (traced by `camera`) as `shading` says, into a frame: colour, opaque where
/// the rays hit and transparent (background) elsewhere, the smoothed depth, the camera's
/// vignetting. Reads no volume: a new `shading` on the same G-buffer marches no ray. Fails
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
    let g = match shading.smoothing_px {
        0 => Cow::Borrowed(gbuffer),
        r => Cow::Owned(smooth(gbuffer, r)),
    };
    let tip = camera.eye_mm().as_vec3();
    let mut frame = Frame::default();
    frame.resize(size, Layers::NONE);
    let w = size[0];
    let vignetting = camera.lens().vignetting > 0.0;
    frame
        .color
        .par_chunks_mut(w)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let i = x + w * y;
                let depth = g.depth_mm[i];
                if depth.is_nan() {
                    *out = Premultiplied::default();
                    continue;
                }
                let p = Vec3::from(g.hit_mm[i]);
                let to_tip = (tip - p).normalize_or_zero();
                let n = Vec3::from(g.normal[i]);
                let n = if n.dot(to_tip) < 0.0 { -n } else { n };
                let mut c = shading.color(p, n, to_tip, depth, g.secretion_mm[i]);
                if vignetting {
                    c *= camera.vignetting(x as f64 + 0.5, y as f64 + 0.5) as f32;
                }
                *out = Premultiplied {
                    rgb: c.min(Vec3::ONE).to_array(),
                    transmittance: 0.0,
                };
            }
        });
    frame.depth_mm.clone_from(&g.depth_mm);
    frame.stats = gbuffer.stats;
    Ok(frame)
}
