//! Tests shared by all phantoms, and helpers for the per-phantom tests.

use super::profile::{AIR_HU, TISSUE_HU};
use super::*;
use crate::{Modality, ValueMap};
use glam::DVec3;

/// Options for a small test volume.
pub(super) fn small(size: usize) -> PhantomOptions {
    PhantomOptions {
        size,
        ..Default::default()
    }
}

/// The distance `t ∈ [t_in, t_out]` along `from + t · dir` where the trilinear value crosses
/// `iso_hu`, by bisection (the values at the two ends must lie on either side).
pub(super) fn iso_crossing(
    volume: &Volume,
    from: DVec3,
    dir: DVec3,
    (mut t_in, mut t_out): (f64, f64),
    iso_hu: f64,
) -> f64 {
    let value = |t: f64| volume.sample_physical(from + dir * t).unwrap() - iso_hu;
    let sign_in = value(t_in).signum();
    assert_ne!(
        sign_in,
        value(t_out).signum(),
        "no crossing of {iso_hu} HU on the ray"
    );
    for _ in 0..60 {
        let mid = 0.5 * (t_in + t_out);
        if value(mid).signum() == sign_in {
            t_in = mid;
        } else {
            t_out = mid;
        }
    }
    0.5 * (t_in + t_out)
}

/// A deterministic pseudo-random unit vector (index `n`).
pub(super) fn direction(n: u64) -> DVec3 {
    let g = |c: u64| noise::gaussian(99, 3 * n + c);
    DVec3::new(g(0), g(1), g(2)).normalize()
}

/// A unit vector perpendicular to unit `axis`, at `angle` around it.
pub(super) fn perpendicular(axis: DVec3, angle: f64) -> DVec3 {
    let reference = axis.any_orthonormal_vector();
    reference * angle.cos() + axis.cross(reference) * angle.sin()
}

const MID_AIR_TISSUE_HU: f64 = 0.5 * (AIR_HU + TISSUE_HU);

#[test]
fn names_round_trip_and_describe() {
    for phantom in Phantom::ALL {
        assert_eq!(Phantom::from_name(phantom.name()), Some(phantom));
        assert!(!phantom.description().is_empty());
    }
    assert_eq!(
        Phantom::from_name("Sphere-Shell"),
        Some(Phantom::SphereShell)
    );
    assert_eq!(Phantom::from_name("sphere_shell"), None);
}

#[test]
fn volumes_follow_the_shared_conventions() {
    for phantom in Phantom::ALL {
        let volume = phantom.build(&small(20));
        let dims = volume.dims();
        assert_eq!(dims.iter().max(), Some(&20), "{}", phantom.name());
        let g = volume.geometry();
        assert_eq!(g.spacing_mm(), DVec3::ONE);
        let centre = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) / 2.0 - 0.5;
        assert!(g.world_of(centre).length() < 1e-12);
        assert_eq!(g.orientation_code(), "LPS");
        assert_eq!(volume.value_map(), ValueMap::new(1.0, -1024.0).unwrap());
        assert_eq!(volume.modality(), &Modality::Ct);
    }
    assert_eq!(Phantom::Colon.build(&small(64)).dims(), [64, 64, 60]);
    assert_eq!(Phantom::SphereShell.build(&small(0)).dims(), [8, 8, 8]);
}

#[test]
fn same_seed_same_voxels_other_seed_other_noise() {
    let noisy = |seed| PhantomOptions {
        size: 24,
        noise_hu: 20.0,
        seed,
        ..Default::default()
    };
    for phantom in Phantom::ALL {
        let a = phantom.build(&noisy(5));
        assert_eq!(a.voxels(), phantom.build(&noisy(5)).voxels());
        assert_ne!(a.voxels(), phantom.build(&noisy(6)).voxels());
        assert_ne!(a.voxels(), phantom.build(&small(24)).voxels());
    }
}

#[test]
fn noise_has_the_requested_spread() {
    // The straight tube's tissue is flat: its noisy voxels there have σ ≈ noise_hu.
    let options = PhantomOptions {
        size: 40,
        noise_hu: 25.0,
        seed: 3,
        ..Default::default()
    };
    let volume = Phantom::StraightTube.build(&options);
    let corner: Vec<f64> = (0..8)
        .flat_map(|j| (0..8).map(move |i| (i, j)))
        .map(|(i, j)| volume.physical(i, j, 20).unwrap() - TISSUE_HU)
        .collect();
    let variance = corner.iter().map(|v| v * v).sum::<f64>() / corner.len() as f64;
    assert!(
        (variance.sqrt() - 25.0).abs() < 6.0,
        "σ = {}",
        variance.sqrt()
    );
    let no_noise = PhantomOptions {
        noise_hu: f64::NAN,
        ..options
    };
    assert_eq!(
        Phantom::StraightTube.build(&no_noise).physical(0, 0, 0),
        Some(TISSUE_HU)
    );
}

#[test]
fn voxels_do_not_depend_on_the_thread_count() {
    let options = PhantomOptions {
        size: 40,
        noise_hu: 15.0,
        seed: 11,
        ..Default::default()
    };
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    for phantom in Phantom::ALL {
        let serial = one_thread.install(|| phantom.build(&options));
        assert_eq!(
            serial.voxels(),
            phantom.build(&options).voxels(),
            "{}",
            phantom.name()
        );
    }
}

#[test]
fn sphere_shell_isosurfaces_sit_on_the_analytic_radii() {
    let (volume, shell) = sphere_shell(&small(64));
    let middle = 0.5 * (shell.inner_radius_vox + shell.outer_radius_vox);
    let mut worst: f64 = 0.0;
    for n in 0..200 {
        let dir = direction(n);
        let inner = iso_crossing(
            &volume,
            shell.centre_vox,
            dir,
            (shell.inner_radius_vox - 2.0, middle),
            MID_AIR_TISSUE_HU,
        );
        let outer = iso_crossing(
            &volume,
            shell.centre_vox,
            dir,
            (middle, shell.outer_radius_vox + 1.2),
            MID_AIR_TISSUE_HU,
        );
        worst = worst
            .max((inner - shell.inner_radius_vox).abs())
            .max((outer - shell.outer_radius_vox).abs());
    }
    assert!(worst < 0.02, "worst radius error {worst} voxel");
}

#[test]
fn straight_tube_isosurface_sits_on_the_analytic_radius() {
    let (volume, tube) = straight_tube(&small(64));
    let axis = tube.centreline.tangent_at(0.0);
    let mut worst: f64 = 0.0;
    for n in 0..200u32 {
        let s = 3.0 + (tube.centreline.length_vox() - 6.0) * (f64::from(n) / 200.0);
        let from = tube.centreline.point_at(s);
        let dir = perpendicular(axis, f64::from(n) * 0.37);
        let r = iso_crossing(
            &volume,
            from,
            dir,
            (0.0, tube.radius_vox + 3.0),
            MID_AIR_TISSUE_HU,
        );
        worst = worst.max((r - tube.radius_vox).abs());
    }
    assert!(worst < 0.02, "worst radius error {worst} voxel");
}
