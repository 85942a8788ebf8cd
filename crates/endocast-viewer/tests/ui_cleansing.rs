//! The cleansing switch: the tagged pool of the colon phantom becomes air when it is turned on
//! and tagged fluid again when it is turned off; a scan that is no CT is not offered it.

use crate::harness::{options, Window};
use endocast_core::phantom::{Phantom, PhantomOptions};
use endocast_core::{Modality, Volume};
use endocast_viewer::cleansing::CleanseSwitch;
use endocast_viewer::scene::{ScanSource, Scene};
use endocast_viewer::session::Session;
use std::sync::Arc;

/// The brightest voxel of `volume` and its value.
fn brightest(volume: &Volume) -> ([usize; 3], f64) {
    let [nx, ny, nz] = volume.dims();
    let mut best = ([0; 3], f64::MIN);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let value = volume.physical(i, j, k).unwrap();
                if value > best.1 {
                    best = ([i, j, k], value);
                }
            }
        }
    }
    best
}

#[test]
fn the_cleansing_checkbox_turns_the_tagged_pool_into_air_and_back() {
    let phantom = PhantomOptions {
        size: 96,
        tagged_fluid: true,
        ..PhantomOptions::default()
    };
    let volume = Phantom::Colon.build(&phantom);
    let ([i, j, k], tagged) = brightest(&volume);
    assert!(tagged > 400.0, "no tagged pool: {tagged} HU");
    // The viewer's phantoms take no options: the tagged one is opened from a file.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tagged.nii");
    endocast_io::write(&path, &volume).unwrap();
    let source = ScanSource::File {
        path,
        series: None,
        orientation: None,
    };
    let mut window = Window::open(options(source));
    window.run_until(|app| app.session().is_some());
    window.frame(Vec::new());
    let value = |w: &Window| {
        let session = w.app.session().unwrap();
        session.scene().volume().physical(i, j, k).unwrap()
    };
    assert!((value(&window) - tagged).abs() < 1.0);
    assert_eq!(
        window.app.cleansing(),
        Some((false, false)),
        "off by default"
    );

    window.click_text("Cleanse tagged fluid");
    window.run_until(|app| app.cleansing() == Some((true, false)));
    assert!(value(&window) < -900.0, "the pool is {} HU", value(&window));
    let said = window.app.message().to_owned();
    assert!(said.contains("pool(s) of tagged fluid"), "{said}");
    // The view is drawn again, from the cleansed scan.
    window.settle();

    window.click_text("Cleanse tagged fluid");
    window.run_until(|app| app.cleansing() == Some((false, false)));
    assert!((value(&window) - tagged).abs() < 1.0, "{}", value(&window));
    assert!(window.app.message().contains("as acquired"));
}

#[test]
fn a_scan_that_is_no_ct_is_not_offered_cleansing() {
    let ct = Phantom::StraightTube.build(&PhantomOptions {
        size: 24,
        ..PhantomOptions::default()
    });
    let mr = Volume::new(
        *ct.geometry(),
        ct.voxels().to_vec(),
        ct.value_map(),
        Modality::Mr,
    )
    .unwrap();
    let source = ScanSource::Phantom {
        name: "straight-tube".into(),
        size: 24,
    };
    let open = |volume: Volume| {
        let scene = Arc::new(Scene::new(source.clone(), volume));
        Session::new(scene, None, None, || {})
    };
    assert_eq!(CleanseSwitch::unavailable(&open(ct)), None);
    let why = CleanseSwitch::unavailable(&open(mr)).expect("an MR is not offered cleansing");
    assert!(why.contains("Hounsfield"), "{why}");
}
