//! Which lumen a command navigates: the region-growing threshold and side, from the preset and
//! the isovalue the user gave; shared by `render` (default viewpoint), `path` and `fly`.

use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::navigate::{preset_lumen, LumenSide};
use endocast_core::render::RenderSettings;

/// How to tell the lumen from the wall.
#[derive(Args, Debug, Clone)]
pub struct LumenArgs {
    /// Region-growing threshold of the lumen, physical units (default: the preset's — e.g.
    /// −900 HU for bronchoscopy, where −500 would leak into the lung — moved by as much as
    /// --iso moves the wall; without a preset, the isovalue itself).
    #[arg(long, value_name = "VALUE", allow_negative_numbers = true)]
    pub lumen_threshold: Option<f64>,
    /// The lumen is brighter than the wall (contrast-filled vessels, CSF on T2); default: the
    /// preset's, else darker (air, CSF on T1).
    #[arg(long)]
    pub bright_lumen: bool,
}

impl LumenArgs {
    /// The threshold and side for `preset` (if any) and the wall isovalue `iso` (the preset's
    /// when `None`).
    pub fn resolve(&self, preset: Option<&str>, iso: Option<f64>) -> Result<(f64, LumenSide)> {
        let known = match preset {
            Some(name) => Some(preset_offset(name)?),
            None => None,
        };
        let side = match (self.bright_lumen, known) {
            (true, _) => LumenSide::Above,
            (false, Some((_, _, side))) => side,
            (false, None) => LumenSide::Below,
        };
        let threshold = match (self.lumen_threshold, known, iso) {
            (Some(t), _, _) => t,
            (None, Some((t, preset_iso, _)), iso) => t + iso.unwrap_or(preset_iso) - preset_iso,
            (None, None, Some(iso)) => iso,
            (None, None, None) => bail!("give --preset, --iso or --lumen-threshold"),
        };
        if !threshold.is_finite() {
            bail!("the lumen threshold must be a finite number, not {threshold}");
        }
        Ok((threshold, side))
    }
}

/// The preset's lumen threshold, its wall isovalue and its lumen side.
fn preset_offset(name: &str) -> Result<(f64, f64, LumenSide)> {
    let (threshold, side) = preset_lumen(name).with_context(|| {
        format!("--preset {name:?} names no lumen; use colonoscopy, bronchoscopy, angioscopy, sinus or ventricles")
    })?;
    let iso = RenderSettings::preset(name).map_or(threshold, |s| s.iso_hu);
    Ok((threshold, iso, side))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(threshold: Option<f64>, bright: bool) -> LumenArgs {
        LumenArgs {
            lumen_threshold: threshold,
            bright_lumen: bright,
        }
    }

    #[test]
    fn the_preset_threshold_moves_with_the_isovalue() {
        let a = args(None, false);
        assert_eq!(
            a.resolve(Some("bronchoscopy"), None).unwrap(),
            (-900.0, LumenSide::Below)
        );
        // CThead stores HU + 1024: an isovalue of 524 puts the airway threshold at 124.
        assert_eq!(
            a.resolve(Some("bronchoscopy"), Some(524.0)).unwrap().0,
            124.0
        );
        assert_eq!(
            a.resolve(Some("angioscopy"), None).unwrap().1,
            LumenSide::Above
        );
        assert_eq!(
            a.resolve(None, Some(-400.0)).unwrap(),
            (-400.0, LumenSide::Below)
        );
        assert_eq!(
            args(Some(7.0), true).resolve(None, None).unwrap(),
            (7.0, LumenSide::Above)
        );
        assert!(a.resolve(None, None).is_err());
        assert!(a.resolve(Some("ramp"), None).is_err());
        assert!(args(Some(f64::NAN), false).resolve(None, None).is_err());
    }
}
