//! What a user asks of a view on top of a study's resolved settings — the CLI's flags and
//! Python's keywords, parsed into values — checked and applied here once, so that every front
//! end means the same by them and refuses the same values with the same words.
//!
//! An [`OptionError`] names the option by its key (`iso_opacity`); a front end spells the key
//! as its users write it ([`OptionError::message`]: `--iso-opacity` on the command line).

use crate::look::{Lighting, Look, LookKind, PresetLook, SecretionMode, Texture};
use crate::render::{Mode, PeelLayer, RenderSettings, TransferFunction, Unpeeled};
use std::fmt;
use std::sync::Arc;

/// An option given with a value it cannot take.
#[derive(Debug, Clone, PartialEq)]
pub struct OptionError {
    /// The option's key, words joined by `_` (`iso_opacity`).
    pub option: &'static str,
    /// What is wrong, in words that follow the option's name ("must be between 0 and 1, not 2").
    pub problem: String,
}

impl OptionError {
    fn new(option: &'static str, problem: impl Into<String>) -> Self {
        Self {
            option,
            problem: problem.into(),
        }
    }

    /// The message with the option spelled by `spell` (e.g. `--iso-opacity`).
    pub fn message(self, spell: impl Fn(&str) -> String) -> String {
        format!("{} {}", spell(self.option), self.problem)
    }
}

impl fmt::Display for OptionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.option, self.problem)
    }
}

impl std::error::Error for OptionError {}

/// The render options given over a study's settings; `None` keeps the study's value.
#[derive(Debug, Clone, Default)]
pub struct ViewOptions {
    /// The rendering mode.
    pub mode: Option<Mode>,
    /// The upper isovalue of two-iso, the scan's units.
    pub iso2: Option<f64>,
    /// The isosurface's opacity, 0–1.
    pub iso_opacity: Option<f32>,
    /// The transfer function.
    pub tf: Option<TransferFunction>,
    /// The sample step, voxels.
    pub step: Option<f64>,
    /// Jitter each pixel's samples.
    pub jitter: Option<bool>,
    /// Shade DVR samples with their gradient.
    pub shade_dvr: Option<bool>,
    /// Skip empty bricks.
    pub skip_empty: Option<bool>,
    /// The background colour, 0–1.
    pub background: Option<[f32; 3]>,
    /// Depth peeling.
    pub peel: PeelOptions,
}

impl ViewOptions {
    /// `settings` with every option given on top.
    pub fn apply(&self, mut s: RenderSettings) -> Result<RenderSettings, OptionError> {
        if let Some(mode) = self.mode {
            s.mode = mode;
        }
        if let Some(iso2) = self.iso2 {
            s.iso2_hu = finite("iso2", iso2)?;
        }
        if let Some(alpha) = self.iso_opacity {
            s.iso_opacity = unit("iso_opacity", alpha)?;
        }
        if let Some(tf) = &self.tf {
            s.tf.clone_from(tf);
        }
        if let Some(step) = self.step {
            if !(step.is_finite() && step > 0.0) {
                return Err(OptionError::new(
                    "step",
                    format!("must be a positive number of voxels, not {step}"),
                ));
            }
            s.step_vox = step;
        }
        s.jitter = self.jitter.unwrap_or(s.jitter);
        s.shade_dvr = self.shade_dvr.unwrap_or(s.shade_dvr);
        s.skip_empty = self.skip_empty.unwrap_or(s.skip_empty);
        if let Some(background) = self.background {
            for c in background {
                unit("background", c)?;
            }
            s.background = background;
        }
        self.peel.apply(&mut s)?;
        Ok(s)
    }
}

/// The depth-peeling options (`mode` peel); `None` keeps the settings' value.
#[derive(Debug, Clone, Default)]
pub struct PeelOptions {
    /// The peel shown.
    pub layer: Option<PeelLayer>,
    /// The peel threshold, the scan's units.
    pub threshold: Option<f64>,
    /// Count crossings into the darker material.
    pub falling: Option<bool>,
    /// Share of what lies in front of the peel kept, 0–1.
    pub keep: Option<f32>,
    /// What rays without the wanted peel show.
    pub unpeeled: Option<Unpeeled>,
    /// The transfer function behind the peel.
    pub tf_after: Option<TransferFunction>,
}

