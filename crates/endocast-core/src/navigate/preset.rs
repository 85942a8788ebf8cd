//! Which lumen each endoscopic preset flies through: the threshold that separates it from the wall
//! for region growing, and on which side of it the lumen lies.

use super::lumen::LumenSide;

/// The region-growing threshold (physical units) and lumen side of an endoscopic preset, or
/// `None` for presets that are not a flight through a lumen (`ramp`, `complex`) and unknown names.
///
/// The thresholds are those measured on the shared scans (`shared/data/README.md`): −500 HU
/// separates gas from the colon and sinus walls; airways need −900 HU, because at −500 the thin
/// bronchial wall leaks into the lung (lung −820…−950 HU, tracheal air −973 HU); the enhanced
/// aorta lies above 130 HU; ventricular CSF is dark on T1, below the renderer's isovalue of 75.
pub fn preset_lumen(name: &str) -> Option<(f64, LumenSide)> {
    Some(match name.trim().to_ascii_lowercase().as_str() {
        "colonoscopy" | "sinus" => (-500.0, LumenSide::Below),
        "bronchoscopy" => (-900.0, LumenSide::Below),
        "angioscopy" => (130.0, LumenSide::Above),
        "ventricles" => (75.0, LumenSide::Below),
        _ => return None,
    })
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
}
