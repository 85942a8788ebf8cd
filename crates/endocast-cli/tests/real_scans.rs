//! Endoscopic renders from inside four real scans (poses in `bench/scenes.json`): the lumen wall
//! must close around the view — nearly every ray hits it, at depths a lumen of that organ allows.

use crate::common::{endocast, read_npy};
use endocast_testdata::shared_data;
use std::path::PathBuf;

/// The scenes file, with paths relative to the repository root.
fn scenes() -> serde_json::Value {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("bench/scenes.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn triple(v: &serde_json::Value) -> String {
    let n: Vec<String> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap().to_string())
        .collect();
    n.join(",")
}

#[test]
fn the_lumen_wall_surrounds_the_endoscope_in_every_real_scan() {
    if shared_data("").is_none() {
        return;
    }
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = tempfile::tempdir().unwrap();
    let scenes = scenes();
    for scene in scenes["scenes"].as_array().unwrap() {
        let name = scene["name"].as_str().unwrap();
        let volume = repo.join(scene["volume"].as_str().unwrap());
        let (png, depth) = (dir.path().join("v.png"), dir.path().join("d.npy"));
        let (eye, look_at, up) = (
            triple(&scene["eye"]),
            triple(&scene["look_at"]),
            triple(&scene["up"]),
        );
        let iso = scene["iso"].as_f64().unwrap().to_string();
        let mut args = vec![
            "render",
            volume.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--mode",
            "iso",
            "--iso",
            &iso,
            "--eye",
            &eye,
            "--look-at",
            &look_at,
            "--up",
            &up,
            "--size",
            "96x96",
            "--depth-out",
            depth.to_str().unwrap(),
            "--json",
        ];
        let orientation;
        if let Some(o) = scene["open_options"]["orientation"].as_str() {
            orientation = o.to_string();
            args.extend(["--orientation", &orientation]);
        }
        let out = endocast(&args);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stats: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let (hits, rays) = (
            stats["iso_hits"].as_f64().unwrap(),
            stats["rays"].as_f64().unwrap(),
        );
        assert!(
            hits >= 0.95 * rays,
            "{name}: only {hits} of {rays} rays hit the wall"
        );
        let (_, values) = read_npy(&depth);
        let mut depths: Vec<f32> = values.into_iter().filter(|d| d.is_finite()).collect();
        depths.sort_by(f32::total_cmp);
        let median = depths[depths.len() / 2];
        // From inside a trachea, aorta, nasal cavity or ventricle the wall is millimetres to a
        // few centimetres away, never at the eye and never across the body.
        assert!(
            (2.0..120.0).contains(&median),
            "{name}: median depth {median} mm"
        );
        assert!(
            depths[0] > 0.5,
            "{name}: the eye sits in the wall ({} mm)",
            depths[0]
        );
    }
}
