//! The written dataset read back as a user would: the depth PNGs against the analytic sphere,
//! and the cameras of transforms.json and COLMAP's text, used with their own formulas only.

use super::DatasetWriter;
use endocast_core::camera::{Camera, Optics, Projection};
use endocast_core::phantom::{self, PhantomOptions, SphereShell};
use endocast_core::render::{Mode, RenderSettings, Renderer};
use endocast_core::views::Image;
use endocast_core::Volume;
use glam::{DMat3, DQuat, DVec3};
use serde_json::Value;
use std::path::Path;
use std::sync::Arc;

fn shell() -> (Arc<Renderer>, SphereShell) {
    let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
        size: 48,
        ..Default::default()
    });
    (Arc::new(Renderer::new(volume)), shell)
}

/// Renders `cameras` of the shell's wall into a new dataset in `folder`.
fn write(renderer: &Arc<Renderer>, cameras: &[Camera], folder: &Path) {
    let mut settings = RenderSettings::default();
    settings.mode = Mode::Iso;
    settings.iso_hu = -480.0;
    let prepared = renderer.prepare(&settings).unwrap();
    let mut writer =
        DatasetWriter::create(folder, renderer.volume(), &optics(&cameras[0])).unwrap();
    for camera in cameras {
        let frame = prepared.render(camera);
        let image = Image::from_frame(&frame, settings.background).unwrap();
        writer
            .push(&image, camera, &frame.depth_mm, renderer.volume())
            .unwrap();
    }
    writer.finish().unwrap();
}

/// Two cameras inside the shell, off its centre, looking different ways.
fn two_cameras(
    volume: &Volume,
    shell: &SphereShell,
    projection: Projection,
    field: f64,
) -> [Camera; 2] {
    let centre = volume.geometry().world_of(shell.centre_vox);
    let at = |offset: DVec3, look: DVec3| {
        Camera::look_at(
            centre + offset,
            centre + offset + look,
            DVec3::Z,
            90.0,
            [40, 30],
        )
        .unwrap()
        .with_projection(projection, field)
        .unwrap()
    };
    [
        at(DVec3::new(2.0, 1.0, 0.0), DVec3::new(1.0, 0.2, 0.1)),
        at(DVec3::new(-3.0, 2.0, 1.0), DVec3::new(0.8, 0.5, -0.2)),
    ]
}

/// The optics of `camera`.
fn optics(camera: &Camera) -> Optics {
    Optics {
        projection: camera.projection(),
        field: camera.field(),
        lens: camera.lens(),
        near_mm: camera.near_mm(),
    }
}

/// A 16-bit greyscale PNG's samples.
fn read_u16(path: &Path) -> Vec<u16> {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut reader = png::Decoder::new(file).read_info().unwrap();
    assert_eq!(reader.info().bit_depth, png::BitDepth::Sixteen);
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut buf).unwrap();
    buf.chunks(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .collect()
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn number(v: &Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("{key} missing"))
}

