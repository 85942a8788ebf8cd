//! Whether a point lies in the air around the body: air joined to the border of its slice
//! across the body's long axis. Lungs and airways are enclosed by the chest wall in such a slice
//! (the trachea too, though it opens at the scan's top), so they count as inside.

use crate::Volume;
use glam::DVec3;
use std::collections::VecDeque;

/// Whether `p_mm` (world mm, inside the volume) lies in air outside the body: its voxel is below
/// `threshold` and joined, through voxels below it, to the border of its slice across the index
/// axis nearest the world's superior axis.
pub(super) fn outside_body(volume: &Volume, p_mm: DVec3, threshold: f64) -> bool {
    let g = volume.geometry();
    let v = g.voxel_from_world().transform_point3(p_mm).round();
    let dims = volume.dims();
    let voxel = [v.x, v.y, v.z].map(|c| c.max(0.0) as usize);
    if (0..3).any(|a| voxel[a] >= dims[a]) {
        return false;
    }
    let across = long_axis(volume);
    let plane: Vec<usize> = (0..3).filter(|&a| a != across).collect();
    let air = |w: [usize; 3]| {
        volume
            .physical(w[0], w[1], w[2])
            .is_some_and(|x| x < threshold)
    };
    if !air(voxel) {
        return false;
    }
    let (a, b) = (plane[0], plane[1]);
    let mut seen = vec![false; dims[a] * dims[b]];
    let mut queue = VecDeque::from([voxel]);
    seen[voxel[a] + dims[a] * voxel[b]] = true;
    while let Some(w) = queue.pop_front() {
        if w[a] == 0 || w[b] == 0 || w[a] + 1 == dims[a] || w[b] + 1 == dims[b] {
            return true;
        }
        for (da, db) in [(1isize, 0isize), (-1, 0), (0, 1), (0, -1)] {
            let mut n = w;
            n[a] = w[a].wrapping_add_signed(da);
            n[b] = w[b].wrapping_add_signed(db);
            let index = n[a] + dims[a] * n[b];
            if !seen[index] && air(n) {
                seen[index] = true;
                queue.push_back(n);
            }
        }
    }
    false
}

/// The index axis nearest the world's superior axis: the body's long axis, along which the
/// trachea runs.
pub(super) fn long_axis(volume: &Volume) -> usize {
    let m = volume.geometry().world_from_voxel().matrix3;
    (0..3)
        .max_by(|&a, &b| m.col(a).z.abs().total_cmp(&m.col(b).z.abs()))
        .unwrap_or(2)
}
