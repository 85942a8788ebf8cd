//! The options that say which lumen a command navigates, shared by `render` (default viewpoint),
//! `path` and `fly`; the rule that turns them into a threshold is the library's
//! ([`endocast_core::study::Study::lumen`]).

use clap::Args;

/// How to tell the lumen from the wall.
#[derive(Args, Debug, Clone, Default)]
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
