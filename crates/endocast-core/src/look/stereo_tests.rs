//! Stereo pairs of the look (issue 35, item 5): each eye the look's mono image from that eye,
//! the sphere through the wall of `geometry_tests` solid and stippled by each eye's depths.

use super::geometry_tests::{
    blue_sphere, camera, ray_pass, red_and_green, sphere_through_wall, wall, WALL_K,
};
use super::*;
use crate::camera::StereoRig;
use crate::render::{Filter, Frame, Quality, StereoFrames};

/// Eyes 2 mm apart, focused on the wall (18 mm ahead).
const RIG: StereoRig = StereoRig {
    eye_separation_mm: 2.0,
    focus_mm: 18.0,
};

/// What the frames show: colours and depths (not their statistics).
fn pixels(frame: &Frame) -> (&[crate::render::Premultiplied], &[f32]) {
    (&frame.color, &frame.depth_mm)
}

#[test]
fn each_eye_of_a_look_pair_is_the_mono_look_from_that_eye() {
    for secretion in [SecretionMode::Off, SecretionMode::On] {
        let volume = wall(secretion == SecretionMode::On);
        let (pass, camera) = (ray_pass(&volume, secretion), camera(&volume));
        let (scene, _, _) = blue_sphere(&volume, WALL_K + 2.0, 4.0);
        let (shading, scene) = (red_and_green(), Some(&scene));
        let mut buffers = StereoFrames::default();
        let pair = stereo_frame(
            &pass,
            (&camera, &RIG),
            &shading,
            scene,
            (0, Filter::Trilinear),
            &mut buffers,
        )
        .unwrap();
        let eyes = RIG.eyes(&camera).unwrap();
        for (eye, frame) in eyes.iter().zip(&pair) {
            let gbuffer = pass.trace(eye, Quality::Full);
            let mono = shade_with_scene(&gbuffer, eye, &shading, scene).unwrap();
            assert_eq!(pixels(frame), pixels(&mono), "{secretion:?}");
        }
        assert_ne!(pair[0].color, pair[1].color, "no parallax");
        // The right eye's searches started past the space the left eye showed empty.
        let right_alone = pass.trace(&eyes[1], Quality::Full).stats.samples;
        let right_shared = pair[1].stats.samples;
        assert!(
            right_shared * 3 < right_alone * 2,
            "{secretion:?}: {right_shared} samples shared, {right_alone} alone"
        );
        // Still frames past the first are the mono still's, eye by eye.
        let stills = stereo_still(
            &pass,
            (&camera, &RIG),
            &shading,
            scene,
            (2, Filter::Trilinear),
        )
        .unwrap();
        for (eye, frame) in eyes.iter().zip(&stills) {
            let mono = still(&pass, eye, &shading, scene, 2, Filter::Trilinear).unwrap();
            assert_eq!(pixels(frame), pixels(&mono), "{secretion:?}");
        }
    }
}

#[test]
fn each_eye_shows_the_sphere_solid_in_front_and_stippled_behind_by_its_own_depths() {
    let volume = wall(false);
    let (pass, camera) = (ray_pass(&volume, SecretionMode::Off), camera(&volume));
    let (scene, centre, radius) = blue_sphere(&volume, WALL_K + 4.0, 5.0);
    let shading = red_and_green();
    let plain = stereo_still(
        &pass,
        (&camera, &RIG),
        &shading,
        None,
        (1, Filter::Trilinear),
    )
    .unwrap();
    let with = stereo_still(
        &pass,
        (&camera, &RIG),
        &shading,
        Some(&scene),
        (1, Filter::Trilinear),
    )
    .unwrap();
    let eyes = RIG.eyes(&camera).unwrap();
    for (eye, (plain, with)) in eyes.iter().zip(plain.iter().zip(&with)) {
        let n = sphere_through_wall(eye, [plain, with], &volume, (centre, radius));
        assert!(n.iter().all(|&n| n > 40), "{n:?}");
    }
    // The eyes see the sphere from 2 mm apart (the counts mirror each other, the pixels not).
    assert_ne!(with[0].color, with[1].color);
}

#[test]
fn a_rig_without_eyes_is_an_error() {
    let volume = wall(false);
    let (pass, camera) = (ray_pass(&volume, SecretionMode::Off), camera(&volume));
    let rig = StereoRig {
        eye_separation_mm: f64::NAN,
        ..RIG
    };
    let shading = red_and_green();
    let pair = stereo_still(
        &pass,
        (&camera, &rig),
        &shading,
        None,
        (1, Filter::Trilinear),
    );
    assert!(matches!(pair, Err(LookError::Camera(_))), "{pair:?}");
}
