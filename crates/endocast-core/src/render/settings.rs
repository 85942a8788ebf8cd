//! What to render: the mode, its isovalues and surfaces, the transfer function and the knobs of
//! the sample loop, each with a documented default.

use super::sample::Lighting;
use super::transfer::TransferFunction;
use thiserror::Error;

/// The render modes. A closed set, matched in the hot loop (static dispatch).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Mode {
    /// First hit of the isovalue, refined by bisection, Blinn-Phong shaded.
    Iso,
    /// Front-to-back direct volume rendering with the transfer function.
    Dvr,
    /// The paper's mode: the shaded isosurface weighted by its opacity, then unshaded DVR behind
    /// it until early termination.
    Hybrid,
    /// Angioscopy (§2.2): a lower isosurface (vessel wall) and an upper one (stent,
    /// calcification), each with its own colour and opacity, and DVR of what lies outside both.
    TwoIso,
    /// Maximum intensity projection.
    Mip,
    /// Minimum intensity projection (airways).
    Minip,
    /// Volumetric depth peeling (Borland et al. 2006): the surface where the ray crosses the
    /// peel threshold for the n-th (or last) time, with what lies before it discarded or
    /// faded; see [`PeelSettings`].
    Peel,
}

impl Mode {
    /// Every mode, in a fixed order.
    pub const ALL: [Mode; 7] = [
        Self::Iso,
        Self::Dvr,
        Self::Hybrid,
        Self::TwoIso,
        Self::Mip,
        Self::Minip,
        Self::Peel,
    ];

    /// The kebab-case name: `iso`, `dvr`, `hybrid`, `two-iso`, `mip`, `minip`, `peel`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Iso => "iso",
            Self::Dvr => "dvr",
            Self::Hybrid => "hybrid",
            Self::TwoIso => "two-iso",
            Self::Mip => "mip",
            Self::Minip => "minip",
            Self::Peel => "peel",
        }
    }

    /// The mode called `name` (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(name.trim()))
    }
}

/// Which way the value crosses the isovalue at the surface, seen from the eye.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Crossing {
    /// Rising when the value at the ray's start is below the isovalue (a dark lumen: air, CSF on
    /// T1), falling otherwise (a bright lumen: contrast-filled vessel, CSF on T2). The default.
    #[default]
    Auto,
    /// From below the isovalue to above it.
    Rising,
    /// From above the isovalue to below it.
    Falling,
}

/// Which peel a ray of [`Mode::Peel`] shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PeelLayer {
    /// The n-th crossing (1 = the first).
    Nth(u32),
    /// The last crossing along the ray.
    Last,
}

impl Default for PeelLayer {
    fn default() -> Self {
        Self::Nth(1)
    }
}

/// What rays that never reach the wanted peel show.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Unpeeled {
    /// Nothing: they are transparent (the background shows). The default.
    #[default]
    Discard,
    /// The whole ray composited with the transfer function of before the peel, as context.
    Context,
}

/// Volumetric depth peeling ([`Mode::Peel`]; Borland et al., "Volumetric depth peeling for
/// medical image display", SPIE 2006). The ray is marched from the eye; each crossing of the
/// threshold into the brighter material (or, with `falling`, into the darker one) counts one
/// peel. Up to the wanted peel the ray is composited with [`RenderSettings::tf`]; at it, that
/// colour and opacity are scaled by `keep` (0 discards them, the paper's usual choice), the
/// surface of the crossing is drawn as the isosurface is in the other modes (refined by
/// bisection, Blinn-Phong shaded, [`RenderSettings::iso_color`] at
/// [`RenderSettings::iso_opacity`]; its distance is the pixel's depth), and behind it the ray
/// is composited with `tf_after`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PeelSettings {
    /// The peel threshold, physical units; `None` (the default) takes
    /// [`RenderSettings::iso_hu`].
    pub threshold_hu: Option<f64>,
    /// The peel shown. Default the first.
    pub layer: PeelLayer,
    /// Count crossings into the darker material instead of the brighter. Default false.
    pub falling: bool,
    /// Share of the colour and opacity accumulated before the peel that is kept, 0–1.
    /// Default 0 (discarded).
    pub keep: f32,
    /// What rays without the wanted peel show. Default [`Unpeeled::Discard`].
    pub unpeeled: Unpeeled,
    /// Transfer function behind the peel; `None` (the default) takes [`RenderSettings::tf`].
    pub tf_after: Option<TransferFunction>,
}