impl PeelOptions {
    fn apply(&self, settings: &mut RenderSettings) -> Result<(), OptionError> {
        let peel = &mut settings.peel;
        if let Some(layer) = self.layer {
            peel.layer = layer;
        }
        if let Some(threshold) = self.threshold {
            peel.threshold_hu = Some(finite("peel_threshold", threshold)?);
        }
        peel.falling = self.falling.unwrap_or(peel.falling);
        if let Some(keep) = self.keep {
            peel.keep = unit("peel_keep", keep)?;
        }
        if let Some(unpeeled) = self.unpeeled {
            peel.unpeeled = unpeeled;
        }
        if let Some(tf) = &self.tf_after {
            peel.tf_after = Some(tf.clone());
        }
        Ok(())
    }
}

/// The endoscope's look (Krüger et al.'s Sinus Endoscopy) asked for over a preset's; `None`
/// keeps the preset's value.
#[derive(Debug, Clone, Default)]
pub struct LookOptions {
    /// Plain, clinical or realistic.
    pub kind: Option<LookKind>,
    /// How secretion is found.
    pub secretion: Option<SecretionMode>,
    /// The secretion threshold, the scan's units.
    pub secretion_iso: Option<f64>,
    /// Wetness, 0–1.
    pub wetness: Option<f32>,
    /// The detail texture (`Some(None)`: none).
    pub texture: Option<Option<Arc<Texture>>>,
    /// The edge of one texture tile, mm.
    pub texture_scale: Option<f32>,
    /// The specular map (bright: wetter, glossier); `None` keeps the one derived from the
    /// detail texture.
    pub specular_map: Option<Arc<Texture>>,
    /// The distance at which the tip's light halves, mm (0: no fall-off).
    pub attenuation: Option<f32>,
    /// Phong or image-based lighting.
    pub lighting: Option<Lighting>,
}

impl LookOptions {
    /// The options that only a clinical or realistic look uses, as given (keys).
    fn given(&self) -> Vec<&'static str> {
        let keys = [
            ("secretion", self.secretion.is_some()),
            ("secretion_iso", self.secretion_iso.is_some()),
            ("wetness", self.wetness.is_some()),
            ("texture", self.texture.is_some()),
            ("texture_scale", self.texture_scale.is_some()),
            ("specular_map", self.specular_map.is_some()),
            ("attenuation", self.attenuation.is_some()),
            ("lighting", self.lighting.is_some()),
        ];
        keys.iter().filter(|(_, on)| *on).map(|(k, _)| *k).collect()
    }

    /// The look asked for over `base` (a preset's look in the scan's units); `tissue_iso`, the
    /// isovalue the user gave, is the tissue threshold the rays stop at. `None` for the plain
    /// look, which has no stages (its options given are an error naming the first).
    pub fn resolve(
        &self,
        base: &PresetLook,
        tissue_iso: Option<f64>,
    ) -> Result<Option<Look>, OptionError> {
        let kind = self.kind.unwrap_or(base.kind);
        let Some(mut look) = Look::of_kind(kind, base) else {
            return match self.given().first() {
                Some(key) => Err(OptionError::new(
                    key,
                    "only applies to the clinical or realistic look (the plain look has no \
                     deferred stage)",
                )),
                None => Ok(None),
            };
        };
        if let Some(iso) = tissue_iso {
            look.ray.tissue_hu = finite("iso", iso)?;
        }
        if let Some(iso) = self.secretion_iso {
            look.ray.secretion_hu = finite("secretion_iso", iso)?;
        }
        if let Some(mode) = self.secretion {
            look.ray.secretion = mode;
        }
        if let Some(w) = self.wetness {
            look.shading.wetness = unit("wetness", w)?;
        }
        if let Some(texture) = &self.texture {
            look.shading.texture.clone_from(texture);
        }
        if let Some(map) = &self.specular_map {
            look.shading.specular_map = Some(map.clone());
        }
        if let Some(mm) = self.texture_scale {
            if !(mm.is_finite() && mm > 0.0) {
                return Err(OptionError::new(
                    "texture_scale",
                    format!("must be a positive number of mm, not {mm}"),
                ));
            }
            look.shading.texture_mm = mm;
        }
        if let Some(mm) = self.attenuation {
            if !(mm.is_finite() && mm >= 0.0) {
                return Err(OptionError::new(
                    "attenuation",
                    format!("must be a distance in mm (0 for none), not {mm}"),
                ));
            }
            look.shading.attenuation_mm = (mm > 0.0).then_some(mm);
        }
        if let Some(lighting) = &self.lighting {
            look.shading.lighting.clone_from(lighting);
        }
        let invalid =
            |e: crate::look::LookError| OptionError::new("look", format!("is invalid: {e}"));
        look.ray.validate().map_err(invalid)?;
        look.shading.validate().map_err(invalid)?;
        Ok(Some(look))
    }
}

