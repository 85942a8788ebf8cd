use super::*;
use crate::camera::Optics;
use crate::navigate::{seed_voxel, LumenSide};
use crate::phantom::{Phantom, PhantomOptions};
use crate::render::{Mode, Renderer};
use crate::{Geometry, Modality, ValueMap};
use glam::{DMat3, DVec3};
use std::sync::Arc;

fn phantom(kind: Phantom, size: usize) -> Volume {
    kind.build(&PhantomOptions {
        size,
        ..Default::default()
    })
}

fn preset(name: &str) -> &'static Preset {
    Preset::find(name).unwrap()
}

/// The share of a 96² iso render from `study`'s start that meets the wall.
fn hit_share(volume: Volume, study: &Study) -> f64 {
    let pose = study.start_pose();
    let optics = Optics {
        field: study.fov_deg(),
        ..Optics::default()
    };
    let camera = optics
        .camera(pose.eye_mm, pose.look_at_mm, pose.up, [96, 96])
        .unwrap();
    let mut settings = study.settings().clone();
    settings.mode = Mode::Iso;
    let renderer = Arc::new(Renderer::new(volume));
    let frame = renderer.prepare(&settings).unwrap().render(&camera);
    let hits = frame.depth_mm.iter().filter(|d| !d.is_nan()).count();
    hits as f64 / frame.depth_mm.len() as f64
}

#[test]
fn the_start_is_inside_the_structure_looking_along_the_automatic_path() {
    let volume = phantom(Phantom::Colon, 96);
    let study = Study::resolve(&volume, &StudyRequest::preset(preset("colonoscopy")));
    let pose = study.start_pose();
    let lumen = study.structure().expect("the colon is found");
    assert!(lumen.contains(seed_voxel(&volume, pose.eye_mm).unwrap()));
    let path = study
        .path()
        .expect("a path is planned from the start")
        .path
        .clone();
    assert!(path.point_at(0.0).distance(pose.eye_mm) < 1e-9);
    let tangent = (path.point_at(LOOK_AHEAD_MM) - path.point_at(0.0)).normalize();
    let forward = (pose.look_at_mm - pose.eye_mm).normalize();
    assert!(forward.dot(tangent) > 0.999, "{forward} against {tangent}");
    assert!(pose.up.dot(forward).abs() < 1e-9);
}

#[test]
fn the_lumen_threshold_follows_the_wall_but_never_comes_near_air() {
    let volume = phantom(Phantom::StraightTube, 32);
    let bronchoscopy = preset("bronchoscopy");
    let plain = Study::resolve(&volume, &StudyRequest::preset(bronchoscopy));
    assert_eq!(plain.lumen(), Ok((-900.0, LumenSide::Below)));
    assert_eq!(plain.notes().count(), 0);
    // Moved up with the wall: as far below it as the preset has it.
    let up = StudyRequest {
        iso: Some(-300.0),
        ..StudyRequest::preset(bronchoscopy)
    };
    let gap = bronchoscopy.iso - -900.0;
    let moved = Study::resolve(&volume, &up).lumen();
    assert_eq!(moved, Ok((-300.0 - gap, LumenSide::Below)));
    // Moved down with the wall to −1150 would be below any air: held a quarter of the way from
    // the air (−1000 HU) to the wall.
    let down = StudyRequest {
        iso: Some(-750.0),
        ..StudyRequest::preset(bronchoscopy)
    };
    let study = Study::resolve(&volume, &down);
    let (threshold, side) = study.lumen().unwrap();
    assert_eq!(side, LumenSide::Below);
    assert!((threshold - -937.5).abs() < 1e-9, "{threshold}");
    assert!(study.notes().any(|n| n.contains("quarter")));
    assert_eq!(study.lumen_at(-300.0), moved);
    // A threshold the user gives is theirs.
    let given = StudyRequest {
        lumen_threshold: Some(-1100.0),
        ..down
    };
    assert_eq!(Study::resolve(&volume, &given).lumen().unwrap().0, -1100.0);
}

#[test]
fn a_scan_stored_as_hu_plus_1024_resolves_the_preset_in_its_own_units() {
    let hu = phantom(Phantom::Sinus, 48);
    let shifted = Volume::new(
        *hu.geometry(),
        hu.voxels().to_vec(),
        ValueMap::new(1.0, 0.0).unwrap(),
        Modality::Unknown,
    )
    .unwrap();
    let offset = hu.value_map().physical(0) - shifted.value_map().physical(0);
    let a = Study::resolve(&hu, &StudyRequest::preset(preset("sinus")));
    let b = Study::resolve(&shifted, &StudyRequest::preset(preset("sinus")));
    assert!((b.settings().iso_hu - a.settings().iso_hu + offset).abs() < 1e-9);
    assert!((b.lumen().unwrap().0 - a.lumen().unwrap().0 + offset).abs() < 1e-9);
    assert_eq!(a.start_pose(), b.start_pose());
}

#[test]
fn a_users_pose_is_kept_and_no_structure_is_searched() {
    let volume = phantom(Phantom::Colon, 64);
    let pose = Pose {
        eye_mm: DVec3::ZERO,
        look_at_mm: DVec3::Z,
        up: DVec3::NEG_Y,
    };
    let request = StudyRequest {
        pose: Some(pose),
        ..StudyRequest::preset(preset("colonoscopy"))
    };
    let study = Study::resolve(&volume, &request);
    assert_eq!(study.start_pose(), pose);
    assert!(study.view().is_none() && study.path().is_none());
}

#[test]
fn without_a_preset_a_round_object_fills_at_least_a_third_of_the_image() {
    // (The other phantoms are tissue to the volume's border: no outside to frame them from.)
    let volume = phantom(Phantom::SphereShell, 48);
    let study = Study::resolve(&volume, &StudyRequest::default());
    assert!(study.found().is_none());
    let share = hit_share(volume, &study);
    assert!(share >= 1.0 / 3.0, "{share:.3}");
}

#[test]
fn a_small_coarse_anisotropic_scan_is_framed_close() {
    // 58 × 58 × 24 voxels of 4 × 4 × 5 mm (a clinical low-resolution MRI), a head-sized ball
    // of tissue (0 HU) in air that leaves a wide margin of the field of view empty.
    let dims = [58, 58, 24];
    let spacing = DVec3::new(4.0, 4.0, 5.0);
    let geometry = Geometry::new(dims, spacing, DVec3::ZERO, DMat3::IDENTITY).unwrap();
    let centre = DVec3::new(28.5, 28.5, 11.5) * spacing;
    let mut voxels = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = DVec3::new(i as f64, j as f64, k as f64) * spacing;
                voxels.push(if p.distance(centre) < 50.0 { 1024 } else { 24 });
            }
        }
    }
    let map = ValueMap::new(1.0, -1024.0).unwrap();
    let volume = Volume::new(geometry, voxels, map, Modality::Mr).unwrap();
    let study = Study::resolve(&volume, &StudyRequest::default());
    let share = hit_share(volume, &study);
    assert!(share >= 1.0 / 3.0, "{share:.3}");
}