impl Default for PeelSettings {
    fn default() -> Self {
        Self {
            threshold_hu: None,
            layer: PeelLayer::default(),
            falling: false,
            keep: 0.0,
            unpeeled: Unpeeled::Discard,
            tf_after: None,
        }
    }
}

/// Settings that cannot be rendered.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SettingsError {
    /// A number is NaN, infinite or outside its range.
    #[error("{name} = {value} is outside {range}")]
    OutOfRange {
        /// The setting.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The accepted range, in words.
        range: &'static str,
    },
    /// The two-isosurface mode needs its lower isovalue below its upper one.
    #[error("the lower isovalue {lower} must lie below the upper isovalue {upper}")]
    IsovaluesOutOfOrder {
        /// The lower isovalue (`iso_hu`).
        lower: f64,
        /// The upper isovalue (`iso2_hu`).
        upper: f64,
    },
}

/// Everything a frame depends on besides the volume and the camera.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RenderSettings {
    /// The render mode. Default [`Mode::Hybrid`].
    pub mode: Mode,
    /// Isovalue in physical units (HU for CT): the lumen wall, or the lower surface of
    /// [`Mode::TwoIso`]. Default −500 HU (air/tissue, see `shared/data/README.md`).
    pub iso_hu: f64,
    /// Opacity of the isosurface, 0–1 (hybrid: 1 hides everything behind it). Default 1.
    pub iso_opacity: f32,
    /// Colour of the isosurface before shading, 0–1 (sRGB). Default a mucosa pink.
    pub iso_color: [f32; 3],
    /// Which crossing counts as the surface. Default [`Crossing::Auto`].
    pub crossing: Crossing,
    /// Upper isovalue of [`Mode::TwoIso`] (stent, calcification), physical units. Default
    /// 700 HU.
    pub iso2_hu: f64,
    /// Opacity of the upper surface, 0–1. Default 1.
    pub iso2_opacity: f32,
    /// Colour of the upper surface, 0–1. Default a metallic white-blue.
    pub iso2_color: [f32; 3],
    /// Transfer function for DVR (and the colours of MIP/MinIP). Default the `ramp` preset.
    pub tf: TransferFunction,
    /// Distance between samples, as a fraction of the smallest voxel spacing (the step in mm
    /// is this times that spacing, the same along every ray). Default 0.5.
    pub step_vox: f64,
    /// Offset each pixel's samples by a deterministic pseudo-random fraction of a step (a hash
    /// of the pixel), trading wood-grain artefacts for noise. Disabled by default: samples then
    /// sit at the middle of each step interval.
    pub jitter: bool,
    /// Interleaved sampling (Keller and Heidrich; the paper of Krüger et al. §4.3): each pixel of
    /// a 4×4 tile offsets its samples by its own sixteenth of a step, in a Bayer order, so that
    /// neighbouring rays never share a sample plane and wood-grain bands break up into a fine
    /// pattern that image-space smoothing and still frames average away. Wins over `jitter`.
    /// Disabled by default.
    pub interleave: bool,
    /// Skip bricks that cannot contribute. Enabled by default; the image is the same without it,
    /// only slower.
    pub skip_empty: bool,
    /// Accumulated opacity at which a ray stops, in (0, 1]. Default 0.99.
    pub early_termination: f32,
    /// Shade DVR samples with their gradient (costs six extra samples per visible sample). The
    /// hybrid mode never shades behind its surface (§3.3). Disabled by default.
    pub shade_dvr: bool,
    /// Bisection steps refining an isosurface hit (§3.3), 0–16; after them the hit is
    /// interpolated linearly inside the final bracket. 0 takes the first sample past the
    /// isovalue as the hit. Default 4.
    pub refine_steps: u32,
    /// [`Mode::Iso`] and [`Mode::Hybrid`]: find the surface exactly instead of by samples and
    /// bisection — a walk over the trilinear cells that can hold the isovalue, each solved for
    /// its crossing (Marmitt et al. 2004), so that no feature thinner than a step is missed and
    /// the depth is the trilinear field's own (`refine_steps` then does not apply). About 1.4×
    /// the sampled search's frame instructions on the colon phantom and a chest CT
    /// (BENCHMARKS.md). Disabled by default.
    pub exact_hits: bool,
    /// DVR and the volume behind a hybrid's or a peel's surface: classify each segment between
    /// two samples as a whole, its value taken to run linearly between them (pre-integrated
    /// classification, Engel et al. 2001), instead of each sample by its own value, so that a
    /// transfer function's narrow peaks are not missed between samples and the step can grow at
    /// equal quality. Default false.
    pub preintegrated: bool,
    /// With `preintegrated`: DVR and the volume behind a hybrid's or a peel's surface take
    /// every `dvr_stride`-th sample of the step grid (from the first one they composite), each
    /// segment between them pre-integrated; 1–16, above 1 only with `preintegrated`. The
    /// isosurface searches keep the full step. Default 1.
    pub dvr_stride: u32,
    /// Material and light weights. Default the VTK peer's.
    pub lighting: Lighting,
    /// Colour behind everything, 0–1. Default black.
    pub background: [f32; 3],
    /// Depth peeling, read by [`Mode::Peel`] only. Default [`PeelSettings::default`].
    pub peel: PeelSettings,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            mode: Mode::Hybrid,
            iso_hu: -500.0,
            iso_opacity: 1.0,
            iso_color: [0.93, 0.72, 0.62],
            crossing: Crossing::Auto,
            iso2_hu: 700.0,
            iso2_opacity: 1.0,
            iso2_color: [0.85, 0.9, 1.0],
            tf: TransferFunction::ramp(-700.0, -300.0),
            step_vox: 0.5,
            jitter: false,
            interleave: false,
            skip_empty: true,
            early_termination: 0.99,
            shade_dvr: false,
            refine_steps: 4,
            exact_hits: false,
            preintegrated: false,
            dvr_stride: 1,
            lighting: Lighting::default(),
            background: [0.0; 3],
            peel: PeelSettings::default(),
        }
    }
}

