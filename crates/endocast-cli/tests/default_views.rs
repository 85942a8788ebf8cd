//! Issue 17: `render SCAN -o x.png` with no options shows the object on every shared scan and
//! every phantom (the wall on the scan's own background/object boundary), and a path that would
//! run away is refused at once with a message that says why.

use crate::common::{endocast, hit_share};
use endocast_testdata::shared_data;
use std::path::Path;

/// Shared scans that hold a volume (not dicom-transfer-syntaxes, whose files are the same small
/// 64 × 64 × 35 EPI mosaic in nine encodings, for the decoders).
const SCANS: [&str; 10] = [
    "abdomen-ct-pancreas-dicom",
    "aorta-stent-cta/stent.nrrd",
    "brain-mri-flair-nrrd/FLAIR.nrrd",
    "brain-mri-t1/chris_t1.nii.gz",
    "chest-ct-airways-dicom",
    "classic-engine-ct/engine.nii.gz",
    "classic-vtk-headsq/quarter.nhdr",
    "head-ct-ge-gantry-tilt/GE",
    "head-ct-stanford-cthead/CThead.nhdr",
    "knee-mri/knee3D_dataR.mha",
];

/// Renders `volume` with no options but a small size; returns the fraction of pixels whose ray
/// met the wall, and stderr.
fn hit_fraction(volume: &Path, dir: &Path) -> (f64, String) {
    let (png, depth) = (dir.join("v.png"), dir.join("d.npy"));
    let out = endocast(&[
        "render",
        volume.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--size",
        "64x64",
        "--depth-out",
        depth.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{}: {stderr}", volume.display());
    (hit_share(&depth), stderr)
}

/// The object fills part of the frame, not none of it and not all of it, and no warning says
/// the image is empty.
fn assert_object_shown(volume: &Path, dir: &Path) {
    let (fraction, stderr) = hit_fraction(volume, dir);
    assert!(
        (0.02..0.95).contains(&fraction),
        "{}: {fraction} of the rays hit; {stderr}",
        volume.display()
    );
    assert!(!stderr.contains("image is empty"), "{stderr}");
    assert!(stderr.contains("wall at"), "{stderr}");
}

#[test]
fn every_phantom_renders_its_object_with_no_options() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "sphere-shell",
        "straight-tube",
        "curved-tube",
        "colon",
        "vessel",
        "joint",
        "sinus",
    ] {
        let path = dir.path().join(format!("{name}.nii.gz"));
        let out = endocast(&[
            "phantom",
            name,
            "--size",
            "48",
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{name}");
        assert_object_shown(&path, dir.path());
    }
}

#[test]
fn every_shared_scan_renders_its_object_with_no_options() {
    let Some(data) = shared_data("") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for scan in SCANS {
        assert_object_shown(&data.join(scan), dir.path());
    }
}

#[test]
fn a_path_through_the_background_is_refused_before_the_search() {
    let Some(data) = shared_data("") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let t1 = data.join("brain-mri-t1/chris_t1.nii.gz");
    let out_path = dir.path().join("p.json");
    // A lateral ventricle at the preset's threshold (75 on this scan) joins the CSF around the
    // brain, the dark skull and the background, when grown from a start without the preset
    // (with it, the start lies in the ventricle the preset finds, which stays closed).
    let out = endocast(&[
        "path",
        t1.to_str().unwrap(),
        "--lumen-threshold",
        "75",
        "--from",
        "-15.44,31.88,17.04",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("leaks out") && stderr.contains("6 of the volume's 6 faces"),
        "{stderr}"
    );
    assert!(!out_path.exists());
    // With no start the preset finds the ventricle, at a threshold where it stays closed.
    let out = endocast(&[
        "path",
        t1.to_str().unwrap(),
        "--preset",
        "ventricles",
        "-o",
        out_path.to_str().unwrap(),
        "--json",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("ventricles: CSF < 75 (T1-like, dark)"),
        "{stderr}"
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let length = summary["length_mm"].as_f64().unwrap();
    // The lateral ventricle is some 40–100 mm long; a runaway path is hundreds.
    assert!((20.0..150.0).contains(&length), "{length} mm");
}
