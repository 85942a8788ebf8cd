//! `--look`, `--secretion`, `--wetness`, `--texture`, `--attenuation` end to end (issue 20), on
//! the layered phantom (air | secretion | tissue).

use crate::common::{endocast, fails_with, read_npy, read_png_rgb};
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
    // B-spline stills are asked for by name; trilinear is the default.
    let args = ["--look", "realistic", "--still", "2"];
    let trilinear = render(
        &volume,
        &png,
        &[&args[..], &["--still-filter", "trilinear"]].concat(),
    );
    assert_eq!(trilinear, render(&volume, &png, &args));
    let spline = render(
        &volume,
        &png,
        &[&args[..], &["--still-filter", "bspline"]].concat(),
    );
    assert_ne!(spline, trilinear);
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
}

/// The left and right halves of a side-by-side image (RGB rows `width` wide).
fn halves(rgb: &[u8], width: usize) -> [Vec<u8>; 2] {
    let (mut left, mut right) = (Vec::new(), Vec::new());
    for row in rgb.chunks(3 * width) {
        let (l, r) = row.split_at(3 * width / 2);
        left.extend_from_slice(l);
        right.extend_from_slice(r);
    }
    [left, right]
}

/// The mean column of the pixels where `a` and `b` (RGB rows `width` wide) differ, and how
/// many there are.
fn mean_column_of_difference(a: &[u8], b: &[u8], width: usize) -> (f64, usize) {
    let columns: Vec<usize> = a
        .chunks(3)
        .zip(b.chunks(3))
        .enumerate()
        .filter(|(_, (p, q))| p != q)
        .map(|(i, _)| i % width)
        .collect();
    let n = columns.len();
    (columns.iter().sum::<usize>() as f64 / n.max(1) as f64, n)
}

#[test]
fn a_realistic_stereo_pair_draws_the_mesh_in_each_eye_with_its_parallax() {
    let dir = tempfile::tempdir().unwrap();
    let volume = layered(dir.path());
    let png = dir.path().join("pair.png");
    let mesh = dir.path().join("tip.obj");
    // Its centre 6.5 mm ahead of the eye, nearer than the focus on the secretion (10 mm).
    std::fs::write(&mesh, octahedron_obj(-11.0)).unwrap();
    let stereo = [
        "--look",
        "realistic",
        "--stereo",
        "side-by-side",
        "--eye-separation",
        "2",
        "--focus",
        "10",
        "--fov",
        "60",
    ];
    render(&volume, &png, &stereo);
    let ([width, height], without) = read_png_rgb(&png);
    let mesh_arg = ["--mesh", mesh.to_str().unwrap()];
    render(&volume, &png, &[&stereo[..], &mesh_arg].concat());
    let (size, with) = read_png_rgb(&png);
    assert_eq!([width, height], [64, 32]);
    assert_eq!(size, [64, 32]);
    let [left, right] = halves(&with, width);
    let [left_plain, right_plain] = halves(&without, width);
    assert_ne!(left, right);
    // The mesh in each eye: where the image differs from the same eye's without it. A point
    // z mm ahead shifts K·(1/z − 1/focus) pixels between the eyes, K = e / tan(fov/2) · h/2
    // (55.4 pixel·mm): 3.0 pixels at the centre's 6.5 mm, to the right in the left eye.
    let (left_x, left_n) = mean_column_of_difference(&left, &left_plain, 32);
    let (right_x, right_n) = mean_column_of_difference(&right, &right_plain, 32);
    assert!(left_n > 20 && right_n > 20, "{left_n} and {right_n} pixels");
    let parallax = left_x - right_x;
    assert!((2.2..3.8).contains(&parallax), "parallax {parallax} pixels");
}

