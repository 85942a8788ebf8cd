//! `--look`, `--secretion`, `--wetness`, `--texture`, `--attenuation` end to end (issue 20), on
//! the layered phantom (air | secretion | tissue).

use crate::common::{endocast, fails_with, read_npy};
use std::path::{Path, PathBuf};

/// The layered phantom at 40 voxels in `dir`.
fn layered(dir: &Path) -> PathBuf {
    let volume = dir.join("layered.nii.gz");
    let out = endocast(&[
        "phantom",
        "layered",
        "-o",
        volume.to_str().unwrap(),
        "--size",
        "40",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    volume
}

/// `endocast render` of `volume` from above the layers with `extra` options; the image's bytes.
fn render(volume: &Path, png: &Path, extra: &[&str]) -> Vec<u8> {
    let mut args = vec![
        "render",
        volume.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--preset",
        "sinus",
        "--eye",
        "0,0,-17.5",
        "--look-at",
        "0,0,0",
        "--size",
        "32x32",
        "--threads",
        "2",
    ];
    args.extend_from_slice(extra);
    let out = endocast(&args);
    assert!(
        out.status.success(),
        "{extra:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read(png).unwrap()
}

#[test]
fn looks_secretion_wetness_texture_and_attenuation_change_the_image() {
    let dir = tempfile::tempdir().unwrap();
    let volume = layered(dir.path());
    let png = dir.path().join("view.png");
    let plain = render(&volume, &png, &[]);
    let depth = dir.path().join("depth.npy");
    let depth_arg = depth.to_str().unwrap();
    let realistic = render(
        &volume,
        &png,
        &["--look", "realistic", "--depth-out", depth_arg],
    );
    assert_ne!(plain, realistic);
    // The tissue lies behind the secretion: 17.5 − 7.5 = 10 mm to the layer on the axis, and
    // at least 3 mm more to the tissue.
    let ((h, w), depths) = read_npy(&depth);
    assert_eq!((h, w), (32, 32));
    let centre = depths[16 * 32 + 16];
    assert!((13.0..20.0).contains(&centre), "tissue at {centre} mm");
    let variants: Vec<Vec<u8>> = [
        &["--look", "realistic", "--secretion", "off"][..],
        &["--look", "realistic", "--wetness", "0"],
        &[
            "--look",
            "realistic",
            "--texture",
            "grid",
            "--texture-scale",
            "4",
        ],
        &["--look", "realistic", "--attenuation", "5"],
        &["--look", "clinical"],
    ]
    .iter()
    .map(|extra| render(&volume, &png, extra))
    .collect();
    for (n, v) in variants.iter().enumerate() {
        assert_ne!(*v, realistic, "variant {n} changed nothing");
    }
    // Accumulated along the ray, the continuous layer measures as with constant density.
    render(
        &volume,
        &png,
        &["--look", "realistic", "--secretion", "accumulate"],
    );
    // A PNG as texture: the plain image itself.
    let texture = dir.path().join("texture.png");
    std::fs::write(&texture, &plain).unwrap();
    let textured = render(
        &volume,
        &png,
        &[
            "--look",
            "realistic",
            "--texture",
            texture.to_str().unwrap(),
        ],
    );
    assert_ne!(textured, realistic);
    // A converged still differs from the single frame.
    let still = render(&volume, &png, &["--look", "realistic", "--still", "4"]);
    assert_ne!(still, realistic);
}

#[test]
fn bad_look_values_are_refused_with_a_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    let volume = layered(dir.path());
    let volume = volume.to_str().unwrap();
    let png = dir.path().join("bad.png");
    let png = png.to_str().unwrap();
    let base = ["render", volume, "-o", png, "--size", "16x16"];
    let cases: [(&[&str], &str); 10] = [
        (&["--look", "photo"], "--look \"photo\" is unknown"),
        (
            &["--look", "realistic", "--secretion", "some"],
            "unknown secretion mode",
        ),
        (&["--look", "realistic", "--wetness", "NaN"], "--wetness"),
        (&["--look", "realistic", "--wetness", "1.5"], "--wetness"),
        (
            &["--look", "realistic", "--attenuation", "-3"],
            "--attenuation",
        ),
        (
            &["--look", "realistic", "--texture", "marble"],
            "unknown texture",
        ),
        (
            &["--look", "realistic", "--texture", "missing.png"],
            "missing.png",
        ),
        (
            &["--look", "realistic", "--texture-scale", "0"],
            "--texture-scale",
        ),
        (
            &["--secretion", "on"],
            "--secretion only applies to the clinical or realistic look",
        ),
        (&["--look", "realistic", "--still", "0"], "--still"),
    ];
    for (extra, needle) in cases {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        fails_with(&args, needle);
    }
    assert!(!Path::new(png).exists());
}

#[test]
fn bench_times_the_realistic_look_against_plain_iso() {
    let out = endocast(&[
        "bench",
        "--phantom-size",
        "48",
        "--frames",
        "2",
        "--size",
        "32x32",
        "--look",
        "realistic",
        "--threads",
        "2",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("| iso only |"), "{table}");
    assert!(table.contains("| realistic look |"), "{table}");
    assert!(table.contains("deferred stage alone"), "{table}");
}
