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

/// A closed octahedron of half-diagonal 1 mm around `(0, 0, z)` (world mm), as OBJ text.
fn octahedron_obj(z: f64) -> String {
    let corners = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let mut obj: String = corners
        .iter()
        .map(|[x, y, dz]| format!("v {x} {y} {}\n", z + dz))
        .collect();
    for (a, b) in [(1, 3), (3, 2), (2, 4), (4, 1)] {
        obj += &format!("f {a} {b} 5\nf {b} {a} 6\n");
    }
    obj
}

#[test]
fn geometry_is_drawn_in_the_realistic_look_in_front_and_behind_the_tissue() {
    let dir = tempfile::tempdir().unwrap();
    let volume = layered(dir.path());
    let png = dir.path().join("view.png");
    let (depth, mesh) = (dir.path().join("depth.npy"), dir.path().join("tip.obj"));
    // In the air 5.5 mm ahead of the eye, its corner toward it: 4.5 mm before the secretion.
    std::fs::write(&mesh, octahedron_obj(-11.0)).unwrap();
    let [depth_arg, mesh_arg] = [&depth, &mesh].map(|p| p.to_str().unwrap());
    let look = ["--look", "realistic", "--depth-out", depth_arg];
    let without = render(&volume, &png, &look);
    let tissue = read_npy(&depth).1[16 * 32 + 16];
    let with = render(&volume, &png, &[&look[..], &["--mesh", mesh_arg]].concat());
    assert_ne!(with, without);
    let nearest = read_npy(&depth).1[16 * 32 + 16];
    // Its corner 5.5 mm away, the centre pixel's ray passing half a pixel beside it.
    assert!((5.5..6.0).contains(&nearest), "the mesh at {nearest} mm");
    // A marker inside the tissue shows through its stipple; the depth stays the tissue's.
    let marker = ["--marker", "0,0,8:4"];
    let behind = render(&volume, &png, &[&look[..], &marker].concat());
    assert_ne!(behind, without);
    assert_eq!(read_npy(&depth).1[16 * 32 + 16], tissue);
    // A stereo pair is not drawn in a look yet.
    let stereo = ["--look", "realistic", "--stereo", "anaglyph"];
    let mut args = vec!["render", volume.to_str().unwrap(), "-o", "/tmp/never.png"];
    args.extend_from_slice(&stereo);
    fails_with(&args, "no stereo pair yet");
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

#[test]
fn the_realistic_look_sees_through_an_endoscope_unless_told_and_lights_by_a_lit_sphere() {
    let dir = tempfile::tempdir().unwrap();
    let volume = layered(dir.path());
    let png = dir.path().join("view.png");
    let view = |extra: &[&str]| render(&volume, &png, extra);
    let realistic = view(&["--look", "realistic"]);
    let endoscope = ["--distortion", "-0.166,0.0246", "--vignetting", "0.6"];
    assert_eq!(
        view(&[&["--look", "realistic"][..], &endoscope].concat()),
        realistic
    );
    let ideal = ["--distortion", "0,0", "--vignetting", "0"];
    assert_ne!(
        view(&[&["--look", "realistic"][..], &ideal].concat()),
        realistic
    );
    // The plain look's lens is the ideal one.
    assert_eq!(view(&[]), view(&ideal));
    let ibl = view(&["--look", "realistic", "--lighting", "ibl"]);
    assert_ne!(ibl, realistic);
    assert_eq!(
        view(&["--look", "realistic", "--lighting", "phong"]),
        realistic
    );
    let sphere = dir.path().join("sphere.png");
    std::fs::write(&sphere, &ibl).unwrap();
    let user = format!("ibl:{}", sphere.display());
    assert_ne!(view(&["--look", "realistic", "--lighting", &user]), ibl);
    let v = volume.to_str().unwrap();
    let base = ["render", v, "-o", "/tmp/never.png", "--size", "16x16"];
    for (extra, needle) in [
        (
            &["--look", "realistic", "--lighting", "matcap"][..],
            "phong, ibl or ibl:FILE.png",
        ),
        (
            &["--look", "realistic", "--lighting", "ibl:gone.png"],
            "gone.png",
        ),
        (
            &["--lighting", "ibl"],
            "--lighting only applies to the clinical or realistic look",
        ),
        (
            &["--look", "realistic", "--distortion", "nan,0"],
            "not a finite number",
        ),
        (
            &["--look", "realistic", "--distortion", "-3,0"],
            "--distortion must be two finite",
        ),
    ] {
        fails_with(&[&base[..], extra].concat(), needle);
    }
}
