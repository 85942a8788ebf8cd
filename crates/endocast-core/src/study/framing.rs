//! The whole object framed from outside: the start without a procedure in a lumen.

use crate::camera::{default_up, FOV_RANGE_DEG};
use crate::pose::Pose;
use crate::tissue::{object_points, object_world_extent, ScanValues};
use crate::Volume;
use glam::DVec3;

/// The share of stray object voxels left out on either side of each axis when the object's
/// extent is measured, and of object points left outside the framed view (noise, a stray
/// bright voxel in the air).
const STRAY: f64 = 0.002;
/// Room around the framed object, as a factor on the field of view it needs.
const MARGIN: f64 = 1.04;
/// The least distance from the camera to the object's nearest point, mm.
const CLEARANCE_MM: f64 = 1.0;

/// The world box (lowest and highest corner, LPS mm) around the object of `volume` (voxels
/// above `scan`'s background/object threshold, stray voxels left out); the whole volume when it
/// holds no object.
pub fn object_bounds(volume: &Volume, scan: &ScanValues) -> (DVec3, DVec3) {
    object_world_extent(volume, scan, STRAY).unwrap_or_else(|| volume.geometry().world_bounds())
}

/// A camera in front of the patient (anterior, −y in LPS) looking at the centre of the object
/// of `volume` (see [`object_bounds`]), as close as lets the object (all but a stray
/// [`STRAY`] of its points) fit the vertical field of view `fov_deg` of a square image with a
/// little room, whatever its shape: the distance each object point needs is measured, not
/// guessed from a box. Superior up.
pub fn object_framing(volume: &Volume, scan: &ScanValues, fov_deg: f64) -> Pose {
    let (lo, hi) = object_bounds(volume, scan);
    let centre = (lo + hi) / 2.0;
    let half_fov = (fov_deg.clamp(FOV_RANGE_DEG.0, FOV_RANGE_DEG.1) / 2.0).to_radians();
    let slope = half_fov.tan() / MARGIN;
    // A point at (dx, dy, dz) from the centre is in view from a camera at distance d on −y
    // when |dx| and |dz| are at most slope · (d + dy): d ≥ max(|dx|, |dz|) / slope − dy.
    let mut needs: Vec<f64> = Vec::new();
    object_points(volume, scan, |p| {
        let d = p - centre;
        needs.push(d.x.abs().max(d.z.abs()) / slope - d.y);
    });
    let front = centre.y - lo.y + CLEARANCE_MM;
    let distance = upper_quantile(&mut needs, STRAY)
        .unwrap_or(front)
        .max(front);
    let eye_mm = centre - DVec3::Y * distance;
    Pose {
        eye_mm,
        look_at_mm: centre,
        up: default_up(centre - eye_mm),
    }
}

/// The value that a share `q` of `values` lies above (reordering them); `None` when empty.
fn upper_quantile(values: &mut [f64], q: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let rank = ((values.len() - 1) as f64 * (1.0 - q)).round() as usize;
    let (_, value, _) = values.select_nth_unstable_by(rank, f64::total_cmp);
    Some(*value)
}