#[test]
fn a_flight_in_the_realistic_look_films_stereo_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let volume = layered(dir.path());
    let route = dir.path().join("route.json");
    std::fs::write(
        &route,
        r#"{"format": "endocast-path", "version": 1, "coordinate_system": "LPS", "units": "mm", "points": [[0, 0, -17], [0, 0, -13]]}"#,
    )
    .unwrap();
    let fly = |look: &str| {
        let frames = dir.path().join(look);
        let out = endocast(&[
            "fly",
            volume.to_str().unwrap(),
            "--path",
            route.to_str().unwrap(),
            "-o",
            frames.to_str().unwrap(),
            "--preset",
            "sinus",
            "--look",
            look,
            "--stereo",
            "side-by-side",
            "--size",
            "24x24",
            "--frame-step",
            "4",
            "--threads",
            "2",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let mut pngs: Vec<_> = std::fs::read_dir(&frames)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        pngs.sort();
        pngs.iter().map(|p| read_png_rgb(p)).collect::<Vec<_>>()
    };
    let (realistic, plain) = (fly("realistic"), fly("plain"));
    assert!(realistic.len() >= 2);
    for ((size, rgb), (_, plain)) in realistic.iter().zip(&plain) {
        assert_eq!(*size, [48, 24]);
        let [left, right] = halves(rgb, 48);
        assert_ne!(left, right);
        assert_ne!(rgb, plain);
    }
}

#[test]
fn bad_look_values_are_refused_with_a_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    let volume = layered(dir.path());
    let volume = volume.to_str().unwrap();
    let png = dir.path().join("bad.png");
    let png = png.to_str().unwrap();
    let base = ["render", volume, "-o", png, "--size", "16x16"];
    let cases: [(&[&str], &str); 11] = [
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
        (
            &["--still", "2", "--still-filter", "cubic"],
            "unknown filter",
        ),
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

/// Writes `pixels` (RGB, `width` wide) as a PNG at `path`.
fn write_rgb_png(path: &Path, width: u32, pixels: &[u8]) {
    let height = pixels.len() as u32 / (3 * width);
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(pixels).unwrap();
}

/// How far red over green varies over the image's lit, unsaturated pixels (`max / min − 1`).
fn hue_spread(png_bytes: &[u8]) -> f64 {
    let mut reader = png::Decoder::new(std::io::Cursor::new(png_bytes))
        .read_info()
        .unwrap();
    let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buffer).unwrap();
    let channels = info.color_type.samples();
    let hues: Vec<f64> = buffer[..info.buffer_size()]
        .chunks_exact(channels)
        .filter(|px| px[..3].iter().all(|&c| (20..250).contains(&c)))
        .map(|px| f64::from(px[0]) / f64::from(px[1]))
        .collect();
    assert!(hues.len() > 100, "{} pixels", hues.len());
    let (lo, hi) = hues
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
    hi / lo - 1.0
}

#[test]
fn a_colour_texture_changes_the_hue_a_specular_map_is_read_and_bad_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let volume = layered(dir.path());
    let png = dir.path().join("look.png");
    // A 2 × 2 checker of reddish and greenish texels, and its grey twin.
    let colour = dir.path().join("colour.png");
    write_rgb_png(
        &colour,
        2,
        &[200, 60, 60, 60, 200, 60, 60, 200, 60, 200, 60, 60],
    );
    let grey = dir.path().join("grey.png");
    write_rgb_png(
        &grey,
        2,
        &[100, 100, 100, 160, 160, 160, 160, 160, 160, 100, 100, 100],
    );
    let look = |texture: &Path, extra: &[&str]| {
        // The ideal lens: the endoscope's vignetting darkens the edge into 8-bit noise of hue.
        let mut args = vec![
            "--look",
            "realistic",
            "--distortion",
            "0,0",
            "--vignetting",
            "0",
            "--secretion",
            "off",
            "--wetness",
            "0",
            // Texels larger than a pixel's footprint: the mip map keeps their colours apart.
            "--texture-scale",
            "40",
            "--texture",
            texture.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        render(&volume, &png, &args)
    };
    let (coloured, greyed) = (look(&colour, &[]), look(&grey, &[]));
    let (c, g) = (hue_spread(&coloured), hue_spread(&greyed));
    assert!(
        c > 0.3 && g < 0.1,
        "hue varies by {c} (colour) and {g} (grey)"
    );
    // A specular map changes the wet look.
    let wet = |extra: &[&str]| {
        let mut args = vec!["--look", "realistic", "--wetness", "1"];
        args.extend_from_slice(extra);
        render(&volume, &png, &args)
    };
    assert_ne!(wet(&[]), wet(&["--specular-map", grey.to_str().unwrap()]));
    // Bad files: named, with the problem.
    let broken = dir.path().join("broken.png");
    std::fs::write(&broken, b"no png here").unwrap();
    let base = [
        "render",
        volume.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--look",
        "realistic",
    ];
    let missing = dir.path().join("missing.png");
    for (flag, file, problem) in [
        ("--texture", &missing, "missing.png"),
        ("--texture", &broken, "not a readable PNG"),
        ("--specular-map", &broken, "broken.png"),
        ("--specular-map", &missing, "specular map"),
    ] {
        let mut args = base.to_vec();
        args.extend_from_slice(&[flag, file.to_str().unwrap()]);
        fails_with(&args, problem);
    }
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