/// The names the options take, parsed with the error a user should see.
pub mod named {
    use super::{LookKind, Mode, OptionError, PeelLayer, SecretionMode, Unpeeled};

    /// A rendering mode by name.
    pub fn mode(name: &str) -> Result<Mode, OptionError> {
        Mode::from_name(name).ok_or_else(|| {
            OptionError::new(
                "mode",
                format!(
                    "{name:?} is unknown; choose iso, dvr, hybrid, two-iso, mip, minip or peel"
                ),
            )
        })
    }

    /// A look by name.
    pub fn look(name: &str) -> Result<LookKind, OptionError> {
        LookKind::from_name(name).ok_or_else(|| {
            OptionError::new(
                "look",
                format!("{name:?} is unknown; choose plain, clinical or realistic"),
            )
        })
    }

    /// A secretion mode by name.
    pub fn secretion(name: &str) -> Result<SecretionMode, OptionError> {
        SecretionMode::from_name(name).ok_or_else(|| {
            OptionError::new(
                "secretion",
                format!("{name:?} is an unknown secretion mode; choose off, on or accumulate"),
            )
        })
    }

    /// What unpeeled rays show, by name.
    pub fn unpeeled(name: &str) -> Result<Unpeeled, OptionError> {
        match name.trim().to_ascii_lowercase().as_str() {
            "discard" => Ok(Unpeeled::Discard),
            "context" => Ok(Unpeeled::Context),
            _ => Err(OptionError::new(
                "unpeeled",
                format!("{name:?} is unknown; choose discard or context"),
            )),
        }
    }

    /// The peel shown: `N` (1, 2, 3 …) or `last` (ASCII case and spaces ignored).
    pub fn peel_layer(text: &str) -> Result<PeelLayer, OptionError> {
        let text = text.trim();
        if text.eq_ignore_ascii_case("last") {
            return Ok(PeelLayer::Last);
        }
        match text.parse::<u32>() {
            Ok(n) if n >= 1 => Ok(PeelLayer::Nth(n)),
            _ => Err(OptionError::new(
                "peel",
                format!("{text:?} is not a peel: give 1, 2, 3 … or last"),
            )),
        }
    }
}

/// `value` when finite, else an error naming `option`.
fn finite(option: &'static str, value: f64) -> Result<f64, OptionError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(OptionError::new(
            option,
            format!("must be a finite number, not {value}"),
        ))
    }
}

/// `value` when within 0–1, else an error naming `option`.
fn unit(option: &'static str, value: f32) -> Result<f32, OptionError> {
    if (0.0..=1.0).contains(&value) {
        Ok(value)
    } else {
        Err(OptionError::new(
            option,
            format!("must be between 0 and 1, not {value}"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_outside_their_range_name_the_option() {
        let s = RenderSettings::default();
        let bad = ViewOptions {
            iso_opacity: Some(1.5),
            ..ViewOptions::default()
        };
        let e = bad.apply(s.clone()).unwrap_err();
        assert_eq!(e.option, "iso_opacity");
        let spelled = e.message(|k| format!("--{}", k.replace('_', "-")));
        assert!(
            spelled.starts_with("--iso-opacity must be between 0 and 1"),
            "{spelled}"
        );
        let nan = ViewOptions {
            peel: PeelOptions {
                threshold: Some(f64::NAN),
                ..PeelOptions::default()
            },
            ..ViewOptions::default()
        };
        assert_eq!(nan.apply(s).unwrap_err().option, "peel_threshold");
    }

    #[test]
    fn options_given_win_and_absent_ones_keep_the_settings() {
        let s = RenderSettings {
            shade_dvr: true,
            ..RenderSettings::default()
        };
        let options = ViewOptions {
            mode: Some(Mode::Peel),
            peel: PeelOptions {
                layer: Some(PeelLayer::Last),
                keep: Some(0.25),
                ..PeelOptions::default()
            },
            ..ViewOptions::default()
        };
        let out = options.apply(s).unwrap();
        assert_eq!(out.mode, Mode::Peel);
        assert!(out.shade_dvr);
        assert_eq!(out.peel.layer, PeelLayer::Last);
        assert_eq!(out.peel.keep, 0.25);
    }

    #[test]
    fn names_parse() {
        assert_eq!(named::peel_layer(" Last"), Ok(PeelLayer::Last));
        assert_eq!(named::peel_layer("2"), Ok(PeelLayer::Nth(2)));
        assert!(named::peel_layer("0").is_err());
        assert!(named::peel_layer("first").is_err());
        assert_eq!(named::unpeeled("Context"), Ok(Unpeeled::Context));
        assert!(named::mode("photo").is_err());
    }
}
