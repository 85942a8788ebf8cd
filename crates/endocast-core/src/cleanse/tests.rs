//! Cleansing against the colon phantom with and without its tagged pools.

use super::*;
use crate::phantom::{self, Colon, Phantom, PhantomOptions};
use glam::DVec3;

/// The wall isovalue: halfway between air and soft tissue, where the phantoms put their surfaces.
const WALL_ISO_HU: f64 = 0.5 * (AIR_HU + SOFT_TISSUE_HU);
/// Step of the march for the first crossing along a ray, voxels.
const MARCH_VOX: f64 = 0.1;

fn colon_phantom(size: usize, tagged_fluid: bool) -> (Volume, Colon) {
    phantom::colon(&PhantomOptions {
        size,
        tagged_fluid,
        ..Default::default()
    })
}

/// The first distance along `from + t · dir` where the trilinear value rises above the wall's
/// isovalue (what a ray caster's first hit finds), refined by bisection; `None` within `max`.
fn first_hit(volume: &Volume, from: DVec3, dir: DVec3, max: f64) -> Option<f64> {
    let above = |t: f64| volume.sample_physical(from + dir * t).unwrap() > WALL_ISO_HU;
    let mut t = 0.0;
    while t < max {
        if above(t + MARCH_VOX) {
            let (mut lo, mut hi) = (t, t + MARCH_VOX);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                (lo, hi) = if above(mid) { (lo, mid) } else { (mid, hi) };
            }
            return Some(0.5 * (lo + hi));
        }
        t += MARCH_VOX;
    }
    None
}

/// Rays from the axis of the middle third of each pool to its submerged wall: straight down
/// (+j) and up to 40° either side of it, across the axis.
fn rays_into_pools(colon: &Colon) -> Vec<(DVec3, DVec3)> {
    let line = &colon.centreline;
    let mut rays = Vec::new();
    for pool in &colon.pools {
        let (a, b) = pool.arc_vox;
        for n in 0..12 {
            let s = a + (b - a) * (1.0 + f64::from(n)) / 13.0 * 0.33 + (b - a) / 3.0;
            let tangent = line.tangent_at(s);
            let down = (DVec3::Y - tangent * tangent.y).normalize();
            let side = tangent.cross(down);
            for angle in [-40f64, -20.0, 0.0, 20.0, 40.0] {
                let angle = angle.to_radians();
                rays.push((line.point_at(s), down * angle.cos() + side * angle.sin()));
            }
        }
    }
    rays
}

#[test]
fn the_wall_under_a_pool_is_where_it_is_without_fluid_and_not_uncleansed() {
    let (dry, _) = colon_phantom(192, false);
    let (wet, colon) = colon_phantom(192, true);
    assert!(colon.pools.len() >= 2, "{} pools", colon.pools.len());
    let cleansed = cleanse(&wet).unwrap();
    // A fold can split a pool where it is shallow: as many pools found or more, and no tag left.
    assert!(
        cleansed.pools.len() >= colon.pools.len(),
        "{}",
        cleansed.summary()
    );
    let brightest = cleansed.volume.physical_range().1;
    assert!(brightest < TAG_THRESHOLD_HU, "{brightest} HU left");
    let reach = 2.0 * colon.max_radius_vox();
    let (mut worst, mut closest_uncleansed) = (0.0f64, f64::INFINITY);
    let rays = rays_into_pools(&colon);
    for &(from, dir) in &rays {
        let truth = first_hit(&dry, from, dir, reach).expect("the dry wall");
        let seen = first_hit(&cleansed.volume, from, dir, reach).expect("the cleansed wall");
        let level = first_hit(&wet, from, dir, reach).expect("the pool's surface");
        worst = worst.max((seen - truth).abs());
        closest_uncleansed = closest_uncleansed.min(truth - level);
    }
    // Phantom voxels are 1 mm.
    assert!(
        worst < 0.5,
        "worst wall depth error {worst} mm over {} rays",
        rays.len()
    );
    assert!(
        closest_uncleansed > 2.0,
        "uncleansed, a ray stopped {closest_uncleansed} mm short of the wall only"
    );
}

#[test]
fn scans_without_tagged_fluid_under_air_are_left_as_they_are() {
    for phantom in [
        Phantom::Colon,
        Phantom::Vessel,
        Phantom::Joint,
        Phantom::Sinus,
    ] {
        let volume = phantom.build(&PhantomOptions {
            size: 64,
            ..Default::default()
        });
        let cleansed = cleanse(&volume).unwrap();
        assert!(
            cleansed.pools.is_empty(),
            "{}: {}",
            phantom.name(),
            cleansed.summary()
        );
        assert_eq!(
            cleansed.volume.voxels(),
            volume.voxels(),
            "{}",
            phantom.name()
        );
    }
}

/// `volume` turned over: its `j` rows reversed in the same geometry, so what lay posterior lies
/// anterior.
fn turned_over(volume: &Volume) -> Volume {
    let [nx, ny, _] = volume.dims();
    let voxels: Vec<u16> = volume
        .voxels()
        .chunks_exact(nx * ny)
        .flat_map(|slice| slice.chunks_exact(nx).rev().flatten().copied())
        .collect();
    Volume::new(
        *volume.geometry(),
        voxels,
        volume.value_map(),
        volume.modality().clone(),
    )
    .unwrap()
}

#[test]
fn a_prone_scan_has_its_pools_on_the_other_side_and_an_mr_is_refused() {
    let (wet, _) = colon_phantom(96, true);
    let supine = cleanse(&wet).unwrap();
    let prone = cleanse(&turned_over(&wet)).unwrap();
    assert!(!supine.pools.is_empty());
    assert_eq!(prone.pools.len(), supine.pools.len());
    assert!(supine.pools.iter().all(|p| p.gravity.sign == 1));
    assert!(prone.pools.iter().all(|p| p.gravity.sign == -1));
    assert_eq!(turned_over(&prone.volume).voxels(), supine.volume.voxels());
    let mr = Volume::new(
        *wet.geometry(),
        wet.voxels().to_vec(),
        wet.value_map(),
        Modality::from_code("MR"),
    )
    .unwrap();
    assert_eq!(cleanse(&mr).unwrap_err(), CleanseError::NotHounsfield);
}

#[test]
fn cleanse_names() {
    assert_eq!(Cleanse::from_name(" ON "), Some(Cleanse::On));
    assert_eq!(Cleanse::from_name("off"), Some(Cleanse::Off));
    assert_eq!(Cleanse::from_name("auto"), None);
    assert_eq!(Cleanse::default(), Cleanse::Off);
}
