//! `endocast render` end to end: a phantom with a known answer, outputs, and bad options.

use crate::common::{count_color, endocast, fails_with, read_npy};

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
    // The pose it used: the eye given, looking along +z, up orthogonal to the view.
    let camera = &stats["camera"];
    assert_eq!(camera["eye"], serde_json::json!([0.0, 0.0, 0.0]));
    assert_eq!(camera["look_direction"], serde_json::json!([0.0, 0.0, 1.0]));
    assert_eq!(camera["field"], 100.0);
    assert_eq!(camera["projection"], "pinhole");
    let up = crate::common::numbers(&camera["up"]);
    assert!(up[2].abs() < 1e-12 && ((up[0].powi(2) + up[1].powi(2)).sqrt() - 1.0).abs() < 1e-12);
    let ((h, w), values) = read_npy(&depth);
    assert_eq!((h, w), (32, 48));
    let worst = values.iter().map(|d| (d - 22.4).abs()).fold(0.0, f32::max);
    // End to end through NIfTI and the CLI; the renderer's own tests hold it to 0.05 voxel.
    assert!(worst < 0.1, "worst depth error {worst} mm");
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
}

/// Renders a 24×24 DVR view of a sphere shell from outside and returns the PNG's bytes.
fn dvr_view(dir: &std::path::Path, extra: &[&str]) -> Vec<u8> {
    let volume = dir.join("shell.nii");
    if !volume.exists() {
        let args = [
            "phantom",
            "sphere-shell",
            "-o",
            volume.to_str().unwrap(),
            "--size",
            "24",
        ];
        assert!(endocast(&args).status.success());
    }
    let png = dir.join("dvr.png");
    let mut args = vec![
        "render",
        volume.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ];
    args.extend_from_slice(&["--mode", "dvr", "--size", "24x24", "--tf", "ramp"]);
    args.extend_from_slice(extra);
    let out = endocast(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read(&png).unwrap()
}

#[test]
fn shade_dvr_changes_a_dvr_image() {
    let dir = tempfile::tempdir().unwrap();
    let flat = dvr_view(dir.path(), &[]);
    let shaded = dvr_view(dir.path(), &["--shade-dvr"]);
    assert_ne!(flat, shaded, "--shade-dvr made no difference");
}

/// Runs `endocast bench` with `args` (which ask for `--json`): its standard output, and each of
/// its lines as JSON.
fn bench_json(args: &[&str]) -> (String, Vec<serde_json::Value>) {
    let out = endocast(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines = stdout
        .lines()
        .map(|l| serde_json::from_str(l).expect("every stdout line is JSON"))
        .collect();
    (stdout, lines)
}

#[test]
fn bench_takes_size_and_prints_json_lines_on_stdout() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("b.jsonl");
    let args = [
        "bench",
        "--phantom-size",
        "32",
        "--frames",
        "2",
        "--size",
        "16x12",
        "--mode",
        "iso",
        "--json",
        "--json-file",
        file.to_str().unwrap(),
    ];
    let (stdout, lines) = bench_json(&args);
    assert!(!lines.is_empty());
    assert!(lines
        .iter()
        .all(|l| l["size"] == serde_json::json!([16, 12]) && l["frames"] == 2));
    assert_eq!(
        std::fs::read_to_string(&file).unwrap(),
        stdout,
        "the file holds the same lines"
    );
    // The old name of --size still works.
    let old = [
        "bench",
        "--phantom-size",
        "32",
        "--frames",
        "2",
        "--image",
        "16x12",
        "--mode",
        "iso",
    ];
    assert!(endocast(&old).status.success());
}

#[test]
fn bench_with_geometry_times_each_frame_without_it_too() {
    let args = [
        "bench",
        "--phantom-size",
        "32",
        "--frames",
        "3",
        "--size",
        "16x12",
        "--rows",
        "iso only",
        "--grid",
        "0,0,0:0,0,1:4",
        "--json",
    ];
    let (stdout, lines) = bench_json(&args);
    let [with, without] = &lines[..] else {
        panic!("one setting and its frames without the grid: {stdout}");
    };
    assert!(with["scene_over_without"].is_null());
    assert!(without["setting"]
        .as_str()
        .unwrap()
        .ends_with(", without geometry"));
    let ratios = without["scene_over_without"].as_array().unwrap();
    assert_eq!(ratios.len(), 3, "one ratio per frame");
    assert!(ratios.iter().all(|r| r.as_f64().unwrap() > 0.0));
}

#[test]
fn peels_of_the_joint_phantom_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let volume = dir.path().join("joint.nii.gz");
    let v = volume.to_str().unwrap();
    assert!(endocast(&["phantom", "joint", "-o", v, "--size", "64"])
        .status
        .success());
    // The eye on the axis 10 mm below the first joint space (its lower surface 1.25 mm below
    // the centre, the second joint space 12.8 mm higher), looking up across both.
    let depth = dir.path().join("depth.npy");
    let png = dir.path().join("peel.png");
    for (peel, expected) in [("1", 8.75), ("2", 21.55), ("last", 21.55)] {
        let out = endocast(&[
            "render",
            v,
            "-o",
            png.to_str().unwrap(),
            "--mode",
            "peel",
            "--peel",
            peel,
            "--peel-threshold",
            "650",
            "--peel-falling",
            "--eye",
            "0,0,-10",
            "--look-at",
            "0,0,1",
            "--up",
            "0,1,0",
            "--size",
            "3x3",
            "--fov",
            "10",
            "--depth-out",
            depth.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (_, values) = read_npy(&depth);
        assert!(
            (values[4] - expected).abs() < 0.1,
            "peel {peel}: {}",
            values[4]
        );
    }
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
        (vec!["--peel", "0"], "--peel"),
        (vec!["--peel-keep", "1.5"], "peel-keep"),
        (vec!["--unpeeled", "maybe"], "maybe"),
        (vec!["--tf-after", "/no/such/after.json"], "after.json"),
        (vec!["--peel-threshold", "inf"], "peel-threshold"),
    ] {
        let mut args = vec!["render", v, "-o", o];
        args.extend(extra.iter().copied());
        fails_with(&args, needle);
    }
}

/// A PNG's width and height.
fn png_size(path: &std::path::Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert!(
        bytes.starts_with(b"\x89PNG"),
        "{} is no PNG",
        path.display()
    );
    let be = |at: usize| u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap());
    (be(16), be(20))
}

