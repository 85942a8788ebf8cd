//! A flight path through a lumen in one call: the centred minimal path between two points (or
//! to the farthest point), smoothed into a camera [`Path`] that provably stays in the lumen.

use super::centreline::{centreline, CentrelinePath, PathEnd};
use super::distance::DistanceField;
use super::error::NavError;
use super::lumen::{Lumen, LumenSide};
use crate::path::{Path, SmoothOptions};
use crate::Volume;
use glam::DVec3;

/// A planned flight: the smooth path, the raw centreline it came from and how much room the
/// camera has along it.
#[derive(Debug, Clone)]
pub struct PlannedPath {
    /// The smoothed path (constant step, rotation-minimising frames).
    pub path: Path,
    /// The raw centred path over voxel centres.
    pub raw: CentrelinePath,
    /// Smallest distance from the smoothed path to the wall, mm.
    pub min_radius_mm: f64,
    /// Mean distance from the smoothed path to the wall, mm.
    pub mean_radius_mm: f64,
}

/// The lumen around `start_mm` (world mm) on `side` of `threshold`, its distance field and the
/// planned path (refused with [`NavError::LumenLeaks`] before any search when the lumen leaks
/// out of the structure, see [`Lumen::leak`]) from `start_mm` to `end`, smoothed with `options` and re-smoothed more tightly
/// until it stays inside the lumen (see [`smooth_centreline`]).
pub fn plan_path(
    volume: &Volume,
    threshold: f64,
    side: LumenSide,
    start_mm: DVec3,
    end: PathEnd,
    options: &SmoothOptions,
) -> Result<(Lumen, DistanceField, PlannedPath), NavError> {
    let seed = seed_voxel(volume, start_mm)?;
    let lumen = Lumen::from_seed(volume, seed, threshold, side)?;
    let (field, planned) = plan_in(volume, &lumen, start_mm, end, options)?;
    Ok((lumen, field, planned))
}

/// [`plan_path`] in a lumen already found (a structure cut out of a larger lumen, such as the
/// aorta): refused with [`NavError::LumenLeaks`] before any search when it leaks, else its
/// distance field and the planned path, which stays inside it.
pub fn plan_in(
    volume: &Volume,
    lumen: &Lumen,
    start_mm: DVec3,
    end: PathEnd,
    options: &SmoothOptions,
) -> Result<(DistanceField, PlannedPath), NavError> {
    if let Some(leak) = lumen.leak() {
        return Err(leak);
    }
    let field = DistanceField::new(lumen, volume.geometry());
    let planned = smooth_centreline(volume, lumen, &field, start_mm, end, options)?;
    Ok((field, planned))
}

/// [`centreline`] from `start_mm` to `end`, smoothed until every sample stays a quarter voxel
/// inside the lumen (a quarter of the raw path's own clearance where that is smaller). A quarter,
/// not more: between two diagonal neighbours next to the wall the interpolated distance is half
/// a voxel, so a stricter test would refuse even the raw path through a narrow vessel.
pub fn smooth_centreline(
    volume: &Volume,
    lumen: &Lumen,
    field: &DistanceField,
    start_mm: DVec3,
    end: PathEnd,
    options: &SmoothOptions,
) -> Result<PlannedPath, NavError> {
    let raw = centreline(volume, lumen, field, start_mm, end)?;
    smooth_raw(field, raw, options)
}

/// A raw centreline (voxel centres of `field`'s lumen) smoothed with `options` until every
/// sample stays a quarter voxel inside the lumen (see [`smooth_centreline`]).
pub fn smooth_raw(
    field: &DistanceField,
    raw: CentrelinePath,
    options: &SmoothOptions,
) -> Result<PlannedPath, NavError> {
    let clearance = 0.25 * field.min_spacing_mm().min(raw.min_distance_mm);
    let inside = |path: &Path| {
        path.samples()
            .iter()
            .all(|s| field.distance_mm(s.position_mm) >= clearance)
    };
    let path = Path::smooth_until(&raw.points_mm, options, inside)?;
    let radii: Vec<f64> = path
        .samples()
        .iter()
        .map(|s| field.distance_mm(s.position_mm))
        .collect();
    let min_radius_mm = radii.iter().copied().fold(f64::INFINITY, f64::min);
    let mean_radius_mm = radii.iter().sum::<f64>() / radii.len().max(1) as f64;
    Ok(PlannedPath {
        path,
        raw,
        min_radius_mm,
        mean_radius_mm,
    })
}

/// The voxel nearest world point `p_mm`, or [`NavError::PointOutside`].
pub fn seed_voxel(volume: &Volume, p_mm: DVec3) -> Result<[usize; 3], NavError> {
    let outside = || NavError::PointOutside {
        point_mm: p_mm.to_array(),
    };
    let v = volume
        .geometry()
        .voxel_from_world()
        .transform_point3(p_mm)
        .round();
    let dims = volume.dims();
    let mut index = [0usize; 3];
    for axis in 0..3 {
        let x = v[axis];
        // Written so that NaN fails too.
        if !(x >= 0.0 && x < dims[axis] as f64) {
            return Err(outside());
        }
        index[axis] = x as usize;
    }
    Ok(index)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};

    #[test]
    fn the_colon_path_runs_end_to_end_inside_the_lumen_without_twisting() {
        let (volume, colon) = phantom::colon(&PhantomOptions {
            size: 96,
            ..Default::default()
        });
        let g = volume.geometry();
        let line = &colon.centreline;
        let start = g.world_of(line.point_at(0.0));
        let end = g.world_of(line.point_at(line.length_vox()));
        let options = SmoothOptions::default();
        let (_, field, planned) = plan_path(
            &volume,
            -480.0,
            LumenSide::Below,
            start,
            PathEnd::Point(end),
            &options,
        )
        .unwrap();
        assert!(planned.min_radius_mm >= 0.5, "{}", planned.min_radius_mm);
        let samples = planned.path.samples();
        assert!((samples[0].position_mm - start).length() < 2.0);
        assert!((samples[samples.len() - 1].position_mm - end).length() < 2.0);
        for s in samples {
            assert!(field.distance_mm(s.position_mm) >= 0.5);
        }
        for pair in samples.windows(2) {
            let turn = pair[0]
                .up
                .dot(pair[1].up)
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees();
            assert!(turn < 5.0, "up turned {turn}° in one step");
        }
    }

    #[test]
    fn points_outside_the_volume_or_nan_are_refused() {
        let (volume, _) = phantom::straight_tube(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        for p in [DVec3::splat(1e6), DVec3::NAN] {
            let error = seed_voxel(&volume, p).unwrap_err();
            assert!(matches!(error, NavError::PointOutside { .. }));
        }
    }
}
