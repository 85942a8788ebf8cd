//! What the ray pass finds ([`RayPassSettings`], [`SecretionMode`]): changing any of it marches
//! the rays again.

use super::{check, LookError};
use crate::render::Layers;

/// How the ray pass treats secretion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum SecretionMode {
    /// No secretion: the ray stops at the tissue threshold. The default.
    #[default]
    Off,
    /// Constant density between the first secretion hit and the first tissue hit (the paper's
    /// Figure 3): the secretion's thickness is their distance.
    On,
    /// Accumulated along the ray at a small step: only the stretches above the secretion
    /// threshold count (a drop floating in air is not spread over the air behind it).
    Accumulate,
}

impl SecretionMode {
    /// Every mode.
    pub const ALL: [SecretionMode; 3] = [Self::Off, Self::On, Self::Accumulate];

    /// The name: `off`, `on`, `accumulate`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Off => "off",
            Self::On => "on",
            Self::Accumulate => "accumulate",
        }
    }

    /// The mode called `name` (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(name.trim()))
    }
}

/// What the ray pass finds; changing any of it marches the rays again.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RayPassSettings {
    /// Tissue threshold, physical units: the surface the ray stops at. Default −230 HU (the
    /// paper's value for CT).
    pub tissue_hu: f64,
    /// Secretion threshold, physical units, between the lumen's value and the tissue
    /// threshold. Default −750 HU.
    pub secretion_hu: f64,
    /// How secretion is found. Default [`SecretionMode::Off`].
    pub secretion: SecretionMode,
    /// Step of [`SecretionMode::Accumulate`] and of the search from the secretion to the
    /// tissue, as a fraction of the smallest voxel spacing, 0.05–2. Default 0.25.
    pub secretion_step_vox: f64,
    /// Interleaved sampling: per-pixel offsets of the sample grid from a 4×4 pattern (see
    /// [`crate::render::RenderSettings::interleave`]). Default on.
    pub interleave: bool,
}

impl Default for RayPassSettings {
    fn default() -> Self {
        Self {
            tissue_hu: -230.0,
            secretion_hu: -750.0,
            secretion: SecretionMode::Off,
            secretion_step_vox: 0.25,
            interleave: true,
        }
    }
}

impl RayPassSettings {
    /// The optional layers the pass renders its frame with: the tissue's hit positions and
    /// normals, or none with secretion (the secretion's search to the tissue finds them, and
    /// the secretion surface's normal).
    pub fn traced_layers(&self) -> Layers {
        if self.secretion == SecretionMode::Off {
            Layers::HIT_POSITION | Layers::NORMAL
        } else {
            Layers::NONE
        }
    }

    /// Checks every number against its range.
    pub fn validate(&self) -> Result<(), LookError> {
        check("tissue threshold", self.tissue_hu, true, "finite numbers")?;
        let s = self.secretion_hu;
        let apart = self.secretion == SecretionMode::Off || s != self.tissue_hu;
        check(
            "secretion threshold",
            s,
            apart,
            "finite numbers other than the tissue's",
        )?;
        let step = self.secretion_step_vox;
        check(
            "secretion step",
            step,
            (0.05..=2.0).contains(&step),
            "[0.05, 2] voxels",
        )
    }
}