impl RenderSettings {
    /// The settings of the preset called `name` (see [`crate::presets`], which holds every
    /// preset's mode, transfer function and surfaces), or `None` for an unknown name.
    pub fn preset(name: &str) -> Option<Self> {
        crate::presets::Preset::find(name).map(crate::presets::Preset::settings)
    }

    /// The step between samples in mm for voxels whose smallest spacing is `min_spacing_mm`.
    pub fn step_mm(&self, min_spacing_mm: f64) -> f64 {
        self.step_vox * min_spacing_mm
    }

    /// The peel threshold in physical units: [`PeelSettings::threshold_hu`], else the isovalue.
    pub fn peel_threshold_hu(&self) -> f64 {
        self.peel.threshold_hu.unwrap_or(self.iso_hu)
    }

    /// Checks every number against its range.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let check = |name, value: f64, ok: bool, range| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(SettingsError::OutOfRange { name, value, range })
            }
        };
        let unit = |name, value: f32| {
            let v = f64::from(value);
            check(name, v, (0.0..=1.0).contains(&v), "[0, 1]")
        };
        check("iso_hu", self.iso_hu, true, "finite numbers")?;
        check("iso2_hu", self.iso2_hu, true, "finite numbers")?;
        unit("iso_opacity", self.iso_opacity)?;
        unit("iso2_opacity", self.iso2_opacity)?;
        for c in self
            .iso_color
            .iter()
            .chain(&self.iso2_color)
            .chain(&self.background)
        {
            unit("colour component", *c)?;
        }
        let step = self.step_vox;
        check(
            "step_vox",
            step,
            (0.01..=16.0).contains(&step),
            "[0.01, 16]",
        )?;
        let stop = f64::from(self.early_termination);
        check(
            "early_termination",
            stop,
            stop > 0.0 && stop <= 1.0,
            "(0, 1]",
        )?;
        let refine = f64::from(self.refine_steps);
        check("refine_steps", refine, self.refine_steps <= 16, "0..=16")?;
        let stride = self.dvr_stride;
        let strides = if self.preintegrated { 16 } else { 1 };
        let range = if self.preintegrated {
            "1..=16"
        } else {
            "1 (above 1 needs pre-integration)"
        };
        check(
            "dvr_stride",
            f64::from(stride),
            (1..=strides).contains(&stride),
            range,
        )?;
        let l = &self.lighting;
        for (name, v) in [
            ("ambient", l.ambient),
            ("diffuse", l.diffuse),
            ("specular", l.specular),
        ] {
            unit(name, v)?;
        }
        let shininess = f64::from(l.shininess);
        check(
            "shininess",
            shininess,
            (1.0..=1000.0).contains(&shininess),
            "[1, 1000]",
        )?;
        let peel = &self.peel;
        check(
            "peel threshold",
            self.peel_threshold_hu(),
            true,
            "finite numbers",
        )?;
        unit("peel keep", peel.keep)?;
        if peel.layer == PeelLayer::Nth(0) {
            return Err(SettingsError::OutOfRange {
                name: "peel",
                value: 0.0,
                range: "1, 2, 3 … or last",
            });
        }
        if self.mode == Mode::TwoIso && self.iso_hu >= self.iso2_hu {
            return Err(SettingsError::IsovaluesOutOfOrder {
                lower: self.iso_hu,
                upper: self.iso2_hu,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_presets_and_validation() {
        for mode in Mode::ALL {
            assert_eq!(Mode::from_name(mode.name()), Some(mode));
        }
        assert_eq!(Mode::from_name("Two-Iso"), Some(Mode::TwoIso));
        for name in TransferFunction::PRESETS {
            let s = RenderSettings::preset(name).unwrap();
            assert_eq!(s.validate(), Ok(()), "{name}");
        }
        assert_eq!(
            RenderSettings::preset("angioscopy").map(|s| s.mode),
            Some(Mode::TwoIso)
        );
        assert!(RenderSettings::preset("nope").is_none());
        let bad = [
            RenderSettings {
                step_vox: 0.0,
                ..Default::default()
            },
            RenderSettings {
                iso_hu: f64::NAN,
                ..Default::default()
            },
            RenderSettings {
                iso_opacity: 1.5,
                ..Default::default()
            },
            RenderSettings {
                early_termination: 0.0,
                ..Default::default()
            },
            RenderSettings {
                mode: Mode::TwoIso,
                iso_hu: 800.0,
                ..Default::default()
            },
            RenderSettings {
                peel: PeelSettings {
                    keep: 1.5,
                    ..Default::default()
                },
                ..Default::default()
            },
            RenderSettings {
                peel: PeelSettings {
                    layer: PeelLayer::Nth(0),
                    ..Default::default()
                },
                ..Default::default()
            },
            RenderSettings {
                peel: PeelSettings {
                    threshold_hu: Some(f64::INFINITY),
                    ..Default::default()
                },
                ..Default::default()
            },
        ];
        for s in bad {
            assert!(s.validate().is_err(), "{s:?}");
        }
    }
}
