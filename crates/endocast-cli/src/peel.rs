//! The depth-peeling options (`--mode peel`), shared by every command that renders.

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use endocast_core::render::{PeelLayer, Unpeeled};
use endocast_core::study::PeelOptions;

/// How `--mode peel` peels (Borland et al.'s volumetric depth peeling).
#[derive(Args, Debug, Clone)]
pub struct PeelArgs {
    /// The peel shown: 1, 2, 3 … (the n-th crossing of the peel threshold) or last (default:
    /// the preset's, else 1).
    #[arg(long, value_name = "N|last", value_parser = parse_layer)]
    peel: Option<PeelLayer>,
    /// The peel threshold, physical units (default: the preset's, else --iso).
    #[arg(long, value_name = "VALUE", allow_negative_numbers = true)]
    peel_threshold: Option<f64>,
    /// Count crossings into the darker material as peels (default: into the brighter).
    #[arg(long)]
    peel_falling: bool,
    /// Share of what lies in front of the peel that stays visible, 0–1 (default 0: discarded).
    #[arg(long, value_name = "0..1")]
    peel_keep: Option<f32>,
    /// Rays that never reach the wanted peel: discard (transparent) or context (drawn with
    /// --tf). Default discard.
    #[arg(long, value_enum)]
    unpeeled: Option<UnpeeledArg>,
    /// Transfer function behind the peel: a JSON file or a preset name (default: the
    /// preset's, else as --tf).
    #[arg(long, value_name = "FILE|NAME")]
    tf_after: Option<String>,
}

/// `--unpeeled`'s values.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum UnpeeledArg {
    Discard,
    Context,
}

impl PeelArgs {
    /// The options given, transfer function behind the peel read.
    pub fn options(&self) -> Result<PeelOptions> {
        Ok(PeelOptions {
            layer: self.peel,
            threshold: self.peel_threshold,
            falling: self.peel_falling.then_some(true),
            keep: self.peel_keep,
            unpeeled: self.unpeeled.map(|u| match u {
                UnpeeledArg::Discard => Unpeeled::Discard,
                UnpeeledArg::Context => Unpeeled::Context,
            }),
            tf_after: self
                .tf_after
                .as_deref()
                .map(endocast_io::transfer_json::transfer_function)
                .transpose()
                .context("cannot use the transfer function behind the peel")?,
        })
    }
}

/// `N` (1, 2, 3 …) or `last`, as case files name it too.
fn parse_layer(text: &str) -> Result<PeelLayer, String> {
    endocast_io::case::peel_layer(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_parse() {
        assert_eq!(parse_layer("2"), Ok(PeelLayer::Nth(2)));
        assert_eq!(parse_layer(" Last"), Ok(PeelLayer::Last));
        assert!(parse_layer("0").is_err());
        assert!(parse_layer("-1").is_err());
        assert!(parse_layer("first").is_err());
    }
}
