//! Small volumes with awkward geometry and values, shared by the writer round-trip tests.

// Helpers panic on failure like the tests that call them.
#![allow(clippy::unwrap_used)]

use endocast_core::{Geometry, Modality, ValueMap, Volume};
use glam::{DMat3, DQuat, DVec3, EulerRot};

const DIMS: [usize; 3] = [7, 5, 4];

/// A deterministic pattern of stored values in `0..=modulus`.
fn pattern(modulus: usize) -> Vec<u16> {
    (0..DIMS.iter().product::<usize>())
        .map(|n| ((n * 7919 + 13) % (modulus + 1)) as u16)
        .collect()
}

fn volume(direction: DMat3, map: ValueMap, modulus: usize) -> Volume {
    let geometry = Geometry::new(
        DIMS,
        DVec3::new(0.7, 0.85, 1.5),
        DVec3::new(-120.5, 33.25, 80.0),
        direction,
    )
    .unwrap();
    Volume::new(geometry, pattern(modulus), map, Modality::Ct).unwrap()
}

/// CT-like HU values (−1024…2000, stored with offset −1024) on an oblique, orthogonal grid.
pub fn oblique_ct() -> Volume {
    let rotation = DMat3::from_quat(DQuat::from_euler(EulerRot::ZYX, 0.4, -0.25, 0.15));
    volume(rotation, ValueMap::new(1.0, -1024.0).unwrap(), 3024)
}

/// The same values on a sheared grid: the slice axis tilted 20° like a CT gantry tilt.
pub fn sheared_ct() -> Volume {
    let tilt = 20f64.to_radians();
    let direction = DMat3::from_cols(DVec3::X, DVec3::Y, DVec3::new(0.0, tilt.sin(), tilt.cos()));
    volume(direction, ValueMap::new(1.0, -1024.0).unwrap(), 3024)
}

/// Values with a non-unit scale and fractional offset (both exact in float32), axis-aligned.
pub fn scaled_volume() -> Volume {
    volume(DMat3::IDENTITY, ValueMap::new(0.5, -100.25).unwrap(), 60000)
}

/// Same dims; geometry within 1e-5; every voxel's physical value within `tolerance`.
pub fn assert_same_volume(actual: &Volume, expected: &Volume, tolerance: f64) {
    let (a, e) = (actual.geometry(), expected.geometry());
    assert_eq!(a.dims(), e.dims());
    assert!(
        a.spacing_mm().abs_diff_eq(e.spacing_mm(), 1e-5),
        "spacing {} vs {}",
        a.spacing_mm(),
        e.spacing_mm()
    );
    assert!(
        a.origin_mm().abs_diff_eq(e.origin_mm(), 1e-5),
        "origin {} vs {}",
        a.origin_mm(),
        e.origin_mm()
    );
    assert!(
        a.direction().abs_diff_eq(e.direction(), 1e-5),
        "direction {} vs {}",
        a.direction(),
        e.direction()
    );
    let [ni, nj, nk] = e.dims();
    for k in 0..nk {
        for j in 0..nj {
            for i in 0..ni {
                let (x, y) = (
                    actual.physical(i, j, k).unwrap(),
                    expected.physical(i, j, k).unwrap(),
                );
                assert!(
                    (x - y).abs() <= tolerance,
                    "voxel ({i},{j},{k}): {x} vs {y}"
                );
            }
        }
    }
}
