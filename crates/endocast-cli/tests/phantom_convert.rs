//! `phantom` and `convert` write files that `info` reads back with the same geometry.

use crate::common::{endocast, info_json, numbers};

#[test]
fn phantom_then_convert_keeps_geometry_and_values() {
    let dir = tempfile::tempdir().unwrap();
    let nii = dir.path().join("p.nii.gz");
    let out = endocast(&[
        "phantom",
        "sphere-shell",
        "-o",
        nii.to_str().unwrap(),
        "--size",
        "24",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let original = info_json(nii.to_str().unwrap(), &[]);
    // The limits in force are part of the report, `--max-voxels` among them.
    let limited = info_json(nii.to_str().unwrap(), &["--max-voxels", "100000"]);
    let limits = &limited["limits"];
    assert_eq!(limits["max_voxels"], 100_000);
    for key in [
        "max_slices",
        "max_frame_bytes",
        "max_image_pixels",
        "max_frames",
        "max_threads",
        "max_texture_edge",
    ] {
        assert!(
            limits[key].as_u64().is_some_and(|n| n > 0),
            "{key}: {limits}"
        );
    }
    assert!(limits.get("memory_counted_bytes").is_some(), "{limits}");
    for ext in ["nrrd", "mha", "nii"] {
        let converted = dir.path().join(format!("p.{ext}"));
        let out = endocast(&[
            "convert",
            nii.to_str().unwrap(),
            "-o",
            converted.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let report = info_json(converted.to_str().unwrap(), &[]);
        for key in ["dimensions", "value_range"] {
            assert_eq!(report[key], original[key], "{ext}: {key}");
        }
        for key in ["spacing_mm", "origin_mm"] {
            let (a, b) = (numbers(&report[key]), numbers(&original[key]));
            assert!(
                a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-5),
                "{ext}: {key}"
            );
        }
    }
}