#[test]
fn the_depth_pngs_hold_the_spheres_radius_within_a_twentieth_voxel() {
    let (renderer, shell) = shell();
    let volume = renderer.volume();
    let spacing = volume.geometry().spacing_mm().x;
    let centre = volume.geometry().world_of(shell.centre_vox);
    let camera = Camera::look_at(
        centre,
        centre + DVec3::new(1.0, 0.3, -0.2),
        DVec3::Z,
        100.0,
        [40, 30],
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("data");
    write(&renderer, &[camera], &folder);
    let json = read_json(&folder.join("transforms.json"));
    let scale = number(&json, "depth_scale_mm");
    let ray = read_u16(&folder.join("depth/00000.png"));
    let z = read_u16(&folder.join("depth_z/00000.png"));
    let radius_mm = shell.inner_radius_vox * spacing;
    for (i, (&ray, &z)) in ray.iter().zip(&z).enumerate() {
        let depth = f64::from(ray) * scale;
        assert!(
            (depth - radius_mm).abs() < 0.05 * spacing,
            "pixel {i}: {depth} mm"
        );
        let cos = camera
            .pixel_ray(i % 40, i / 40)
            .unwrap()
            .dir
            .dot(camera.forward());
        assert!((f64::from(z) * scale - radius_mm * cos).abs() < 0.05 * spacing);
    }
}

/// Pixel of camera-frame (OpenGL) point `p` by the JSON's model, as nerfstudio computes it.
fn project_gl(json: &Value, p: DVec3) -> (f64, f64) {
    let (fx, fy, cx, cy) = (
        number(json, "fl_x"),
        number(json, "fl_y"),
        number(json, "cx"),
        number(json, "cy"),
    );
    let (a, b) = match json["camera_model"].as_str().unwrap() {
        "OPENCV" => (p.x / -p.z, p.y / -p.z),
        "OPENCV_FISHEYE" => {
            let across = p.x.hypot(p.y);
            let theta = across.atan2(-p.z);
            (theta * p.x / across, theta * p.y / across)
        }
        other => panic!("{other}"),
    };
    (cx + fx * a, cy - fy * b)
}

/// World point of pixel `(x, y)` of `frame` from its depth codes, by the JSON only: z-depth
/// for a pinhole, depth along the ray for a fisheye.
fn unproject(json: &Value, frame: &Value, folder: &Path, (x, y): (usize, usize)) -> Option<DVec3> {
    let (fx, fy, cx, cy) = (
        number(json, "fl_x"),
        number(json, "fl_y"),
        number(json, "cx"),
        number(json, "cy"),
    );
    let w = json["w"].as_u64().unwrap() as usize;
    let scale = number(json, "depth_scale_mm");
    let (a, b) = ((x as f64 + 0.5 - cx) / fx, -(y as f64 + 0.5 - cy) / fy);
    let p = match json["camera_model"].as_str().unwrap() {
        "OPENCV" => {
            let z = read_u16(&folder.join(frame["depth_file_path"].as_str().unwrap()))[x + w * y];
            DVec3::new(a, b, -1.0) * f64::from(z) * scale
        }
        _ => {
            let t =
                read_u16(&folder.join(frame["depth_ray_file_path"].as_str().unwrap()))[x + w * y];
            let theta = a.hypot(b);
            let d = DVec3::new(
                a / theta * theta.sin(),
                b / theta * theta.sin(),
                -theta.cos(),
            );
            d * f64::from(t) * scale
        }
    };
    let m = &frame["transform_matrix"];
    let row = |r: usize| {
        let r: Vec<f64> = m[r]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        r[0] * p.x + r[1] * p.y + r[2] * p.z + r[3]
    };
    Some(DVec3::new(row(0), row(1), row(2)))
}

/// World point `p` in the OpenGL camera frame of `frame`.
fn to_camera_gl(frame: &Value, p: DVec3) -> DVec3 {
    let m = &frame["transform_matrix"];
    let at = |r: usize, c: usize| m[r][c].as_f64().unwrap();
    let rotation = DMat3::from_cols_array_2d(&[
        [at(0, 0), at(1, 0), at(2, 0)],
        [at(0, 1), at(1, 1), at(2, 1)],
        [at(0, 2), at(1, 2), at(2, 2)],
    ]);
    rotation.transpose() * (p - DVec3::new(at(0, 3), at(1, 3), at(2, 3)))
}

#[test]
fn the_transforms_reproject_wall_points_between_frames_within_half_a_pixel() {
    let (renderer, shell) = shell();
    for (projection, field) in [
        (Projection::Pinhole, 90.0),
        (Projection::Equidistant, 160.0),
    ] {
        let cameras = two_cameras(renderer.volume(), &shell, projection, field);
        let dir = tempfile::tempdir().unwrap();
        write(&renderer, &cameras, dir.path());
        let json = read_json(&dir.path().join("transforms.json"));
        let frames = json["frames"].as_array().unwrap();
        let (mut compared, mut worst) = (0, 0.0f64);
        for y in (0..30).step_by(3) {
            for x in (0..40).step_by(3) {
                let Some(wall) = unproject(&json, &frames[0], dir.path(), (x, y)) else {
                    continue;
                };
                let Some(seen) = cameras[1].project(wall) else {
                    continue;
                };
                if !(0.0..40.0).contains(&seen.0) || !(0.0..30.0).contains(&seen.1) {
                    continue;
                }
                let (u, v) = project_gl(&json, to_camera_gl(&frames[1], wall));
                worst = worst.max((u - seen.0).hypot(v - seen.1));
                compared += 1;
            }
        }
        assert!(compared > 20, "{projection:?}: {compared} points");
        assert!(worst < 0.5, "{projection:?}: {worst} px");
    }
}

#[test]
fn colmaps_text_has_the_poses_and_intrinsics_of_transforms_json() {
    let (renderer, shell) = shell();
    let cameras = two_cameras(renderer.volume(), &shell, Projection::Equidistant, 170.0);
    let dir = tempfile::tempdir().unwrap();
    write(&renderer, &cameras, dir.path());
    let json = read_json(&dir.path().join("transforms.json"));
    let colmap = dir.path().join("colmap");
    let cameras_txt = std::fs::read_to_string(colmap.join("cameras.txt")).unwrap();
    let camera: Vec<&str> = cameras_txt
        .lines()
        .filter(|l| !l.starts_with('#'))
        .collect();
    assert_eq!(camera.len(), 1, "one camera for frames of the same optics");
    let fields: Vec<&str> = camera[0].split_whitespace().collect();
    assert_eq!(fields[..4], ["1", "OPENCV_FISHEYE", "40", "30"]);
    let params: Vec<f64> = fields[4..].iter().map(|f| f.parse().unwrap()).collect();
    let keys = ["fl_x", "fl_y", "cx", "cy", "k1", "k2", "k3", "k4"];
    assert_eq!(params, keys.map(|k| number(&json, k)));
    let images_txt = std::fs::read_to_string(colmap.join("images.txt")).unwrap();
    let images: Vec<&str> = images_txt
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .collect();
    let frames = json["frames"].as_array().unwrap();
    assert_eq!(images.len(), frames.len());
    for (line, frame) in images.iter().zip(frames) {
        let f: Vec<&str> = line.split_whitespace().collect();
        let n: Vec<f64> = f[1..8].iter().map(|v| v.parse().unwrap()).collect();
        let q = DQuat::from_xyzw(n[1], n[2], n[3], n[0]);
        let t = DVec3::new(n[4], n[5], n[6]);
        assert_eq!(
            format!("images/{}", f[9]),
            frame["file_path"].as_str().unwrap()
        );
        for p in [DVec3::new(10.0, -4.0, 7.0), DVec3::new(-3.0, 20.0, 1.0)] {
            let opencv = q * p + t;
            let gl = to_camera_gl(frame, p);
            assert!(opencv.distance(DVec3::new(gl.x, -gl.y, -gl.z)) < 1e-9);
        }
    }
    let points = std::fs::read_to_string(colmap.join("points3D.txt")).unwrap();
    assert!(points.lines().all(|l| l.starts_with('#')));
}

#[test]
fn a_file_or_a_folder_with_files_is_refused() {
    let (renderer, _) = shell();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("taken");
    std::fs::write(&file, "x").unwrap();
    let error = DatasetWriter::create(&file, renderer.volume(), &Optics::default()).unwrap_err();
    assert!(error.to_string().contains("is a file"), "{error}");
    let error =
        DatasetWriter::create(dir.path(), renderer.volume(), &Optics::default()).unwrap_err();
    assert!(error.to_string().contains("files in it"), "{error}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    let orthographic = Camera::look_at(DVec3::ZERO, DVec3::X, DVec3::Z, 90.0, [4, 4])
        .unwrap()
        .with_projection(Projection::Orthographic, 30.0)
        .unwrap();
    let new = dir.path().join("new");
    let error = DatasetWriter::create(&new, renderer.volume(), &optics(&orthographic)).unwrap_err();
    assert!(error.to_string().contains("orthographic"), "{error}");
    assert!(!new.exists());
    let mut writer = DatasetWriter::create(&new, renderer.volume(), &Optics::default()).unwrap();
    let image = Image::from_rgb(4, 4, vec![0; 48]).unwrap();
    let error = writer
        .push(&image, &orthographic, &[f32::NAN; 16], renderer.volume())
        .unwrap_err();
    assert!(error.to_string().contains("orthographic"), "{error}");
    assert_eq!(std::fs::read_dir(new.join("images")).unwrap().count(), 0);
}

#[test]
fn a_frame_with_another_field_carries_its_own_intrinsics_and_colmap_camera() {
    let (renderer, shell) = shell();
    let [a, b] = two_cameras(renderer.volume(), &shell, Projection::Pinhole, 90.0);
    let b = b.with_projection(Projection::Pinhole, 60.0).unwrap();
    let dir = tempfile::tempdir().unwrap();
    write(&renderer, &[a, b, a], dir.path());
    let json = read_json(&dir.path().join("transforms.json"));
    let frames = json["frames"].as_array().unwrap();
    assert!(frames[0].get("fl_x").is_none() && frames[2].get("fl_x").is_none());
    let narrower = 15.0 / (30f64.to_radians()).tan();
    assert!((number(&frames[1], "fl_x") - narrower).abs() < 1e-9);
    assert!((number(&json, "fl_x") - 15.0).abs() < 1e-9);
    let colmap = dir.path().join("colmap");
    let cameras = std::fs::read_to_string(colmap.join("cameras.txt")).unwrap();
    assert_eq!(cameras.lines().filter(|l| !l.starts_with('#')).count(), 2);
    let images = std::fs::read_to_string(colmap.join("images.txt")).unwrap();
    let ids: Vec<&str> = images
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .map(|l| l.split_whitespace().nth(8).unwrap())
        .collect();
    assert_eq!(ids, ["1", "2", "1"]);
}
