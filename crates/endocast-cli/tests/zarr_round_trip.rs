//! OME-Zarr end to end (issue 37, item 3): a NIfTI scan converted to OME-Zarr renders the
//! same image, byte for byte, as the NIfTI itself; a level of the pyramid opens by its folder.

use crate::common::{endocast, fails_with, info_json};
use endocast_testdata::shared_data;
use std::path::Path;

/// Runs `endocast` and panics with its error output when it fails.
fn run(args: &[&str]) {
    let out = endocast(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Converts `scan` to `DIR/scan.zarr`, renders both to PNG and asserts the same bytes and the
/// same geometry and values in `info`.
fn renders_the_same_as_zarr(scan: &Path, dir: &Path, render: &[&str]) {
    let zarr = dir.join("scan.zarr");
    let (scan, zarr) = (scan.to_str().unwrap(), zarr.to_str().unwrap());
    run(&["convert", scan, "-o", zarr]);
    let mut pngs = Vec::new();
    for (input, name) in [(scan, "scan.png"), (zarr, "zarr.png")] {
        let png = dir.join(name);
        let mut args = vec!["render", input, "-o", png.to_str().unwrap()];
        args.extend_from_slice(render);
        run(&args);
        pngs.push(std::fs::read(&png).unwrap());
    }
    assert!(pngs[0] == pngs[1], "the OME-Zarr renders differently");
    let (a, b) = (info_json(scan, &[]), info_json(zarr, &[]));
    for key in [
        "dimensions",
        "spacing_mm",
        "origin_mm",
        "direction_columns",
        "value_map",
        "modality",
    ] {
        assert_eq!(a[key], b[key], "{key}");
    }
}

#[test]
fn a_phantom_renders_the_same_from_nifti_and_ome_zarr() {
    let dir = tempfile::tempdir().unwrap();
    let nii = dir.path().join("shell.nii.gz");
    let nii_arg = nii.to_str().unwrap();
    run(&["phantom", "sphere-shell", "-o", nii_arg, "--size", "72"]);
    let view = [
        "--mode",
        "iso",
        "--eye",
        "0,0,0",
        "--look-at",
        "0,1,1",
        "--size",
        "48x32",
    ];
    renders_the_same_as_zarr(&nii, dir.path(), &view);
    // 72 voxels is more than a 64³ chunk: a second level, half as fine, opens by its folder.
    let level = dir.path().join("scan.zarr/1");
    let report = info_json(level.to_str().unwrap(), &[]);
    assert_eq!(report["dimensions"], serde_json::json!([36, 36, 36]));
    assert_eq!(report["spacing_mm"], serde_json::json!([2.0, 2.0, 2.0]));
    assert!(!dir.path().join("scan.zarr/2").exists());
}

#[test]
fn a_shared_ct_renders_the_same_from_nifti_and_ome_zarr() {
    let Some(engine) = shared_data("classic-engine-ct/engine.nii.gz") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    renders_the_same_as_zarr(&engine, dir.path(), &["--size", "64x48"]);
}

#[test]
fn convert_refuses_to_replace_a_folder_that_is_not_a_zarr_store() {
    let dir = tempfile::tempdir().unwrap();
    let nii = dir.path().join("p.nii");
    run(&[
        "phantom",
        "sphere-shell",
        "-o",
        nii.to_str().unwrap(),
        "--size",
        "8",
    ]);
    let folder = dir.path().join("mine.zarr");
    std::fs::create_dir(&folder).unwrap();
    std::fs::write(folder.join("notes.txt"), b"keep me").unwrap();
    let args = [
        "convert",
        nii.to_str().unwrap(),
        "-o",
        folder.to_str().unwrap(),
    ];
    fails_with(&args, "not a Zarr store");
    assert_eq!(std::fs::read(folder.join("notes.txt")).unwrap(), b"keep me");
    // A store endocast wrote is replaced, as files are.
    let store = dir.path().join("p.zarr");
    let args = [
        "convert",
        nii.to_str().unwrap(),
        "-o",
        store.to_str().unwrap(),
    ];
    run(&args);
    run(&args);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
}
