//! `--cleanse on|off`: electronic cleansing of tagged fluid, for every command that reads a scan.

use anyhow::{Context, Result};
use clap::Args;
use endocast_core::cleanse::Cleanse;
use endocast_core::Volume;

/// Whether the scan's tagged fluid is removed before anything else sees it.
#[derive(Args, Debug, Clone)]
pub struct CleanseArgs {
    /// Electronic cleansing (CT colonography): pools of oral-contrast-tagged fluid lying under
    /// air, and their partial volumes with air and wall, replaced by air, so the wall under a
    /// pool renders as wall. Bone, contrast-filled vessels and bowel full of fluid (no air level)
    /// are kept. on or off.
    #[arg(long, value_name = "on|off", default_value = "off", value_parser = parse_cleanse)]
    pub cleanse: Cleanse,
}

impl CleanseArgs {
    /// `volume` cleansed when asked for, saying what was removed on stderr.
    pub fn apply(&self, volume: Volume) -> Result<Volume> {
        let (volume, summary) = self.cleanse.apply(volume).context("--cleanse on")?;
        if let Some(summary) = summary {
            eprintln!("{summary}");
        }
        Ok(volume)
    }
}

fn parse_cleanse(text: &str) -> Result<Cleanse, String> {
    Cleanse::from_name(text).ok_or_else(|| format!("expected on or off, not {text:?}"))
}
