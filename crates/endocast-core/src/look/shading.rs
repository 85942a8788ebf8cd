//! The deferred stage: a [`GBuffer`] smoothed and shaded into a frame, without the volume.
//!
//! Per pixel (Krüger et al. §4.4): Phong lighting from a light at the endoscope's tip, falling
//! off with distance; a tri-planar detail texture modulating the tissue colour; wetness as a
//! low-power view-dependent darkening (wet tissue turns dark where it turns away) plus sharp
//! highlights where it faces the tip, stronger on the texture's darker texels and where there is
//! secretion; and the secretion as fog, blending the tissue toward the secretion colour with
//! its thickness.

use super::lanes::{map, map3, normalize_or_zero, Lanes, LANES};
use super::texture::Texture;
use super::{check, LookError};
use glam::Vec3;
use std::sync::Arc;

/// Share of the colour the full wet darkening takes away at grazing view.
pub(super) const WET_DARKENING: f32 = 0.55;

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
    #[inline(always)]
    pub(super) fn falloff(&self, depth_mm: f32) -> f32 {
        self.attenuation_mm.map_or(1.0, |half| {
            let r = depth_mm / half;
            1.0 / (1.0 + r * r)
        })
    }

    /// The colours of eight hits (before the vignetting and the clamp to 1), `tip` the light at
    /// the endoscope's tip; lanes without a hit (NaN) give NaN or anything else.
    #[inline(always)]
    pub(super) fn colors8(&self, s: &Surface8, tip: Vec3) -> [Lanes; 3] {
        let tip = tip.to_array();
        let to_tip = normalize_or_zero(map3(|a, k| tip[a] - s.hit[a][k]));
        let [nx, ny, nz] = &s.normal;
        let facing = map(|k| nx[k] * to_tip[0][k] + ny[k] * to_tip[1][k] + nz[k] * to_tip[2][k]);
        // The normal turned toward the tip: its cosine with the light is |n · to tip|.
        let cos = map(|k| facing[k].abs().clamp(0.0, 1.0));
        let texel = match &self.texture {
            Some(t) => t.triplanar8(&map3(|a, k| s.hit[a][k] / self.texture_mm), &s.normal),
            None => [0.5; LANES],
        };
        let fog = if s.secretion.iter().any(|&mm| mm > 0.0) {
            map(|k| self.fog(s.secretion[k]))
        } else {
            [0.0; LANES]
        };
        let wet = map(|k| {
            let raised = (1.0 - self.wetness) * fog[k] * self.wetness.min(0.5) * 2.0;
            (self.wetness + raised).clamp(0.0, 1.0)
        });
        let lit = map(|k| self.ambient + self.diffuse * cos[k]);
        let darkening = map(|k| 1.0 - wet[k] * WET_DARKENING * (1.0 - cos[k] * cos[k]));
        let tissue = map(|k| (1.0 + self.texture_strength * (2.0 * texel[k] - 1.0)) * lit[k]);
        let tissue = map(|k| tissue[k] * darkening[k]);
        let mucus = map(|k| lit[k] * darkening[k]);
        let highlight = self.highlights8(&wet, &cos, &texel);
        let falloff = map(|k| self.falloff(s.depth[k]));
        map3(|c, k| {
            let (t, m) = (self.tissue_color[c], self.secretion_color[c]);
            let mixed = t * tissue[k] * (1.0 - fog[k]) + m * mucus[k] * fog[k];
            (mixed + highlight[k]) * falloff[k]
        })
    }

    /// The wet highlights of eight hits: sharp (the Phong exponent [`Self::shininess`]) where the
    /// light reflects toward the tip (for a light at the eye, `2 cos² − 1` with the normal),
    /// stronger on the texture's darker `texel`s and with wetness `wet`.
    #[inline(always)]
    fn highlights8(&self, wet: &Lanes, cos: &Lanes, texel: &Lanes) -> Lanes {
        let mirror = map(|k| (2.0 * cos[k] * cos[k] - 1.0).max(0.0));
        let strength = map(|k| wet[k] * self.specular * (1.3 - 0.6 * texel[k]));
        let mut highlight = [0.0; LANES];
        for k in 0..LANES {
            if strength[k] > 0.0 && mirror[k] > 0.0 {
                highlight[k] = strength[k] * mirror[k].powf(self.shininess);
            }
        }
        highlight
    }
}

/// Eight pixels of a smoothed G-buffer row, channel by channel.
pub(super) struct Surface8 {
    /// Depth, mm (NaN: no hit).
    pub depth: Lanes,
    /// Hit position, mm.
    pub hit: [Lanes; 3],
    /// Unit normal (either side).
    pub normal: [Lanes; 3],
    /// Secretion, mm.
    pub secretion: Lanes,
}
