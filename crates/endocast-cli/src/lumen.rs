//! The options that say which lumen a command navigates, shared by `render` (default viewpoint),
//! `path` and `fly`; the rule that turns them into a threshold is the library's
//! ([`LumenChoice::resolve`]).

use anyhow::{bail, Result};
use clap::Args;
use endocast_core::navigate::{LumenChoice, LumenChoiceError, LumenSide};
use endocast_core::presets::Preset;

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
    /// The lumen these options and `preset` (if any) describe, with the wall isovalue `iso`
    /// (the preset's when `None`).
    pub fn choice<'a>(&self, preset: Option<&'a Preset>, iso: Option<f64>) -> LumenChoice<'a> {
        LumenChoice {
            preset,
            iso,
            threshold: self.lumen_threshold,
            bright_lumen: self.bright_lumen,
            within: None,
        }
    }

    /// The threshold and side for `preset` (if any) and the wall isovalue `iso` (the preset's
    /// when `None`), with the error in terms of the options.
    pub fn resolve(&self, preset: Option<&Preset>, iso: Option<f64>) -> Result<(f64, LumenSide)> {
        match self.choice(preset, iso).resolve() {
            Ok(lumen) => Ok(lumen),
            Err(LumenChoiceError::Underdetermined) => {
                bail!("give --preset, --iso or --lumen-threshold")
            }
            Err(error) => Err(error.into()),
        }
    }
}
