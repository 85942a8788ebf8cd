//! The deferred stage: a [`GBuffer`] smoothed and shaded into a frame, without the volume.
//!
//! Per pixel (Krüger et al. §4.4): Phong lighting from a light at the endoscope's tip (or
//! image-based lighting, its diffuse term from a lit sphere: [`super::LitSphere`]), falling
//! off with distance; a tri-planar detail texture modulating the tissue colour; wetness as a
//! low-power view-dependent darkening (wet tissue turns dark where it turns away) plus sharp
//! highlights where it faces the tip, stronger on the texture's darker texels and where there is
//! secretion (its density and the nearness of its first layer); and the secretion as fog,
//! blending the tissue toward the secretion colour with its thickness, under a glossy film lit
//! and highlighted by the secretion surface's own normal, fading in where the layer thins.

use super::lanes::{map, map3, normalize_or_zero, Lanes, LANES};
use super::lit_sphere::{or_normal, Lighting, TipView};
use super::texture::{Texture, LUMA};
use super::{check, LookError};
use std::sync::Arc;

/// Share of the colour the full wet darkening takes away at grazing view.
pub(super) const WET_DARKENING: f32 = 0.55;

/// The specular map read from the detail texture (Krüger et al. §4.4: specularity linked to
/// its darker pixels): `BASE + GAIN · (1 − texel)`, so a mid-grey texel gives 1, the darkest
/// 1.5 and the brightest 0.5.
pub(super) const SPECULAR_MAP_BASE: f32 = 0.5;
/// See [`SPECULAR_MAP_BASE`].
pub(super) const SPECULAR_MAP_GAIN: f32 = 1.0;
/// A given specular map's strength at its brightest (white) texels; black gives none.
pub(super) const SPECULAR_MAP_MAX: f32 = 1.5;

/// The smallest cosine between the view and the normal that widens a pixel's footprint on the
/// surface (at most 16 times: the texture's mip level at most 4 coarser than facing).
pub(super) const MIN_FOOTPRINT_COS: f32 = 1.0 / 16.0;

/// Secretion thickness at which the mucus film's gloss is full, mm; thinner, it fades in
/// smoothly (soft edges where the layer thins).
pub(super) const FILM_MM: f32 = 1.0;
/// Strength of the mucus film's highlights against the tissue's (a smooth liquid surface).
pub(super) const FILM_GLOSS: f32 = 1.3;
/// Phong exponent of the mucus film's highlights: a liquid's, sharper than the mucosa's.
pub(super) const FILM_SHININESS: f32 = 30.0;

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
    /// Strength of the wet highlights at full wetness, 0–1 (times the specular map, 0–1.5).
    /// Default 1.
    pub specular: f32,
    /// Sharpness of the mucosa's wet highlights (Phong exponent), 1–1000. Default 24: glints, not
    /// a broad sheen, where a wall faces the tip closely.
    pub shininess: f32,
    /// Wetness, 0 (dry) – 1. Default 0.
    pub wetness: f32,
    /// The detail texture (its colour, or grey, modulates the tissue's); `None` (the default)
    /// for none.
    pub texture: Option<Arc<Texture>>,
    /// The specular map: where it is bright the tissue is wetter and glossier, where black it
    /// has no highlights (its luminance, 0–1, times [`SPECULAR_MAP_MAX`]); tiled and projected
    /// as the texture is. `None` (the default): derived from the detail texture, strongest on
    /// its darker texels (Krüger et al. §4.4).
    pub specular_map: Option<Arc<Texture>>,
    /// Edge of one texture tile on the tissue, mm, 0.1–1000. Default 30.
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
    /// How the tissue and the mucus film are lit: Phong (`ambient + diffuse · cos`, the
    /// default) or a lit sphere's diffuse light ([`Lighting::LitSphere`]: `ambient` and
    /// `diffuse` unused); the highlights are the specular model's either way.
    pub lighting: Lighting,
}

