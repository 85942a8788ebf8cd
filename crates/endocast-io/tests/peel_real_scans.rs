//! Depth peeling in real scans (issue 19): from inside the tibia of the knee MRI the first peel
//! is the femur's surface across the joint space, and from inside the stented aorta of the CTA
//! it is what lies behind the wall, in both cases beyond the surface an endoscope would see.

use endocast_core::camera::Optics;
use endocast_core::presets::Preset;
use endocast_core::render::{Frame, Mode, RenderSettings, Renderer};
use endocast_io::OpenOptions;
use endocast_testdata::shared_data;
use glam::DVec3;
use std::sync::Arc;

const SIZE: usize = 64;

/// The scan `data`, or `None` outside CI when it is absent.
fn open(data: &str) -> Option<Arc<Renderer>> {
    let path = shared_data(data)?;
    let volume = endocast_io::open(&path, &OpenOptions::default())
        .unwrap()
        .volume;
    Some(Arc::new(Renderer::new(volume)))
}

/// The iso render (the near wall, as an endoscope sees it) and the peel render of `settings`
/// from `eye` towards `look_at`.
fn near_and_peeled(
    renderer: &Arc<Renderer>,
    settings: &RenderSettings,
    [eye, look_at, up]: [[f64; 3]; 3],
) -> (Frame, Frame) {
    let camera = Optics::default()
        .camera(
            DVec3::from(eye),
            DVec3::from(look_at),
            DVec3::from(up),
            [SIZE, SIZE],
        )
        .unwrap();
    let mut iso = RenderSettings::default();
    (iso.mode, iso.iso_hu) = (Mode::Iso, settings.peel_threshold_hu());
    let near = renderer.prepare(&iso).unwrap().render(&camera);
    let peeled = renderer.prepare(settings).unwrap().render(&camera);
    (near, peeled)
}

/// Over the central half of the image: the share of pixels whose peel lies at least `gap_mm`
/// beyond the near wall, and the median of those distances.
fn beyond(near: &Frame, peeled: &Frame, gap_mm: f32) -> (f64, f32) {
    let quarter = SIZE / 4;
    let mut beyond = Vec::new();
    for y in quarter..SIZE - quarter {
        for x in quarter..SIZE - quarter {
            let i = x + SIZE * y;
            beyond.push(peeled.depth_mm[i] - near.depth_mm[i]);
        }
    }
    let count = beyond.len();
    let far = beyond.iter().filter(|d| **d >= gap_mm).count();
    let mut seen: Vec<f32> = beyond.into_iter().filter(|d| !d.is_nan()).collect();
    seen.sort_by(f32::total_cmp);
    (far as f64 / count as f64, seen[seen.len() / 2])
}

#[test]
fn a_peel_from_inside_the_tibia_shows_the_femur_across_the_joint() {
    let Some(renderer) = open("knee-mri/knee3D_dataT.mha") else {
        return;
    };
    let settings = Preset::find("arthroscopy").unwrap().settings();
    // The docs' view: from the tibia's marrow up across the joint space.
    let pose = [[75.0, 30.0, 32.0], [75.0, 30.0, 70.0], [-1.0, 0.0, 0.0]];
    let (near, peeled) = near_and_peeled(&renderer, &settings, pose);
    let (share, median) = beyond(&near, &peeled, 1.0);
    assert!(
        share > 0.75,
        "{share} of the peels lie beyond the tibia's own surface"
    );
    assert!(median > 2.0, "median {median} mm beyond it");
}

#[test]
fn a_peel_from_inside_the_stented_aorta_shows_what_lies_behind_the_wall() {
    let Some(renderer) = open("aorta-stent-cta/stent.nrrd") else {
        return;
    };
    let mut settings = RenderSettings::default();
    settings.mode = Mode::Peel;
    // Between soft tissue (≤ 62) and the lumen (312–437): from the lumen, the first crossing
    // back above it lies outside the graft (stent wires, then the vertebral body).
    settings.peel.threshold_hu = Some(150.0);
    let pose = [[65.0, 49.0, 128.0], [65.0, 100.0, 128.0], [0.0, 0.0, 1.0]];
    let (near, peeled) = near_and_peeled(&renderer, &settings, pose);
    let (share, median) = beyond(&near, &peeled, 0.5);
    assert!(share > 0.6, "{share} of the peels lie behind the wall");
    assert!(median > 2.0, "median {median} mm behind it");
}
