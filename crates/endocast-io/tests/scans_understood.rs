//! Issue 17 on the shared scans: each scan's values understood (HU, HU + 1024, intensities; CSF
//! dark or bright), and the ventricles found at the brain's centre on T1, FLAIR and a T2-like
//! volume made from the T1.

use endocast_core::cleanse::cleanse;
use endocast_core::navigate::{default_view, find_trachea, DefaultView, LumenChoice};
use endocast_core::presets::Preset;
use endocast_core::tissue::{self, ScanValues, ValueKind};
use endocast_core::{ValueMap, Volume};
use endocast_io::OpenOptions;
use endocast_testdata::shared_data;
use glam::DVec3;

/// The scan `name` under shared/data, or `None` (skipping, with a message) when absent; fails
/// under CI, where the data must be there.
fn load(name: &str) -> Option<Volume> {
    let path = shared_data(name)?;
    Some(
        endocast_io::open(&path, &OpenOptions::default())
            .unwrap()
            .volume,
    )
}

#[test]
fn every_scan_is_read_as_hu_shifted_hu_or_intensities() {
    let expected = [
        ("abdomen-ct-pancreas-dicom", Some(0.0), -500.0),
        ("chest-ct-airways-dicom", Some(0.0), -500.0),
        ("head-ct-ge-gantry-tilt/GE", Some(0.0), -500.0),
        ("head-ct-stanford-cthead/CThead.nhdr", Some(1024.0), 524.0),
        ("classic-vtk-headsq/quarter.nhdr", Some(1024.0), 524.0),
        // Otsu's background/object boundaries (README: 91 engine, 27.8 knee).
        ("classic-engine-ct/engine.nii.gz", None, 69.0),
        ("knee-mri/knee3D_dataR.mha", None, 24.0),
        ("brain-mri-t1/chris_t1.nii.gz", None, 56.0),
        ("brain-mri-flair-nrrd/FLAIR.nrrd", None, 61.0),
        ("aorta-stent-cta/stent.nrrd", None, 188.0),
    ];
    for (name, offset, wall) in expected {
        let Some(volume) = load(name) else { return };
        let scan = ScanValues::measure(&volume);
        let kind = offset.map_or(ValueKind::Intensity, |offset| ValueKind::Hounsfield {
            offset,
        });
        assert_eq!(scan.kind, kind, "{name}: {scan:?}");
        let iso = tissue::default_settings(&scan).iso_hu;
        assert!((iso - wall).abs() < 1.0, "{name}: wall at {iso}");
    }
}

/// The T1 with CSF and tissue swapped, background kept dark: a T2-like head.
fn t2_like(t1: &Volume) -> Volume {
    let voxels = t1
        .voxels()
        .iter()
        .map(|&v| if v < 10 { v } else { 255 - v.min(245) })
        .collect();
    Volume::new(
        *t1.geometry(),
        voxels,
        ValueMap::new(1.0, 0.0).unwrap(),
        t1.modality().clone(),
    )
    .unwrap()
}

/// The ventricles preset on `volume` with no point given: the resolved summary and the eye's
/// position and value.
fn ventricle_view(volume: &Volume) -> (String, DVec3, f64) {
    let scan = ScanValues::measure(volume);
    let resolved = tissue::resolve(Preset::find("ventricles").unwrap(), volume, &scan);
    let choice = LumenChoice {
        preset: Some(&resolved.preset),
        within: tissue::central_structure(&resolved.preset, volume, &scan),
        ..LumenChoice::default()
    };
    let view = default_view(volume, Some(&choice), 90.0);
    let DefaultView::InsideLumen {
        pose, threshold, ..
    } = view
    else {
        panic!("{view:?}");
    };
    let voxel = volume
        .geometry()
        .voxel_from_world()
        .transform_point3(pose.eye_mm);
    let value = volume.sample_physical(voxel).unwrap();
    eprintln!(
        "{}; grown at {threshold:.1}; eye {:.1} value {value:.0}",
        resolved.summary, pose.eye_mm
    );
    (resolved.summary, pose.eye_mm, value)
}

