//! `endocast mesh` and the geometry options end to end: the sphere phantom's lumen as a closed
//! mesh, loaded back with `--mesh` where the wall is, and bad geometry options refused.

use crate::common::{endocast, fails_with, read_npy};

#[test]
fn the_lumen_mesh_loads_back_where_the_wall_is() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let volume = path("shell.nii.gz");
    let out = endocast(&["phantom", "sphere-shell", "-o", &volume, "--size", "48"]);
    assert!(out.status.success());
    let mesh = path("wall.ply");
    let out = endocast(&[
        "mesh", &volume, "--iso", "-480", "--from", "0,0,0", "-o", &mesh,
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("watertight"), "{stdout}");
    let view = ["--eye", "0,0,0", "--look-at", "0,0,1", "--size", "32x32"];
    let render = |extra: &[&str], depth: &str| {
        let png = path("view.png");
        let mut args = vec!["render", volume.as_str(), "-o", &png, "--depth-out", depth];
        args.extend_from_slice(&view);
        args.extend_from_slice(extra);
        let out = endocast(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        read_npy(std::path::Path::new(depth)).1
    };
    let wall = render(&["--mode", "iso"], &path("iso.npy"));
    // The volume made invisible (opaque only above every value): only the mesh has a depth.
    let tf = path("invisible.json");
    std::fs::write(
        &tf,
        r#"{"opacity": [[5000, 0], [6000, 1]], "color": [[0, 1, 1, 1]]}"#,
    )
    .unwrap();
    let spec = format!("{mesh}:orange:1");
    let drawn = render(
        &["--mode", "dvr", "--tf", &tf, "--mesh", &spec],
        &path("mesh.npy"),
    );
    for (a, b) in wall.iter().zip(&drawn) {
        assert!((a - b).abs() < 0.2, "iso {a} mesh {b}");
    }
}

#[test]
fn bad_geometry_options_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let volume = dir.path().join("shell.nii.gz");
    let volume = volume.to_str().unwrap();
    assert!(
        endocast(&["phantom", "sphere-shell", "-o", volume, "--size", "24"])
            .status
            .success()
    );
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap();
    let render = |extra: &[&str], needle: &str| {
        let mut args = vec!["render", volume, "-o", "/tmp/never.png", "--size", "8x8"];
        args.extend_from_slice(extra);
        fails_with(&args, needle);
    };
    render(&["--mesh", bad.to_str().unwrap()], "bad.obj");
    render(&["--grid", "0,0,0:0,0,0:5"], "grid");
    render(&["--marker", "0,0,nan"], "nan");
    render(&["--endoscope", "0"], "endoscope");
    fails_with(&["mesh", volume, "--iso", "-480", "-o", "x.vtk"], "x.vtk");
}

#[test]
fn a_segmentation_overlay_is_drawn_where_its_voxels_are() {
    use endocast_testdata::overlays::{write_segmentation, Grid, SegFrame};
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let volume = path("shell.nii.gz");
    assert!(
        endocast(&["phantom", "sphere-shell", "-o", &volume, "--size", "48"])
            .status
            .success()
    );
    // A 9 × 9 × 5 mm block of one segment in the air ahead of the eye, z 5–9 mm.
    let seg = path("block.dcm");
    let grid = Grid {
        origin: [-4.0, -4.0, 5.0],
        spacing: [1.0, 1.0],
        size: [9, 9],
    };
    let all: Vec<(usize, usize)> = (0..9).flat_map(|r| (0..9).map(move |c| (r, c))).collect();
    let frames: Vec<SegFrame> = (5..10)
        .map(|z| SegFrame {
            segment: 1,
            z: f64::from(z),
            pixels: all.clone(),
        })
        .collect();
    write_segmentation(
        std::path::Path::new(&seg),
        &grid,
        &[(1, "block", [34865, 53485, 50171])],
        &frames,
    );
    let depth = path("depth.npy");
    let png = path("view.png");
    let out = endocast(&[
        "render",
        &volume,
        "-o",
        &png,
        "--depth-out",
        &depth,
        "--mode",
        "iso",
        "--eye",
        "0,0,0",
        "--look-at",
        "0,0,1",
        "--size",
        "33x33",
        "--overlay",
        &seg,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("overlay") && stderr.contains("block 0.4 ml"),
        "{stderr}"
    );
    // The block's near face: half a voxel before its first plane of voxel centres.
    let (_, depths) = read_npy(std::path::Path::new(&depth));
    let centre = depths[16 * 33 + 16];
    assert!((centre - 4.5).abs() < 0.1, "{centre}");
}

#[test]
fn the_airway_tree_meshes_from_a_point_in_the_trachea_with_the_preset_alone() {
    let Some(chest) = endocast_testdata::shared_data("chest-ct-airways-dicom") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("airways.stl");
    let out = endocast(&[
        "mesh",
        chest.to_str().unwrap(),
        "--preset",
        "bronchoscopy",
        "--from",
        "-18.55,72.33,11.5",
        "-o",
        mesh.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The tree grown at the preset's lumen threshold (some ten thousand triangles), not the
    // lungs joined to it at the wall's isovalue (about a million).
    let triangles: usize = stdout
        .split(": ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{stdout}"));
    assert!((5_000..200_000).contains(&triangles), "{stdout}");
}
