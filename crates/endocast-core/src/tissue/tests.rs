use super::*;
use crate::navigate::LumenSide;
use crate::phantom::{Phantom, PhantomOptions};
use crate::presets::Preset;
use crate::{Geometry, Modality, ValueMap, Volume};
use glam::DVec3;

fn phantom(p: Phantom) -> Volume {
    p.build(&PhantomOptions {
        size: 48,
        ..Default::default()
    })
}

/// A volume of `dims` whose value at voxel `v` is `value(v)`, stored as is (`u8`-like scan).
fn synthetic(dims: [usize; 3], value: impl Fn([usize; 3]) -> u16) -> Volume {
    let mut voxels = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                voxels.push(value([i, j, k]));
            }
        }
    }
    let geometry = Geometry::axis_aligned(dims, DVec3::ONE, DVec3::ZERO).unwrap();
    let map = ValueMap::new(1.0, 0.0).unwrap();
    Volume::new(geometry, voxels, map, Modality::Unknown).unwrap()
}

/// A "head": background 0, a ball of tissue at 118 with two CSF "ventricles" (30) near the
/// centre. `t2` swaps CSF and tissue to 200 and 90.
fn brain(t2: bool) -> Volume {
    let (csf, tissue) = if t2 { (200, 90) } else { (30, 118) };
    synthetic([48, 48, 48], |[i, j, k]| {
        let p = DVec3::new(i as f64, j as f64, k as f64) - DVec3::splat(23.5);
        let ventricle = |x: f64| (p - DVec3::new(x, 0.0, 0.0)).length() < 3.5;
        if p.length() > 20.0 {
            0
        } else if ventricle(-4.0) || ventricle(4.0) {
            csf
        } else {
            tissue
        }
    })
}

#[test]
fn hounsfield_phantoms_are_recognised_and_unchanged() {
    for p in [Phantom::SphereShell, Phantom::Colon, Phantom::Sinus] {
        let volume = phantom(p);
        let scan = ScanValues::measure(&volume);
        assert_eq!(scan.kind, ValueKind::Hounsfield { offset: 0.0 }, "{p:?}");
        assert_eq!(scan.from_hounsfield(), LinearMap::IDENTITY);
        assert_eq!(
            default_settings(&scan),
            crate::render::RenderSettings::default()
        );
        let colonoscopy = Preset::find("colonoscopy").unwrap();
        let resolved = resolve(colonoscopy, &volume, &scan);
        assert_eq!(resolved.preset, *colonoscopy);
        assert_eq!(resolved.settings(), colonoscopy.settings());
        assert_eq!(resolved.summary, "colonoscopy: gas < -500 (CT in HU)");
    }
}

#[test]
fn hu_plus_1024_is_recognised_and_presets_shift_by_it() {
    // Air 24, a ball of soft tissue at 1064 with a bone shell at 2024 (HU + 1024).
    let shifted = synthetic([40, 40, 40], |[i, j, k]| {
        let r = (DVec3::new(i as f64, j as f64, k as f64) - DVec3::splat(19.5)).length();
        match r {
            r if r < 15.0 => 1064,
            r if r < 17.0 => 2024,
            _ => 24,
        }
    });
    let scan = ScanValues::measure(&shifted);
    assert_eq!(scan.kind, ValueKind::Hounsfield { offset: 1024.0 });
    assert_eq!(default_settings(&scan).iso_hu, 524.0);
    let sinus = Preset::find("sinus").unwrap();
    let resolved = resolve(sinus, &shifted, &scan);
    assert_eq!(resolved.preset.iso, 524.0);
    assert_eq!(resolved.preset.lumen.unwrap().threshold, 524.0);
    let tf = resolved.settings().tf;
    assert_eq!(tf.opacity_at(1424.0), sinus.settings().tf.opacity_at(400.0));
    assert_eq!(
        resolved.summary,
        "sinus: air < 524 (CT stored as HU + 1024)"
    );
    // A scan that says it is MR is never read as HU.
    let mr = Volume::new(
        *shifted.geometry(),
        shifted.voxels().to_vec(),
        shifted.value_map(),
        Modality::Mr,
    )
    .unwrap();
    assert_eq!(ScanValues::measure(&mr).kind, ValueKind::Intensity);
}

#[test]
fn an_intensity_scan_gets_its_wall_on_otsus_threshold() {
    let volume = brain(false);
    let scan = ScanValues::measure(&volume);
    assert_eq!(scan.kind, ValueKind::Intensity);
    assert!((scan.background, scan.object) == (0.0, 118.0), "{scan:?}");
    assert!(scan.object_threshold > 0.0 && scan.object_threshold < 118.0);
    let settings = default_settings(&scan);
    assert!((settings.iso_hu - scan.object_threshold).abs() < 1e-9);
    // The ramp still rises from the background to the object.
    assert_eq!(settings.tf.opacity_at(0.0), 0.0);
    assert!(settings.tf.opacity_at(118.0) > 0.9);
}

#[test]
fn csf_is_found_dark_on_t1_and_bright_on_t2() {
    let ventricles = Preset::find("ventricles").unwrap();
    for t2 in [false, true] {
        let volume = brain(t2);
        let scan = ScanValues::measure(&volume);
        let csf = measure_csf(&volume, &scan).unwrap();
        assert_eq!(csf.dark, !t2);
        let (c, t) = if t2 { (200.0, 90.0) } else { (30.0, 118.0) };
        assert_eq!((csf.csf, csf.tissue), (c, t));
        let resolved = resolve(ventricles, &volume, &scan);
        let lumen = resolved.preset.lumen.unwrap();
        let side = if t2 {
            LumenSide::Above
        } else {
            LumenSide::Below
        };
        assert_eq!(lumen.side, side);
        // The threshold lies between CSF and tissue, where the reference's 75 lies.
        assert!(side.holds(c, lumen.threshold) && !side.holds(t, lumen.threshold));
        let expected = if t2 {
            "T2-like, bright"
        } else {
            "T1-like, dark"
        };
        assert!(resolved.summary.contains(expected), "{}", resolved.summary);
        // The transfer function keeps CSF clear and makes tissue visible, either way round.
        let tf = resolved.settings().tf;
        assert_eq!(tf.opacity_at(c), 0.0);
        assert!(tf.opacity_at(t + 0.5 * (t - c)) > 0.0);
    }
}
