//! Which lumen a command navigates: the region-growing threshold and lumen side, from the
//! preset's lumen (see [`crate::presets`]) and what the user changed.

use super::lumen::LumenSide;
use crate::presets::{self, Preset};
use thiserror::Error;

/// The region-growing threshold (physical units) and lumen side of the preset called `name`, or
/// `None` for presets that are not a flight through a lumen (`ramp`, `complex`) and unknown names.
/// The values live in [`presets::ALL`].
pub fn preset_lumen(name: &str) -> Option<(f64, LumenSide)> {
    let lumen = Preset::find(name)?.lumen?;
    Some((lumen.threshold, lumen.side))
}

/// What was asked about the lumen: a preset, the wall isovalue, an explicit threshold and side.
/// [`LumenChoice::resolve`] turns it into the threshold and side to grow the lumen with.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LumenChoice<'a> {
    /// The procedure, whose lumen gives the threshold and side. Default none.
    pub preset: Option<&'a Preset>,
    /// The wall isovalue, physical units; `None` (the default) means the preset's.
    pub iso: Option<f64>,
    /// An explicit region-growing threshold, physical units, overriding the rest. Default none.
    pub threshold: Option<f64>,
    /// The lumen is brighter than the wall (contrast, CSF on T2). Default false: the preset's
    /// side, else darker (air, CSF on T1).
    pub bright_lumen: bool,
    /// A central structure the lumen must be (see [`Central`]); default none: the largest
    /// lumen.
    pub within: Option<Central>,
}

/// A structure at the object's centre (the lateral ventricles): the largest component that
/// reaches into `region` and does not touch the volume's border. Where the lumen at the
/// threshold leaks out (ventricles joined to the CSF around the brain, and through a dark
/// skull to the background), the threshold is moved towards `floor` in steps until it does
/// not; where it never does (a skull-stripped brain), the lumen is cut at the object's
/// surface (see [`crate::navigate::CENTRAL_DEPTH_MM`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Central {
    /// Inclusive voxel box, lowest and highest corner.
    pub region: ([usize; 3], [usize; 3]),
    /// The lumen's own level (CSF), physical units: the threshold never reaches it.
    pub floor: f64,
    /// The background's level, physical units: the voxels below it joined to the volume's
    /// border lie outside the object (the head, or a skull-stripped brain), and the structure
    /// lies deep inside that (see [`crate::navigate::CENTRAL_DEPTH_MM`]).
    pub background: f64,
}

/// A lumen choice that names no threshold.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum LumenChoiceError {
    /// The preset is not a procedure in a lumen (the benchmark presets).
    #[error("preset {0:?} names no lumen; use {lumens}", lumens = presets::lumen_names())]
    PresetHasNoLumen(&'static str),
    /// Neither a preset, an isovalue nor a threshold was given.
    #[error("no lumen threshold: give a preset, an isovalue or a threshold")]
    Underdetermined,
    /// The threshold works out NaN or infinite.
    #[error("the lumen threshold must be a finite number, not {0}")]
    NotFinite(f64),
}

impl LumenChoice<'_> {
    /// The threshold and side of the lumen:
    /// - an explicit `threshold` wins;
    /// - else the preset's threshold, moved by as much as `iso` moves the wall from the preset's
    ///   isovalue (a scan stored as HU + 1024, such as CThead, moves both by 1024; the airways'
    ///   −900 HU stays 400 below their −500 HU wall);
    /// - else, without a preset, the isovalue itself.
    ///
    /// The side is above with `bright_lumen`, else the preset's, else below.
    pub fn resolve(&self) -> Result<(f64, LumenSide), LumenChoiceError> {
        let lumen = match self.preset {
            Some(preset) => Some(
                preset
                    .lumen
                    .map(|lumen| (lumen, preset.iso))
                    .ok_or(LumenChoiceError::PresetHasNoLumen(preset.name))?,
            ),
            None => None,
        };
        let side = match (self.bright_lumen, lumen) {
            (true, _) => LumenSide::Above,
            (false, Some((lumen, _))) => lumen.side,
            (false, None) => LumenSide::Below,
        };
        let threshold = match (self.threshold, lumen, self.iso) {
            (Some(t), _, _) => t,
            (None, Some((lumen, preset_iso)), iso) => {
                lumen.threshold + iso.unwrap_or(preset_iso) - preset_iso
            }
            (None, None, Some(iso)) => iso,
            (None, None, None) => return Err(LumenChoiceError::Underdetermined),
        };
        if !threshold.is_finite() {
            return Err(LumenChoiceError::NotFinite(threshold));
        }
        Ok((threshold, side))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::RenderSettings;

    #[test]
    fn every_endoscopic_preset_has_a_lumen_on_the_renderers_side_of_its_surface() {
        for name in [
            "colonoscopy",
            "bronchoscopy",
            "angioscopy",
            "sinus",
            "ventricles",
        ] {
            let (threshold, side) = preset_lumen(name).unwrap();
            let iso = RenderSettings::preset(name).unwrap().iso_hu;
            // The grown lumen must not reach past the surface the renderer draws.
            assert!(side.holds(threshold, iso) || threshold == iso, "{name}");
        }
        assert_eq!(preset_lumen("ramp"), None);
        assert_eq!(preset_lumen(" Bronchoscopy "), preset_lumen("bronchoscopy"));
    }

    fn choice(
        preset: Option<&str>,
        iso: Option<f64>,
        threshold: Option<f64>,
        bright_lumen: bool,
    ) -> LumenChoice<'static> {
        LumenChoice {
            preset: preset.map(|name| Preset::find(name).unwrap()),
            iso,
            threshold,
            bright_lumen,
            within: None,
        }
    }

    #[test]
    fn the_preset_threshold_moves_with_the_isovalue() {
        let resolve = |preset, iso| choice(preset, iso, None, false).resolve();
        assert_eq!(
            resolve(Some("bronchoscopy"), None),
            Ok((-900.0, LumenSide::Below))
        );
        // CThead stores HU + 1024: an isovalue of 524 puts the airway threshold at 124.
        assert_eq!(resolve(Some("bronchoscopy"), Some(524.0)).unwrap().0, 124.0);
        assert_eq!(
            resolve(Some("angioscopy"), None).unwrap().1,
            LumenSide::Above
        );
        assert_eq!(resolve(None, Some(-400.0)), Ok((-400.0, LumenSide::Below)));
        assert_eq!(
            choice(None, None, Some(7.0), true).resolve(),
            Ok((7.0, LumenSide::Above))
        );
        assert_eq!(resolve(None, None), Err(LumenChoiceError::Underdetermined));
        assert_eq!(
            resolve(Some("ramp"), None),
            Err(LumenChoiceError::PresetHasNoLumen("ramp"))
        );
        assert!(matches!(
            choice(None, None, Some(f64::NAN), false).resolve(),
            Err(LumenChoiceError::NotFinite(_))
        ));
        // An explicit threshold and side win over the preset's.
        assert_eq!(
            choice(Some("colonoscopy"), Some(-400.0), Some(-600.0), true).resolve(),
            Ok((-600.0, LumenSide::Above))
        );
    }

    #[test]
    fn errors_name_the_lumen_presets() {
        let message = LumenChoiceError::PresetHasNoLumen("ramp").to_string();
        assert!(
            message.contains("\"ramp\"") && message.contains("bronchoscopy"),
            "{message}"
        );
    }
}