#[test]
fn lenses_and_stereo_outputs_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let volume = dir.path().join("shell.nii.gz");
    let v = volume.to_str().unwrap();
    assert!(
        endocast(&["phantom", "sphere-shell", "-o", v, "--size", "48"])
            .status
            .success()
    );
    let render = |extra: &[&str], out: &str| {
        let png = dir.path().join(out);
        let mut args = vec!["render", v, "-o", png.to_str().unwrap(), "--mode", "iso"];
        args.extend_from_slice(&["--eye", "0,0,0", "--look-at", "0,0,1", "--size", "40x30"]);
        args.extend_from_slice(extra);
        let result = endocast(&args);
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(result.status.success(), "{extra:?}: {stderr}");
        png
    };
    // A 200° fisheye from the centre: a round image, rays at the radius everywhere in it.
    let depth = dir.path().join("fisheye.npy");
    let fisheye = [
        "--lens",
        "equidistant",
        "--fov",
        "200",
        "--distortion",
        "-0.1,0.02",
    ];
    let mut args = fisheye.to_vec();
    args.extend_from_slice(&[
        "--vignetting",
        "0.3",
        "--depth-out",
        depth.to_str().unwrap(),
    ]);
    render(&args, "fisheye.png");
    let (_, depths) = read_npy(&depth);
    let hits: Vec<f32> = depths.iter().copied().filter(|d| d.is_finite()).collect();
    assert!(
        hits.len() > 500 && hits.len() < depths.len(),
        "a round image"
    );
    assert!(hits.iter().all(|d| (d - 16.8).abs() < 0.1), "0.35 × 48 mm");
    render(&["--lens", "orthographic", "--fov", "30"], "ortho.png");
    // Stereo: combined images, the doubled layouts, and a pair of files.
    for (output, size) in [
        ("anaglyph", (40, 30)),
        ("dubois", (40, 30)),
        ("side-by-side", (80, 30)),
    ] {
        let png = render(
            &["--stereo", output, "--focus", "10"],
            &format!("{output}.png"),
        );
        assert_eq!(png_size(&png), size, "{output}");
    }
    let top_bottom = render(&["--stereo", "top-bottom"], "tb.png");
    assert_eq!(png_size(&top_bottom), (40, 60));
    render(&["--stereo", "pair", "--eye-separation", "0.5"], "eyes.png");
    for eye in ["eyes-left.png", "eyes-right.png"] {
        assert_eq!(png_size(&dir.path().join(eye)), (40, 30), "{eye}");
    }
    let png = dir.path().join("x.png");
    let base = ["render", v, "-o", png.to_str().unwrap()];
    let with = |extra: &[&'static str]| -> Vec<&str> { [&base[..], extra].concat() };
    fails_with(&with(&["--lens", "fisheye"]), "unknown lens");
    fails_with(
        &with(&["--lens", "equidistant", "--fov", "400"]),
        "invalid camera",
    );
    fails_with(&with(&["--distortion", "nan,0"]), "not a finite number");
    fails_with(&with(&["--vignetting", "2"]), "vignetting");
    fails_with(&with(&["--stereo", "anaglyph", "--focus", "-3"]), "focus");
    fails_with(&with(&["--stereo", "wobble"]), "unknown stereo output");
    fails_with(
        &with(&["--stereo", "anaglyph", "--lens", "orthographic"]),
        "orthographic",
    );
}

