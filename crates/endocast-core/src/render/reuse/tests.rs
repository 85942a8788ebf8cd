//! Frames rendered with reuse are the frames rendered alone, bit for bit, along a flight and
//! through turns, jumps and structures entering the view; a ball made too large is caught.

use super::FrameReuse;
use crate::render::tests::{assert_same_image, colon_view};
use crate::render::{Camera, Frame, Mode, Prepared, RenderSettings, Renderer, TransferFunction};
use crate::{Geometry, Modality, ValueMap, Volume};
use glam::DVec3;
use std::sync::Arc;

/// The phantoms' air/tissue boundary value.
const PHANTOM_WALL_HU: f64 = -480.0;

fn iso(hu: f64) -> RenderSettings {
    RenderSettings {
        mode: Mode::Iso,
        iso_hu: hu,
        ..RenderSettings::default()
    }
}

/// Renders `cameras` in turn with one reuse state and alone; asserts the images are the same
/// and returns the reused frames' fractions of late starts and their samples over the plain
/// frames'.
fn fly(prepared: &Prepared, reuse: &mut FrameReuse, cameras: &[Camera]) -> Vec<(f64, f64)> {
    let mut frame = Frame::default();
    cameras
        .iter()
        .enumerate()
        .map(|(k, camera)| {
            prepared.render_reusing(camera, reuse, &mut frame);
            let alone = prepared.render(camera);
            assert_same_image(&frame, &alone, &format!("frame {k}"));
            let samples = frame.stats.samples as f64 / alone.stats.samples.max(1) as f64;
            (reuse.late_fraction(), samples)
        })
        .collect()
}

/// Whether every camera's frame with reuse (ball scaled by `scale`) is the frame alone.
fn all_same(prepared: &Prepared, scale: f32, cameras: &[Camera]) -> bool {
    let mut reuse = FrameReuse::with_ball_scale(scale);
    let mut frame = Frame::default();
    cameras.iter().all(|camera| {
        prepared.render_reusing(camera, &mut reuse, &mut frame);
        let alone = prepared.render(camera);
        frame.color == alone.color
            && frame
                .depth_mm
                .iter()
                .zip(&alone.depth_mm)
                .all(|(a, b)| a.to_bits() == b.to_bits())
    })
}

/// Cameras moving `step` voxels a frame along the colon phantom's centreline from `camera`.
fn along_colon(camera: &Camera, frames: usize, step_mm: f64) -> Vec<Camera> {
    (0..frames)
        .map(|k| {
            let eye = camera.eye_mm() + camera.forward() * (k as f64 * step_mm);
            Camera::look_at(
                eye,
                eye + camera.forward(),
                camera.up(),
                90.0,
                camera.size(),
            )
            .unwrap()
        })
        .collect()
}

/// Along the colon, iso and hybrid frames with reuse are the frames alone, and most of their
/// searches start late with far fewer samples (on this small phantom the first frame, from the
/// clear ball alone, takes 0.82 of the samples, the later ones 0.54–0.57).
#[test]
fn a_flight_along_the_colon_gives_the_same_frames_with_fewer_samples() {
    let (renderer, camera) = colon_view(160, 0.3, 64);
    let cameras = along_colon(&camera, 6, 0.8);
    for (mode, opacity, jitter) in [(Mode::Iso, 1.0, false), (Mode::Hybrid, 0.6, true)] {
        let settings = RenderSettings {
            mode,
            iso_opacity: opacity,
            jitter,
            tf: TransferFunction::preset("complex").unwrap(),
            ..iso(PHANTOM_WALL_HU)
        };
        let prepared = renderer.prepare(&settings).unwrap();
        let runs = fly(&prepared, &mut FrameReuse::new(), &cameras);
        for &(late, samples) in &runs[1..] {
            assert!(late > 0.9, "{mode:?}: {late} of the pixels started late");
            if mode == Mode::Iso {
                assert!(samples < 0.7, "{mode:?}: {samples} of the samples");
            }
        }
    }
}

