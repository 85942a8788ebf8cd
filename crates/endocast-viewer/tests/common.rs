//! A session in the straight-tube phantom, and waiting for its frames.

use endocast_core::phantom::{self, PhantomOptions};
use endocast_core::pose::Pose;
use endocast_core::presets::Preset;
use endocast_core::render::progressive::Stage;
use endocast_core::Volume;
use endocast_viewer::scene::{ScanSource, Scene};
use endocast_viewer::session::Session;
use endocast_viewer::worker::{Delivered, STILL_FRAMES};
use glam::DVec3;
use std::sync::Arc;
use std::time::Duration;

/// Edge of the phantom, voxels (1 mm).
pub const SIZE: usize = 40;

/// The tube's axis point at the volume's centre and its radius, world mm.
pub struct TubeTruth {
    pub centre_mm: DVec3,
    pub axis: DVec3,
    pub radius_mm: f64,
}

/// The straight tube (`SIZE`), a pose in its middle looking across it (toward the wall), and
/// where its axis is.
pub fn tube() -> (Volume, Pose, TubeTruth) {
    let options = PhantomOptions {
        size: SIZE,
        ..PhantomOptions::default()
    };
    let (volume, tube) = phantom::straight_tube(&options);
    let geometry = *volume.geometry();
    let points = tube.centreline.points();
    let mid = (points[0] + points[1]) / 2.0;
    let centre_mm = geometry.world_of(mid);
    let axis = (geometry.world_of(points[1]) - geometry.world_of(points[0])).normalize();
    let across = (geometry.world_of(mid + DVec3::X) - centre_mm).normalize();
    let pose = Pose {
        eye_mm: centre_mm,
        look_at_mm: centre_mm + across,
        up: axis,
    };
    let truth = TubeTruth {
        centre_mm,
        axis,
        radius_mm: tube.radius_vox,
    };
    (volume, pose, truth)
}

/// A session in the middle of the straight tube (colonoscopy preset), looking across it
/// (toward the wall) at `64 × 64` pixels.
pub fn tube_session() -> (Session, TubeTruth) {
    let (volume, pose, truth) = tube();
    let source = ScanSource::Phantom {
        name: "straight-tube".into(),
        size: SIZE,
    };
    let scene = Arc::new(Scene::new(source, volume));
    let preset = Preset::find("colonoscopy");
    let mut session = Session::new(scene, preset, Some(pose), || {});
    session.set_view_size([64, 64]);
    (session, truth)
}

/// Distance of `p` from the tube's axis, mm.
pub fn off_axis_mm(truth: &TubeTruth, p: DVec3) -> f64 {
    let d = p - truth.centre_mm;
    (d - truth.axis * d.dot(truth.axis)).length()
}

/// Sends the current (still) view and waits for its final still.
pub fn settled(session: &mut Session) -> Delivered {
    session.sync(false);
    let generation = session.worker().generation();
    session
        .worker()
        .wait_for(generation, Duration::from_secs(60), |f| {
            f.stage == Stage::Still(STILL_FRAMES)
        })
        .expect("the view refines to its still within a minute")
}

/// Mean absolute difference of two RGB images of one size, 0–255.
pub fn mean_difference(a: &Delivered, b: &Delivered) -> f64 {
    assert_eq!(a.image.width(), b.image.width());
    let (a, b) = (a.image.rgb(), b.image.rgb());
    let sum: u64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| u64::from(x.abs_diff(*y)))
        .sum();
    sum as f64 / a.len() as f64
}
