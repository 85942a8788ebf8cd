//! A preset carried from its reference scale to a scan's units, and the view without a preset.

use super::brain::measure_csf;
use super::{short, LinearMap, ScanValues, ValueKind};
use crate::look::PresetLook;
use crate::navigate::LumenSide;
use crate::presets::{Preset, Reference, Surface};
use crate::render::{RenderSettings, TransferFunction};
use crate::views::slices::Window;
use crate::Volume;

/// A preset in a scan's units, and what was resolved, in words.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolved {
    /// The preset with every value (isovalues, lumen threshold and side, window) in the scan's
    /// units.
    pub preset: Preset,
    /// Its transfer function in the scan's units.
    pub tf: TransferFunction,
    /// The map from the preset's reference scale to the scan's units.
    pub map: LinearMap,
    /// One line: what the lumen is in this scan and why, e.g.
    /// `"ventricles: CSF ≤ 74 (T1-like, dark)"`.
    pub summary: String,
}

impl Resolved {
    /// The render settings of the resolved preset (see [`Preset::settings`]).
    pub fn settings(&self) -> RenderSettings {
        RenderSettings {
            tf: self.tf.clone(),
            ..self.preset.settings()
        }
    }
}

/// `preset` in the units of `volume`, whose histogram is `scan`:
/// - HU presets: shifted by the scan's HU offset (CT, HU + 1024); on a scan not recognised as
///   HU they are used as they are, and the summary says so;
/// - the T1 brain preset: stretched from the reference CSF and tissue levels to the scan's own
///   ([`measure_csf`]), reversed where CSF is bright.
pub fn resolve(preset: &Preset, volume: &Volume, scan: &ScanValues) -> Resolved {
    let (map, why) = match (preset.reference, scan.kind) {
        (Reference::Hounsfield, ValueKind::Hounsfield { .. }) => {
            (scan.from_hounsfield(), scan.to_string())
        }
        (Reference::Hounsfield, ValueKind::Intensity) => (
            LinearMap::IDENTITY,
            "values not recognised as HU; the preset's HU used as they are".to_owned(),
        ),
        (Reference::AsGiven, _) => (
            LinearMap::IDENTITY,
            "the preset's values used as they are (tuned on one scan, no tissue anchor)".to_owned(),
        ),
        (Reference::T1Brain { csf, tissue }, _) => match measure_csf(volume, scan) {
            Some(c) => (
                LinearMap::through((csf, tissue), (c.csf, c.tissue)),
                c.weighting().to_owned(),
            ),
            None => (
                LinearMap::IDENTITY,
                "no clear CSF/tissue contrast at the centre; the T1 values used as they are"
                    .to_owned(),
            ),
        },
    };
    let mapped = map_preset(preset, map);
    let summary = match mapped.lumen {
        Some(lumen) => format!(
            "{}: {} {} {} ({why})",
            preset.name,
            lumen.tissue,
            if lumen.side == LumenSide::Below {
                "<"
            } else {
                ">"
            },
            short(lumen.threshold),
        ),
        None => format!("{}: wall at {} ({why})", preset.name, short(mapped.iso)),
    };
    Resolved {
        preset: mapped,
        tf: map_tf(&preset.transfer_function(), map),
        map,
        summary,
    }
}

/// The look's values without a preset ([`PresetLook::CT`]) in the units of `scan`, as
/// [`default_settings`] carries the render settings.
pub fn default_look(scan: &ScanValues) -> PresetLook {
    let map = scan.from_hounsfield();
    let ct = PresetLook::CT;
    PresetLook {
        tissue: map.apply(ct.tissue),
        secretion: map.apply(ct.secretion),
        ..ct
    }
}

/// The render settings without a preset ([`RenderSettings::default`]: the wall at −500 HU, the
/// −700…−300 HU ramp) in the units of `scan` (see [`ScanValues::from_hounsfield`]: the wall on
/// Otsu's background/object threshold for a scan that is not in HU).
pub fn default_settings(scan: &ScanValues) -> RenderSettings {
    let base = RenderSettings::default();
    let map = scan.from_hounsfield();
    RenderSettings {
        iso_hu: map.apply(base.iso_hu),
        iso2_hu: map.apply(base.iso2_hu),
        tf: map_tf(&base.tf, map),
        ..base
    }
}

fn map_preset(preset: &Preset, map: LinearMap) -> Preset {
    let mut p = *preset;
    p.iso = map.apply(p.iso);
    p.look.tissue = map.apply(p.look.tissue);
    p.look.secretion = map.apply(p.look.secretion);
    p.iso2 = p.iso2.map(|s| Surface {
        iso: map.apply(s.iso),
        ..s
    });
    if let Some(lumen) = p.lumen.as_mut() {
        lumen.threshold = map.apply(lumen.threshold);
        if map.scale < 0.0 {
            lumen.side = match lumen.side {
                LumenSide::Below => LumenSide::Above,
                LumenSide::Above => LumenSide::Below,
            };
        }
    }
    p.window = Window {
        level_hu: map.apply(p.window.level_hu),
        width_hu: p.window.width_hu * map.scale.abs(),
    };
    p
}

/// The transfer function with every point's value mapped (and the lists reversed where the map
/// reverses the order, so they stay sorted).
fn map_tf(tf: &TransferFunction, map: LinearMap) -> TransferFunction {
    let mut opacity: Vec<(f64, f32)> = tf
        .opacity_points()
        .iter()
        .map(|&(v, a)| (map.apply(v), a))
        .collect();
    let mut color: Vec<(f64, [f32; 3])> = tf
        .color_points()
        .iter()
        .map(|&(v, c)| (map.apply(v), c))
        .collect();
    if map.scale < 0.0 {
        opacity.reverse();
        color.reverse();
    }
    TransferFunction::from_points(&opacity, &color)
        .expect("a monotone map keeps a valid transfer function valid")
}
