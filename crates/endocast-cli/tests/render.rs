//! `endocast render` end to end: a phantom with a known answer, outputs, and bad options.

use crate::common::{endocast, fails_with, read_npy};

#[test]
fn from_the_centre_of_a_sphere_shell_every_depth_is_the_radius() {
    let dir = tempfile::tempdir().unwrap();
    let volume = dir.path().join("shell.nii.gz");
    let out = endocast(&[
        "phantom",
        "sphere-shell",
        "-o",
        volume.to_str().unwrap(),
        "--size",
        "64",
    ]);
    assert!(out.status.success());
    // 64 voxels of 1 mm centred on the world origin: the centre is (0,0,0), the inner radius
    // 0.35 × 64 = 22.4 mm, where the phantom's ramp crosses the air/tissue mid-value −480 HU.
    let png = dir.path().join("view.png");
    let depth = dir.path().join("depth.npy");
    let out = endocast(&[
        "render",
        volume.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--mode",
        "iso",
        "--eye",
        "0,0,0",
        "--look-at",
        "0,0,1",
        "--size",
        "48x32",
        "--fov",
        "100",
        "--depth-out",
        depth.to_str().unwrap(),
        "--json",
        "--threads",
        "2",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stats: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(stats["rays"], 48 * 32);
    assert_eq!(stats["iso_hits"], 48 * 32);
    let ((h, w), values) = read_npy(&depth);
    assert_eq!((h, w), (32, 48));
    let worst = values.iter().map(|d| (d - 22.4).abs()).fold(0.0, f32::max);
    // End to end through NIfTI and the CLI; the renderer's own tests hold it to 0.05 voxel.
    assert!(worst < 0.1, "worst depth error {worst} mm");
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
}

#[test]
fn bad_render_options_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let volume = dir.path().join("v.nii");
    assert!(endocast(&[
        "phantom",
        "sphere-shell",
        "-o",
        volume.to_str().unwrap(),
        "--size",
        "16"
    ])
    .status
    .success());
    let v = volume.to_str().unwrap();
    let png = dir.path().join("o.png");
    let o = png.to_str().unwrap();
    for (extra, needle) in [
        (vec!["--eye", "0,0,NaN", "--look-at", "0,0,1"], "finite"),
        (vec!["--eye", "0,0,0"], "--look-at"),
        (vec!["--eye", "0,0,0", "--look-at", "0,0,0"], "camera"),
        (vec!["--fov", "200"], "camera"),
        (vec!["--mode", "xray"], "xray"),
        (vec!["--preset", "gastroscopy"], "gastroscopy"),
        (vec!["--tf", "/no/such/tf.json"], "tf.json"),
        (vec!["--iso-opacity", "1.5"], "iso-opacity"),
        (vec!["--size", "0x10"], "size"),
        (vec!["--threads", "0"], "threads"),
    ] {
        let mut args = vec!["render", v, "-o", o];
        args.extend(extra.iter().copied());
        fails_with(&args, needle);
    }
}
