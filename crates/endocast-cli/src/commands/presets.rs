//! `endocast presets`: the preset table of the library, as an aligned table or as JSON.

use anyhow::{Context, Result};
use clap::Args;
use endocast_core::navigate::LumenSide;
use endocast_core::presets::{self, Preset};
use endocast_core::render::PeelLayer;
use serde_json::{json, Value};
use std::io::Write;

/// Arguments of `endocast presets`.
#[derive(Args, Debug)]
pub struct PresetsArgs {
    /// Print a JSON array with one object per preset, every field included.
    #[arg(long)]
    json: bool,
}

/// Runs `endocast presets`.
pub fn run(args: &PresetsArgs) -> Result<()> {
    let text = if args.json {
        let all: Vec<Value> = presets::iter().map(preset_json).collect();
        serde_json::to_string_pretty(&all)? + "\n"
    } else {
        table()
    };
    // Written, not printed: a closed pipe (`| head`) is an error, not a panic.
    std::io::stdout()
        .lock()
        .write_all(text.as_bytes())
        .context("cannot write to stdout")
}

/// An `f32` setting as the decimal it was written as (0.6, not 0.6000000238418579).
fn decimal(value: f32) -> f64 {
    value.to_string().parse().unwrap_or(f64::from(value))
}

fn decimals(values: [f32; 3]) -> [f64; 3] {
    values.map(decimal)
}

/// One preset with every field; colours are the ones rendered (the renderer's default where
/// the preset keeps it).
fn preset_json(preset: &Preset) -> Value {
    let settings = preset.settings();
    json!({
        "name": preset.name,
        "description": preset.description,
        "mode": preset.mode.name(),
        "tf": preset.tf,
        "iso": preset.iso,
        "iso_opacity": decimal(preset.iso_opacity),
        "iso_color": decimals(settings.iso_color),
        "iso2": preset.iso2.map(|upper| json!({
            "iso": upper.iso,
            "opacity": decimal(upper.opacity),
            "color": decimals(settings.iso2_color),
        })),
        "peel": preset.peel.map(|peel| json!({
            "threshold": peel.threshold,
            "falling": peel.falling,
            "layer": match peel.layer {
                PeelLayer::Nth(n) => n.to_string(),
                PeelLayer::Last => "last".to_owned(),
            },
            "tf_after": peel.tf_after,
        })),
        "lumen": preset.lumen.map(|lumen| json!({
            "threshold": lumen.threshold,
            "side": lumen.side.to_string(),
        })),
        "window": {
            "level": preset.window.level_hu,
            "width": preset.window.width_hu,
        },
        "projection": preset.projection.name(),
        "fov_deg": preset.fov_deg,
    })
}

/// The presets as text columns under a header, each column as wide as its widest cell.
fn table() -> String {
    let header = [
        "NAME",
        "MODE",
        "TF",
        "ISO",
        "OPACITY",
        "ISO2",
        "LUMEN",
        "WINDOW",
        "LENS",
        "DESCRIPTION",
    ];
    let mut rows = vec![header.map(String::from)];
    for p in presets::iter() {
        rows.push([
            p.name.to_owned(),
            p.mode.name().to_owned(),
            p.tf.to_owned(),
            p.iso.to_string(),
            p.iso_opacity.to_string(),
            p.iso2
                .map_or("-".into(), |s| format!("{} @ {}", s.iso, s.opacity)),
            p.lumen.map_or("-".into(), |l| {
                let sign = match l.side {
                    LumenSide::Below => '<',
                    LumenSide::Above => '>',
                };
                format!("{sign} {}", l.threshold)
            }),
            format!("{},{}", p.window.level_hu, p.window.width_hu),
            format!("{} {}°", p.projection.name(), p.fov_deg),
            p.description.to_owned(),
        ]);
    }
    let mut widths = [0; 10];
    for row in &rows {
        for (width, cell) in widths.iter_mut().zip(row) {
            *width = (*width).max(cell.chars().count());
        }
    }
    let mut text = String::new();
    for row in &rows {
        let cells: Vec<String> = row
            .iter()
            .zip(widths)
            .map(|(cell, width)| format!("{cell:<width$}"))
            .collect();
        text.push_str(cells.join("  ").trim_end());
        text.push('\n');
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_has_a_row_per_preset_in_aligned_columns() {
        let text = table();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 1 + presets::ALL.len());
        let column = |line: &str, word: &str| line.find(word);
        let lens = column(lines[0], "LENS");
        assert!(
            lines[1..].iter().all(|l| column(l, "pinhole") == lens),
            "{text}"
        );
        assert!(text.contains("< -900"), "{text}");
    }
}