#[test]
fn the_ventricles_are_found_on_t1_flair_and_a_t2_like_head() {
    let Some(t1) = load("brain-mri-t1/chris_t1.nii.gz") else {
        return;
    };
    // Landmarks read from the T1 (bench/scenes.json's ventricle scene): the two lateral
    // ventricles' bodies lie near x = ±16, y = 32, z = 17 mm.
    let near_ventricle = |eye: DVec3| {
        [-16.0, 16.0]
            .iter()
            .any(|&x| eye.distance(DVec3::new(x, 32.0, 17.0)) < 12.0)
    };
    let (summary, eye, value) = ventricle_view(&t1);
    assert_eq!(summary, "ventricles: CSF < 75 (T1-like, dark)");
    assert!(value < 50.0 && near_ventricle(eye), "{value} at {eye}");
    let (summary, eye, value) = ventricle_view(&t2_like(&t1));
    assert!(
        summary.contains("CSF >") && summary.contains("T2-like, bright"),
        "{summary}"
    );
    assert!(value > 205.0 && near_ventricle(eye), "{value} at {eye}");
    let Some(flair) = load("brain-mri-flair-nrrd/FLAIR.nrrd") else {
        return;
    };
    let (summary, _, value) = ventricle_view(&flair);
    assert!(summary.contains("T1-like, dark"), "{summary}");
    assert!(value < 65.0, "{value}");
}

#[test]
fn the_airway_tree_is_found_on_the_chest_ct_without_the_lung() {
    let Some(chest) = load("chest-ct-airways-dicom") else {
        return;
    };
    let (tree, threshold) = find_trachea(&chest, -900.0).unwrap();
    let g = chest.geometry();
    let spacing = g.spacing_mm();
    let ml = tree.voxel_count() as f64 * spacing.x * spacing.y * spacing.z / 1000.0;
    let (lo, hi) = tree.bounds();
    let (lo_mm, hi_mm) = (
        g.world_of(DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64)),
        g.world_of(DVec3::new(hi[0] as f64, hi[1] as f64, hi[2] as f64)),
    );
    eprintln!("airway tree at {threshold}: {ml:.1} ml, {lo_mm:.1} to {hi_mm:.1} mm");
    // Measured: 34.7 ml at -900 HU, 142 mm top to bottom (the whole stack), 116 mm across
    // (x -61.5 to 54.7: both main and the lobar bronchi); the lungs hold litres.
    assert!(
        (20.0..=80.0).contains(&ml),
        "{ml} ml: the lung holds litres"
    );
    assert!((hi_mm.z - lo_mm.z).abs() > 100.0);
    let across = (hi_mm.x - lo_mm.x).abs();
    assert!((60.0..=160.0).contains(&across), "{across} mm across");
    // The same chest stored in sagittal slices (superior along `i`): the same tree.
    let sagittal = chest.with_axes([2, 0, 1]).unwrap();
    let (tree_s, threshold_s) = find_trachea(&sagittal, -900.0).unwrap();
    assert_eq!(
        (tree_s.voxel_count(), threshold_s),
        (tree.voxel_count(), threshold)
    );
    assert!(tree_s.voxels().all(|[a, b, c]| tree.contains([b, c, a])));
}

/// Issue 36: the abdomen CT has no oral contrast; the CT table's bright top under the air
/// beneath it and an enhanced bowel wall under gas gave three false pools.
#[test]
fn the_abdomen_ct_without_oral_contrast_has_no_pool_to_cleanse() {
    let Some(abdomen) = load("abdomen-ct-pancreas-dicom") else {
        return;
    };
    let cleansed = cleanse(&abdomen).unwrap();
    assert!(cleansed.pools.is_empty(), "{}", cleansed.summary());
    assert_eq!(cleansed.volume.voxels(), abdomen.voxels());
}

#[test]
fn head_cts_without_an_orientation_are_read_upright() {
    // CThead and headsq store their slices from the top of the head down (bench/scenes.json
    // gave them --orientation LPI); the guess from the anatomy finds it and says so.
    for name in [
        "head-ct-stanford-cthead/CThead.nhdr",
        "classic-vtk-headsq/quarter.nhdr",
    ] {
        let Some(path) = shared_data(name) else {
            return;
        };
        let loaded = endocast_io::open(&path, &OpenOptions::default()).unwrap();
        assert_eq!(loaded.volume.geometry().orientation_code(), "LPI", "{name}");
        assert!(
            loaded
                .warnings
                .iter()
                .any(|w| w.contains("guessed from the anatomy")),
            "{name}: {:?}",
            loaded.warnings
        );
        // Given, the orientation wins over the guess.
        let mut options = OpenOptions::default();
        options.orientation = Some("LPS".into());
        let given = endocast_io::open(&path, &options).unwrap();
        assert_eq!(given.volume.geometry().orientation_code(), "LPS", "{name}");
    }
    // The GE head declares its orientation: the guess agrees with it.
    let Some(ge) = load("head-ct-ge-gantry-tilt/GE") else {
        return;
    };
    let guess = endocast_core::navigate::guess_head_orientation(&ge).unwrap();
    let declared = ge.geometry().orientation_code();
    assert_eq!(guess.code[2..], declared[2..], "{}", guess.reason);
}
