//! The named looks and what each sets: [`LookKind`], [`SecretionMode`], and [`Look`] (both
//! stages' settings) built from a preset's [`PresetLook`].

use super::settings::{RayPassSettings, SecretionMode};
use super::shading::Shading;
use super::texture::Texture;
use crate::camera::{Lens, Projection};
use std::sync::Arc;

/// How a view looks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum LookKind {
    /// The renderer's own image in the preset's mode (hybrid, DVR, …), no deferred stage. The
    /// default.
    #[default]
    Plain,
    /// The tissue surface lit from the endoscope's tip, darkening with distance, smoothed; no
    /// texture, wetness or secretion: a clean, stylised view for measuring and teaching.
    Clinical,
    /// As an endoscope shows it: wet, textured mucosa lit from the tip, secretion veiling the
    /// tissue (the paper's look).
    Realistic,
}

impl LookKind {
    /// Every look.
    pub const ALL: [LookKind; 3] = [Self::Plain, Self::Clinical, Self::Realistic];

    /// The name: `plain`, `clinical`, `realistic`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Plain => "plain",
            Self::Clinical => "clinical",
            Self::Realistic => "realistic",
        }
    }

    /// The look called `name` (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(name.trim()))
    }

    /// The lens a camera of `projection` has in this look when the user gives none: the
    /// realistic look sees through a rigid endoscope ([`Lens::RIGID_ENDOSCOPE`] on a pinhole),
    /// the others through an ideal lens. A fisheye projection is itself the wide-angle lens's
    /// compression of the field (equidistant: `r = f θ`, a barrel-distorted pinhole), and the
    /// endoscope's coefficients were measured against a rectilinear image, so they are not
    /// stacked on it by default (given explicitly they still apply, to the normalised position
    /// in the image circle); it keeps the endoscope's vignetting, halved because a fisheye's is
    /// relative to its image circle (the endoscope's periphery: 0.7 there, as on the pinhole's
    /// inscribed circle). An orthographic view is no endoscope's.
    pub fn default_lens(self, projection: Projection) -> Lens {
        let endoscope = Lens::RIGID_ENDOSCOPE;
        match (self, projection) {
            (Self::Realistic, Projection::Pinhole) => endoscope,
            (Self::Realistic, p) if p.is_fisheye() => Lens {
                vignetting: endoscope.vignetting / 2.0,
                ..Lens::default()
            },
            _ => Lens::default(),
        }
    }
}

/// A preset's look: which one it shows by default and the values `clinical` and `realistic`
/// take (thresholds on the preset's reference scale, carried to a scan by
/// [`crate::tissue::resolve`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PresetLook {
    /// The look shown when none is asked for.
    pub kind: LookKind,
    /// The tissue threshold: where the ray stops (the paper's −230 HU for CT).
    pub tissue: f64,
    /// The secretion threshold, between the lumen's value and `tissue`.
    pub secretion: f64,
    /// How the realistic look treats secretion.
    pub secretion_mode: SecretionMode,
    /// The realistic look's wetness, 0–1.
    pub wetness: f32,
    /// The realistic look's detail texture (a [`super::BUILT_IN_TEXTURES`] name).
    pub texture: &'static str,
    /// Edge of one texture tile on the tissue, mm.
    pub texture_mm: f32,
    /// Distance at which the tip's light has fallen to half, mm.
    pub attenuation_mm: f32,
    /// The tissue's colour before lighting, 0–1.
    pub tissue_color: [f32; 3],
    /// The secretion's colour, 0–1.
    pub secretion_color: [f32; 3],
}

impl PresetLook {
    /// The look of CT airways and sinuses (values in HU): tissue at −230 HU and secretion at
    /// −750 HU (Krüger et al. §4.1 and the shared scans' air −1000 / soft tissue +40), mucosa
    /// pink, yellowish mucus, plain by default.
    pub const CT: PresetLook = PresetLook {
        kind: LookKind::Plain,
        tissue: -230.0,
        secretion: -750.0,
        secretion_mode: SecretionMode::On,
        wetness: 0.8,
        texture: "mucosa",
        texture_mm: 30.0,
        attenuation_mm: 40.0,
        tissue_color: [0.93, 0.62, 0.55],
        secretion_color: [0.92, 0.88, 0.62],
    };
}

/// Both stages' settings of a clinical or realistic look.
#[derive(Debug, Clone, PartialEq)]
pub struct Look {
    /// Which look these are the settings of (its default lens: [`LookKind::default_lens`]).
    pub kind: LookKind,
    /// What the ray pass finds (changing it marches the rays again).
    pub ray: RayPassSettings,
    /// How the G-buffer is shaded (changing it does not).
    pub shading: Shading,
}

impl Look {
    /// The look `kind` with `preset`'s values (thresholds as `preset` holds them, so resolve
    /// the preset to the scan first); `None` for [`LookKind::Plain`], which has no stages.
    pub fn of_kind(kind: LookKind, preset: &PresetLook) -> Option<Look> {
        let ray = RayPassSettings {
            tissue_hu: preset.tissue,
            secretion_hu: preset.secretion,
            ..RayPassSettings::default()
        };
        let shading = Shading {
            tissue_color: preset.tissue_color,
            secretion_color: preset.secretion_color,
            attenuation_mm: Some(preset.attenuation_mm),
            ..Shading::default()
        };
        match kind {
            LookKind::Plain => None,
            LookKind::Clinical => Some(Look { kind, ray, shading }),
            LookKind::Realistic => Some(Look {
                kind,
                ray: RayPassSettings {
                    secretion: preset.secretion_mode,
                    ..ray
                },
                shading: Shading {
                    wetness: preset.wetness,
                    texture: Texture::built_in(preset.texture).map(Arc::new),
                    texture_mm: preset.texture_mm,
                    ..shading
                },
            }),
        }
    }
}
