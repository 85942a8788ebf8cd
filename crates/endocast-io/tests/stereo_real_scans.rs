//! Stereo pairs inside real scans: the second eye's searches, started where the first eye
//! showed the space empty, give the images of two plain renders bit for bit (issue 16), for a
//! dark lumen (air: trachea, nasal cavity, ventricle on T1) and a bright one (contrast: aorta).

use endocast_core::camera::{Optics, StereoRig};
use endocast_core::render::{Frame, Mode, RenderSettings, Renderer};
use endocast_io::OpenOptions;
use endocast_testdata::shared_data;
use glam::DVec3;

/// One scene of `bench/scenes.json`: the scan, how to open it, the isovalue and the pose.
struct Scene {
    data: &'static str,
    orientation: Option<&'static str>,
    iso: f64,
    eye: [f64; 3],
    look_at: [f64; 3],
    up: [f64; 3],
}

const SCENES: [Scene; 4] = [
    Scene {
        data: "chest-ct-airways-dicom",
        orientation: None,
        iso: -500.0,
        eye: [-9.84, 66.32, 51.5],
        look_at: [-17.58, 72.5, 15.5],
        up: [0.0, -1.0, 0.0],
    },
    Scene {
        data: "abdomen-ct-pancreas-dicom",
        orientation: None,
        iso: 130.0,
        eye: [27.55, 113.71, 355.91],
        look_at: [27.41, 102.56, 319.91],
        up: [0.0, -1.0, 0.0],
    },
    Scene {
        data: "head-ct-stanford-cthead/CThead.nhdr",
        orientation: Some("LPI"),
        iso: 550.0,
        eye: [104.0, 44.0, -120.0],
        look_at: [104.0, 63.779, -122.967],
        up: [0.0, 0.0, 1.0],
    },
    Scene {
        data: "brain-mri-t1/chris_t1.nii.gz",
        orientation: None,
        iso: 75.0,
        eye: [16.24, 31.88, 17.04],
        look_at: [12.055, 12.348, 18.037],
        up: [0.0, 0.0, 1.0],
    },
];

fn same(a: &Frame, b: &Frame, what: &str) {
    assert_eq!(a.color, b.color, "{what}: colours");
    let bits = |f: &Frame| f.depth_mm.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(a), bits(b), "{what}: depths");
}

#[test]
fn stereo_pairs_in_real_scans_equal_two_plain_renders() {
    for scene in &SCENES {
        let Some(path) = shared_data(scene.data) else {
            continue;
        };
        let mut options = OpenOptions::default();
        options.orientation = scene.orientation.map(str::to_owned);
        let volume = endocast_io::open(&path, &options).unwrap().volume;
        let renderer = std::sync::Arc::new(Renderer::new(volume));
        let camera = Optics::default()
            .camera(
                DVec3::from(scene.eye),
                DVec3::from(scene.look_at),
                DVec3::from(scene.up),
                [128, 96],
            )
            .unwrap();
        for mode in [Mode::Iso, Mode::Hybrid] {
            let mut settings = RenderSettings::default();
            (settings.mode, settings.iso_hu, settings.iso_opacity) = (mode, scene.iso, 0.6);
            let prepared = renderer.prepare(&settings).unwrap();
            let focus = prepared.nearest_surface_mm(&camera);
            let rig = StereoRig::for_view(None, focus, || None).unwrap();
            let [left, right] = prepared.render_stereo(&camera, &rig).unwrap();
            let [l, r] = rig.eyes(&camera).unwrap();
            let what = format!("{} {mode:?}", scene.data);
            same(&left, &prepared.render(&l), &format!("{what} left"));
            same(&right, &prepared.render(&r), &format!("{what} right"));
            let alone = prepared.render(&r).stats.samples;
            // The nasal cavity is a few mm wide (and CThead's slices 2 mm apart): the walls lie
            // within the margin, so nothing is skipped there; elsewhere most samples are.
            let most = scene.data.contains("cthead") || right.stats.samples * 2 < alone;
            assert!(
                right.stats.samples <= alone && most,
                "{what}: {} samples with the left eye's help, {alone} without",
                right.stats.samples
            );
        }
    }
}