#[test]
fn the_unfolded_cube_and_the_panorama_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let volume = dir.path().join("shell.nii.gz");
    let v = volume.to_str().unwrap();
    let made = endocast(&["phantom", "sphere-shell", "-o", v, "--size", "48"]);
    assert!(made.status.success());
    let png = dir.path().join("view.png");
    let depth = dir.path().join("depth.npy");
    let base = ["render", v, "-o", png.to_str().unwrap(), "--mode", "iso"];
    let at_centre = ["--eye", "0,0,0", "--look-at", "0,0,1"];
    let render = |extra: &[&str]| {
        let mut args = [&base[..], &at_centre[..], extra].concat();
        args.extend_from_slice(&["--depth-out", depth.to_str().unwrap()]);
        let result = endocast(&args);
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(result.status.success(), "{extra:?}: {stderr}");
        read_npy(&depth)
    };
    // The cube from the shell's centre: six faces of 16 pixels in the cross, each ray meeting
    // the shell at its radius (0.35 × 48 mm); the six empty cells without a ray.
    let ((h, w), depths) = render(&["--lens", "cube", "--size", "64x48"]);
    assert_eq!((w, h), (64, 48));
    assert_eq!(png_size(&png), (64, 48));
    let hit = |x: usize, y: usize| depths[x + w * y].is_finite();
    assert_eq!(depths.iter().filter(|d| d.is_finite()).count(), 6 * 16 * 16);
    assert!(depths
        .iter()
        .filter(|d| d.is_finite())
        .all(|d| (d - 16.8).abs() < 0.1));
    let faces = [(24, 8), (8, 24), (24, 24), (40, 24), (56, 24), (24, 40)];
    assert!(faces.iter().all(|&(x, y)| hit(x, y)), "a face without hits");
    let empty = [(8, 8), (40, 8), (56, 8), (8, 40), (40, 40), (56, 40)];
    assert!(
        empty.iter().all(|&(x, y)| !hit(x, y)),
        "an empty cell with hits"
    );
    assert!(count_color(&png, [255, 220, 0]) > 50, "the faces' labels");
    // The panorama: every pixel sees the shell.
    let ((h, w), depths) = render(&["--lens", "panorama", "--size", "64x32"]);
    assert_eq!(((w, h), png_size(&png)), ((64, 32), (64, 32)));
    assert!(depths.iter().all(|d| (d - 16.8).abs() < 0.1));
    let with = |extra: &[&'static str]| -> Vec<&str> { [&base[..], extra].concat() };
    fails_with(&with(&["--lens", "cube", "--fov", "100"]), "invalid camera");
    fails_with(
        &with(&["--lens", "panorama", "--fov", "200"]),
        "invalid camera",
    );
    fails_with(
        &with(&["--lens", "cube", "--stereo", "anaglyph"]),
        "no stereo eyes",
    );
    fails_with(
        &with(&["--lens", "panorama", "--vignetting", "0.3"]),
        "no lens distortion",
    );
}
