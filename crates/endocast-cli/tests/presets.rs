//! `endocast presets`: the library's table, as text and as JSON.

use crate::common::endocast;
use endocast_core::presets;

#[test]
fn presets_lists_every_preset_as_a_table_and_as_json() {
    let out = endocast(&["presets"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + presets::ALL.len(), "{text}");
    assert!(lines[0].starts_with("NAME"), "{text}");
    for (line, preset) in lines[1..].iter().zip(presets::ALL) {
        assert!(line.starts_with(preset.name), "{line}");
        assert!(line.contains(preset.description), "{line}");
    }

    let out = endocast(&["presets", "--json"]);
    assert!(out.status.success());
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let all = json.as_array().unwrap();
    assert_eq!(all.len(), presets::ALL.len());
    let keys = [
        "name",
        "description",
        "mode",
        "tf",
        "iso",
        "iso_opacity",
        "iso_color",
        "iso2",
        "lumen",
        "window",
        "projection",
        "fov_deg",
    ];
    for (object, preset) in all.iter().zip(presets::ALL) {
        for key in keys {
            assert!(object.get(key).is_some(), "{} lacks {key}", preset.name);
        }
        assert_eq!(object["name"], preset.name);
        assert_eq!(object["mode"], preset.mode.name());
        assert_eq!(object["iso"], preset.iso);
        assert_eq!(object["fov_deg"], preset.fov_deg);
        assert_eq!(object["projection"], "pinhole");
    }
    let find = |name: &str| all.iter().find(|p| p["name"] == name).unwrap();
    let bronchoscopy = find("bronchoscopy");
    assert_eq!(bronchoscopy["iso_opacity"], 0.6);
    assert_eq!(bronchoscopy["lumen"]["threshold"], -900.0);
    assert_eq!(bronchoscopy["lumen"]["side"], "below");
    assert_eq!(bronchoscopy["window"]["level"], -600.0);
    let angioscopy = find("angioscopy");
    assert_eq!(angioscopy["iso2"]["iso"], 700.0);
    assert_eq!(angioscopy["lumen"]["side"], "above");
    assert_eq!(find("ramp")["lumen"], serde_json::Value::Null);
    assert_eq!(find("ramp")["iso2"], serde_json::Value::Null);
}
