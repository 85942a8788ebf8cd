//! `endocast dissect`: the colon phantom laid flat with no options beyond the preset, its map
//! the size of its image, and bad input refused by name.

use crate::common::{endocast, fails_with, read_npy, read_png_rgb};

#[test]
fn the_colon_phantom_laid_flat_has_a_map_of_its_image_and_states_its_scale() {
    let dir = tempfile::tempdir().unwrap();
    let scan = dir.path().join("colon.nii.gz");
    let scan = scan.to_str().unwrap();
    assert!(endocast(&["phantom", "colon", "-o", scan, "--size", "64"])
        .status
        .success());
    let png = dir.path().join("flat.png");
    let out = endocast(&[
        "dissect",
        scan,
        "--preset",
        "colonoscopy",
        "-o",
        png.to_str().unwrap(),
        "--json",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["along_mm_per_px"], 0.5);
    assert_eq!(report["around_deg_per_px"], 1.0);
    assert!(report["wall_fraction"].as_f64().unwrap() > 0.5, "{report}");
    let ([width, height], _) = read_png_rgb(&png);
    let ((rows, columns), map) = read_npy(&dir.path().join("flat.map.npy"));
    assert_eq!((columns, rows), (width, height));
    assert_eq!(map.len(), width * height * 3);
    assert!(
        map[..3].iter().all(|v| v.is_nan()),
        "the corner is a margin"
    );
    assert!(map.iter().any(|v| v.is_finite()));
}

#[test]
fn dissect_refuses_bad_input_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let scan = dir.path().join("tube.nii.gz");
    let scan = scan.to_str().unwrap();
    assert!(
        endocast(&["phantom", "straight-tube", "-o", scan, "--size", "24"])
            .status
            .success()
    );
    let png = dir.path().join("flat.png");
    let png = png.to_str().unwrap();
    fails_with(
        &["dissect", scan, "--path", "/no/such/path.json", "-o", png],
        "/no/such/path.json",
    );
    fails_with(
        &[
            "dissect",
            scan,
            "--along-step",
            "NaN",
            "--preset",
            "colonoscopy",
            "-o",
            png,
        ],
        "step",
    );
    fails_with(&["dissect", scan, "-o", png], "--preset");
    fails_with(
        &[
            "dissect",
            scan,
            "--preset",
            "colonoscopy",
            "-o",
            "/tmp/x.jpg",
        ],
        ".png",
    );
}