/// A box of tissue around air holding a small sphere near the eye, a second one off to the
/// side and a thin rod across the view (values ramped over one voxel).
fn thin_structures() -> Volume {
    let n = 48;
    let g = Geometry::axis_aligned([n; 3], DVec3::ONE, DVec3::ZERO).unwrap();
    let spheres = [
        (DVec3::new(24.0, 25.0, 22.0), 1.2),
        (DVec3::new(35.0, 24.0, 24.0), 1.5),
    ];
    let rod = |p: DVec3| DVec3::new(p.x - 22.0, 0.0, p.z - 34.0).length() - 0.6;
    let voxels = (0..n * n * n)
        .map(|i| {
            let p = DVec3::new((i % n) as f64, (i / n % n) as f64, (i / (n * n)) as f64);
            let wall = (p.min_element()).min(n as f64 - 1.0 - p.max_element()) - 2.0;
            let inside = spheres
                .iter()
                .map(|&(c, r)| (p - c).length() - r)
                .fold(rod(p), f64::min)
                .min(wall);
            (1000.0 * (0.5 - inside).clamp(0.0, 1.0)) as u16
        })
        .collect();
    Volume::new(g, voxels, ValueMap::IDENTITY, Modality::Unknown).unwrap()
}

/// A camera at `eye` (voxels = mm here) looking along `forward`, 60°, 48².
fn look(eye: DVec3, forward: DVec3) -> Camera {
    Camera::look_at(eye, eye + forward, DVec3::Y, 60.0, [48, 48]).unwrap()
}

/// A turn that brings a sphere and the rod into view step by step, a turn of 90° at once, a
/// jump and a move back: every frame the frame alone.
#[test]
fn turns_jumps_and_structures_entering_the_view_give_the_same_frames() {
    let renderer = Arc::new(Renderer::new(thin_structures()));
    let prepared = renderer.prepare(&iso(500.0)).unwrap();
    let eye = DVec3::new(24.0, 24.0, 14.0);
    let turn = |deg: f64| {
        let a = deg.to_radians();
        DVec3::new(a.sin(), 0.0, a.cos())
    };
    let mut cameras: Vec<Camera> = (0..5)
        .map(|k| look(eye, turn(-20.0 + 12.0 * f64::from(k))))
        .collect();
    cameras.push(look(eye, turn(110.0)));
    cameras.push(look(eye + DVec3::new(0.0, 0.0, 12.0), DVec3::Z));
    cameras.push(look(eye + DVec3::new(-4.0, 0.0, 4.0), DVec3::Z));
    cameras.push(look(eye, DVec3::Z));
    let runs = fly(&prepared, &mut FrameReuse::new(), &cameras);
    assert!(runs.iter().all(|&(late, _)| late > 0.5), "{runs:?}");
}

/// A state kept across a change of volume or settings starts from the clear ball alone: a
/// sphere added to the volume between two frames is seen.
#[test]
fn a_new_volume_or_new_settings_are_not_bounded_by_the_old_frame() {
    let camera = look(DVec3::new(24.0, 24.0, 14.0), DVec3::Z);
    let empty = Arc::new(Renderer::new(thin_structures()));
    let mut reuse = FrameReuse::new();
    let mut frame = Frame::default();
    empty
        .prepare(&iso(500.0))
        .unwrap()
        .render_reusing(&camera, &mut reuse, &mut frame);
    let mut voxels = thin_structures().voxels().to_vec();
    // A solid block in front of the eye, where the old frame saw the far wall.
    for k in 28..31 {
        for j in 22..27 {
            for i in 22..27 {
                voxels[i + 48 * (j + 48 * k)] = 1000;
            }
        }
    }
    let g = *empty.volume().geometry();
    let volume = Volume::new(g, voxels, ValueMap::IDENTITY, Modality::Unknown).unwrap();
    let changed = Arc::new(Renderer::new(volume));
    let prepared = changed.prepare(&iso(500.0)).unwrap();
    prepared.render_reusing(&camera, &mut reuse, &mut frame);
    assert_same_image(&frame, &prepared.render(&camera), "new volume");
    let lower = empty.prepare(&iso(200.0)).unwrap();
    lower.render_reusing(&camera, &mut reuse, &mut frame);
    assert_same_image(&frame, &lower.render(&camera), "new isovalue");
}

/// The mutation check: with the clear ball three times too large the frames change (a search
/// then starts behind the small sphere near the eye), so the tests above would catch it.
#[test]
fn a_clear_ball_made_too_large_changes_the_frames() {
    let renderer = Arc::new(Renderer::new(thin_structures()));
    let prepared = renderer.prepare(&iso(500.0)).unwrap();
    let cameras = [look(DVec3::new(24.0, 24.0, 14.0), DVec3::Z)];
    assert!(all_same(&prepared, 1.0, &cameras));
    assert!(!all_same(&prepared, 3.0, &cameras));
}
