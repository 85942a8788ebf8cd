//! A point picked by hand (a click in a slice) moved into the lumen: the nearest voxel of the
//! lumen within a small radius (the planner's [`super::snap_radius_mm`] suits), so that a click meant for a bronchus that lands on its wall or
//! beside it still puts the endoscope inside.

use super::lumen::{Lumen, LumenSide};
use super::plan::seed_voxel;
use crate::Volume;
use glam::DVec3;

/// `p_mm` itself when its nearest voxel lies in the lumen, else the world position (mm) of
/// the voxel nearest `p_mm`, within `radius_mm`, that does: in `structure` when given (the
/// study's airway tree, aorta, …), else on `side` of `threshold`. `None` when there is none
/// that near (or `p_mm` is not finite).
pub fn nearest_lumen_point(
    volume: &Volume,
    p_mm: DVec3,
    (threshold, side): (f64, LumenSide),
    structure: Option<&Lumen>,
    radius_mm: f64,
) -> Option<DVec3> {
    let geometry = volume.geometry();
    let centre = geometry.voxel_from_world().transform_point3(p_mm);
    if !centre.is_finite() {
        return None;
    }
    let reach = (DVec3::splat(radius_mm) / geometry.spacing_mm()).ceil();
    let dims = volume.dims();
    let range = |axis: usize| {
        let lo = (centre[axis] - reach[axis]).max(0.0);
        let hi = (centre[axis] + reach[axis]).min(dims[axis] as f64 - 1.0);
        (lo.ceil() as usize)..=(hi.max(-1.0).floor().max(0.0) as usize)
    };
    let inside = |v: [usize; 3]| match structure {
        Some(lumen) => lumen.contains(v),
        None => volume
            .physical(v[0], v[1], v[2])
            .is_some_and(|value| side.holds(value, threshold)),
    };
    if seed_voxel(volume, p_mm).is_ok_and(inside) {
        return Some(p_mm);
    }
    let mut best: Option<(f64, DVec3)> = None;
    for k in range(2) {
        for j in range(1) {
            for i in range(0) {
                let world = geometry.world_of(DVec3::new(i as f64, j as f64, k as f64));
                let d = world.distance(p_mm);
                if d <= radius_mm && best.is_none_or(|(b, _)| d < b) && inside([i, j, k]) {
                    best = Some((d, world));
                }
            }
        }
    }
    best.map(|(_, world)| world)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{straight_tube, PhantomOptions};

    #[test]
    fn a_point_in_the_wall_moves_to_the_nearest_lumen_voxel_and_one_far_away_does_not() {
        let (volume, tube) = straight_tube(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        let g = volume.geometry();
        let axis = tube.centreline.points()[0] + DVec3::Z * 16.0;
        let world = |v: DVec3| g.world_of(v);
        let lumen = (-500.0, LumenSide::Below);
        let voxel = g.spacing_mm().x;
        // On the axis: stays, exactly.
        let on_axis = world(axis + DVec3::splat(0.3));
        let snapped = nearest_lumen_point(&volume, on_axis, lumen, None, 5.0);
        assert_eq!(snapped, Some(on_axis));
        // Two voxels beyond the wall: moved back into the tube, about two voxels.
        let outside = world(axis + DVec3::X * (tube.radius_vox + 2.0));
        let snapped = nearest_lumen_point(&volume, outside, lumen, None, 5.0).unwrap();
        let off_axis = (g.voxel_from_world().transform_point3(snapped) - axis).length();
        assert!(off_axis < tube.radius_vox, "{off_axis}");
        assert!(
            snapped.distance(outside) < 3.5 * voxel,
            "{}",
            snapped.distance(outside)
        );
        // Too far for the radius: none.
        let far = world(axis + DVec3::X * (tube.radius_vox + 12.0));
        assert_eq!(
            nearest_lumen_point(&volume, far, lumen, None, 5.0 * voxel),
            None
        );
        assert_eq!(
            nearest_lumen_point(&volume, DVec3::NAN, lumen, None, 5.0),
            None
        );
    }
}