impl Default for Shading {
    fn default() -> Self {
        Self {
            tissue_color: [0.93, 0.62, 0.55],
            secretion_color: [0.92, 0.88, 0.62],
            ambient: 0.12,
            diffuse: 0.88,
            specular: 1.0,
            shininess: 24.0,
            wetness: 0.0,
            texture: None,
            specular_map: None,
            texture_mm: 30.0,
            texture_strength: 0.6,
            attenuation_mm: Some(40.0),
            fog_mm: 1.5,
            smoothing_px: 2,
            lighting: Lighting::Phong,
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
    ///
    /// The tissue: lit (ambient plus diffuse), its texture's detail (per channel: a colour
    /// texture changes the hue), darkened by the wetness's low-power view term
    /// (`1 − wet · WET_DARKENING · (1 − cos²)`), then its highlights added (times the specular
    /// map: the one given, else stronger on the texture's darker texels). The texture and the
    /// map are read at the mip level of the pixel's footprint on the tissue (`s.footprint`,
    /// widened by `1 / cos` of the view to the normal). Over it the secretion: a fog
    /// toward the mucus colour, lit (not darkened) by the secretion surface's own normal, with the glossy
    /// film's highlights on that surface fading in with the layer's thickness (no hard edge
    /// where it thins). Secretion raises the wetness with its density (its fog) and the
    /// nearness of its first layer (the tip's light there).
    #[inline(always)]
    pub(super) fn colors8(&self, s: &Surface8, view: &TipView) -> [Lanes; 3] {
        let tip = view.at.to_array();
        let to_tip = normalize_or_zero(map3(|a, k| tip[a] - s.hit[a][k]));
        // The normals turned toward the tip: the cosine with the light is |n · to tip|.
        let cos = cosines(&s.normal, &to_tip);
        let film_cos = cosines(&s.secretion_normal, &to_tip);
        // No surface of its own (no secretion normal): the tissue's.
        let film_cos = map(|k| {
            if film_cos[k].is_nan() {
                cos[k]
            } else {
                film_cos[k]
            }
        });
        let (texel, specular_map) = self.detail8(s, &cos);
        let secreted = s.secretion.iter().any(|&mm| mm > 0.0);
        let (fog, film) = if secreted {
            let film = map(|k| smoothstep(s.secretion[k] / FILM_MM));
            (map(|k| self.fog(s.secretion[k])), film)
        } else {
            ([0.0; LANES], [0.0; LANES])
        };
        let wet = map(|k| {
            let near = self.falloff((s.depth[k] - s.secretion[k]).max(0.0));
            let raised = (1.0 - self.wetness) * fog[k] * near * self.wetness.min(0.5) * 2.0;
            (self.wetness + raised).clamp(0.0, 1.0)
        });
        let (lit, film_lit) = self.diffuse8(s, (&cos, &film_cos), &to_tip, view);
        let darkening = map(|k| 1.0 - wet[k] * WET_DARKENING * (1.0 - cos[k] * cos[k]));
        let tissue = map3(|c, k| {
            let detail = 1.0 + self.texture_strength * (2.0 * texel[c][k] - 1.0);
            detail * lit[k] * darkening[k]
        });
        // The mucus is a translucent liquid, not the wet mucosa: lit, not darkened.
        let mucus = film_lit;
        let tissue_gloss = map(|k| wet[k] * specular_map[k] * (1.0 - fog[k]));
        let film_gloss = map(|k| wet[k] * FILM_GLOSS * film[k]);
        let highlight = self.highlights8(&tissue_gloss, &cos, self.shininess);
        let glints = if secreted {
            self.highlights8(&film_gloss, &film_cos, FILM_SHININESS)
        } else {
            [0.0; LANES]
        };
        let falloff = map(|k| self.falloff(s.depth[k]));
        map3(|c, k| {
            let (t, m) = (self.tissue_color[c], self.secretion_color[c]);
            let mixed = t * tissue[c][k] * (1.0 - fog[k]) + m * mucus[k] * fog[k];
            (mixed + highlight[k] + glints[k]) * falloff[k]
        })
    }

    /// The detail texture's colours of eight hits (mid-grey without one) and the specular
    /// map's strengths there, `cos` the cosines of the view to the normals.
    #[inline(always)]
    fn detail8(&self, s: &Surface8, cos: &Lanes) -> ([Lanes; 3], Lanes) {
        let tiles = map3(|a, k| s.hit[a][k] / self.texture_mm);
        let footprint = map(|k| s.footprint[k] / (cos[k].max(MIN_FOOTPRINT_COS) * self.texture_mm));
        let texel = match &self.texture {
            Some(t) => t.triplanar8(&tiles, &s.normal, &footprint),
            None => [[0.5; LANES]; 3],
        };
        let specular_map = match &self.specular_map {
            Some(m) => {
                let v = luma(&m.triplanar8(&tiles, &s.normal, &footprint));
                map(|k| SPECULAR_MAP_MAX * v[k])
            }
            None => {
                let v = luma(&texel);
                map(|k| SPECULAR_MAP_BASE + SPECULAR_MAP_GAIN * (1.0 - v[k]))
            }
        };
        (texel, specular_map)
    }

    /// The diffuse light of eight hits' tissue and mucus film (their cosines with the light
    /// at the tip `cos`): Phong's, or the lit sphere's at their normals.
    #[inline(always)]
    fn diffuse8(
        &self,
        s: &Surface8,
        (cos, film_cos): (&Lanes, &Lanes),
        to_tip: &[Lanes; 3],
        view: &TipView,
    ) -> (Lanes, Lanes) {
        match &self.lighting {
            Lighting::Phong => (
                map(|k| self.ambient + self.diffuse * cos[k]),
                map(|k| self.ambient + self.diffuse * film_cos[k]),
            ),
            Lighting::LitSphere(sphere) => {
                let film_normal = or_normal(&s.secretion_normal, &s.normal);
                (
                    sphere.light8(&s.normal, to_tip, view),
                    sphere.light8(&film_normal, to_tip, view),
                )
            }
        }
    }

    /// Highlights of eight hits: sharp (Phong exponent `shininess`) where the light reflects
    /// toward the tip (for a light at the eye, `2 cos² − 1` with the normal), times
    /// [`Self::specular`] and `gloss`.
    #[inline(always)]
    fn highlights8(&self, gloss: &Lanes, cos: &Lanes, shininess: f32) -> Lanes {
        let mirror = map(|k| (2.0 * cos[k] * cos[k] - 1.0).max(0.0));
        let strength = map(|k| gloss[k] * self.specular);
        let mut highlight = [0.0; LANES];
        for k in 0..LANES {
            if strength[k] > 0.0 && mirror[k] > 0.0 {
                highlight[k] = strength[k] * mirror[k].powf(shininess);
            }
        }
        highlight
    }
}

/// The luminance of eight colours.
#[inline(always)]
fn luma(rgb: &[Lanes; 3]) -> Lanes {
    map(|k| LUMA[0] * rgb[0][k] + LUMA[1] * rgb[1][k] + LUMA[2] * rgb[2][k])
}

/// `|n · v|` per lane, at most 1 (NaN where the normal is NaN).
#[inline(always)]
fn cosines(n: &[Lanes; 3], v: &[Lanes; 3]) -> Lanes {
    let [nx, ny, nz] = n;
    let cos = map(|k| (nx[k] * v[0][k] + ny[k] * v[1][k] + nz[k] * v[2][k]).abs());
    map(|k| if cos[k] > 1.0 { 1.0 } else { cos[k] })
}

/// `3x² − 2x³` of `x` clamped to [0, 1].
#[inline(always)]
pub(super) fn smoothstep(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
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
    /// Unit normal of the secretion's surface (either side; NaN: none, the tissue's is taken).
    pub secretion_normal: [Lanes; 3],
    /// The pixel's width on a surface facing the eye at the hit's depth, mm.
    pub footprint: Lanes,
}
