//! The colon with no seed: the largest gas-filled component inside the body. The air around the
//! patient reaches the volume's sides (left, right, front or back; the colon may be cut by the
//! top or bottom slice), and the lung is aerated tissue, not gas: most of its voxels lie well
//! above air's −1000 HU.

use super::lumen::{Lumen, LumenSide};
use crate::Volume;

/// How far below the lumen threshold a voxel counts as gas, physical units (HU): the colonoscopy
/// threshold −500 HU puts it at −950 HU, where lung parenchyma (−820…−950) is not.
pub const GAS_BELOW_THRESHOLD: f64 = 450.0;
/// The smallest share of gas voxels in a large component (a gas-filled lumen's rim of partial
/// volume is a thin shell; aerated lung is mostly above the gas level).
const MIN_GAS_SHARE: f64 = 0.5;
/// Components of at least this volume, mm³, must be mostly gas: lungs hold litres. Smaller
/// ones (a bowel pocket, a thin tube whose rim of partial volume is most of it) need not be.
const LARGE_MM3: f64 = 200_000.0;
/// Components tried, largest first.
const TRIES: usize = 12;
/// How far outside a component its surroundings are looked at, mm: beyond a bowel wall.
const SHELL_MM: f64 = 5.0;
/// The largest share of air (on the lumen side, not the component's own) at [`SHELL_MM`]
/// outside a component inside the body: a bowel loop is wrapped in tissue and fat, a hollow
/// in the scanner's table (its walls a few millimetres thick) in the air around it.
const MAX_AIR_AROUND: f64 = 0.25;

/// The colon below `threshold` (−500 HU): the largest of the largest components that does not
/// reach the volume's sides (the `i` and `j` faces), is wrapped in tissue (at most
/// [`MAX_AIR_AROUND`] of air [`SHELL_MM`] outside it: not a hollow in the table) and, when it
/// holds [`LARGE_MM3`] or more, is mostly gas (below `threshold −` [`GAS_BELOW_THRESHOLD`]):
/// not the lung. `None` when none is.
pub fn find_colon(volume: &Volume, threshold: f64) -> Option<Lumen> {
    let gas = threshold - GAS_BELOW_THRESHOLD;
    let dims = volume.dims();
    let s = volume.geometry().spacing_mm();
    let voxel_mm3 = s.x * s.y * s.z;
    let accept = |lumen: &Lumen| {
        let (lo, hi) = lumen.bounds();
        let at_side = (0..2).any(|a| lo[a] == 0 || hi[a] + 1 == dims[a]);
        let large = lumen.voxel_count() as f64 * voxel_mm3 >= LARGE_MM3;
        !at_side
            && (!large || gas_share(volume, lumen, gas) >= MIN_GAS_SHARE)
            && air_around(volume, lumen, threshold) <= MAX_AIR_AROUND
    };
    Lumen::largest_accepted(volume, threshold, LumenSide::Below, TRIES, accept)
        .ok()
        .flatten()
}

/// The share of the points [`SHELL_MM`] outside `lumen`'s surface (from each surface voxel
/// along each axis it faces the wall on, within the volume) that are air below `threshold`
/// and not the lumen's own.
fn air_around(volume: &Volume, lumen: &Lumen, threshold: f64) -> f64 {
    let dims = volume.dims();
    let spacing = volume.geometry().spacing_mm().to_array();
    let reach = spacing.map(|s| (SHELL_MM / s).ceil().max(1.0) as isize);
    let (mut air, mut all) = (0usize, 0usize);
    for v in lumen.voxels() {
        for (axis, sign) in (0..3).flat_map(|a| [(a, -1isize), (a, 1)]) {
            let at = |n: isize| {
                let mut w = v.map(|x| x as isize);
                w[axis] += sign * n;
                (w[axis] >= 0 && (w[axis] as usize) < dims[axis]).then(|| w.map(|x| x as usize))
            };
            let (Some(next), Some(out)) = (at(1), at(reach[axis])) else {
                continue;
            };
            if lumen.contains(next) {
                continue;
            }
            all += 1;
            let is_air = volume
                .physical(out[0], out[1], out[2])
                .is_some_and(|x| x < threshold);
            air += usize::from(is_air && !lumen.contains(out));
        }
    }
    air as f64 / all.max(1) as f64
}

/// The share of `lumen`'s voxels below `gas`.
fn gas_share(volume: &Volume, lumen: &Lumen, gas: f64) -> f64 {
    let below = lumen
        .voxels()
        .filter(|v| volume.physical(v[0], v[1], v[2]).is_some_and(|x| x < gas))
        .count();
    below as f64 / lumen.voxel_count().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};

    #[test]
    fn the_colon_phantom_is_found_and_not_the_air_outside() {
        let (volume, colon) = phantom::colon(&PhantomOptions {
            size: 64,
            ..Default::default()
        });
        let found = find_colon(&volume, -500.0).unwrap();
        let middle = colon
            .centreline
            .point_at(0.5 * colon.centreline.length_vox());
        let v = middle.round();
        assert!(found.contains([v.x as usize, v.y as usize, v.z as usize]));
        // A threshold below every gas voxel finds nothing.
        assert!(find_colon(&volume, -2000.0).is_none());
    }

    #[test]
    fn aerated_lung_and_the_air_at_the_sides_are_passed_over() {
        // Tissue (40 HU, stored 1040) with a large "lung" box at −850 HU, a smaller gas box at
        // −1000 HU, and the largest, a slab of air along the i = 0 side; voxels of 3 mm, so
        // that the lung holds 260 ml.
        let dims = [40, 30, 20];
        let mut voxels = vec![1040u16; dims[0] * dims[1] * dims[2]];
        for k in 1..19 {
            for j in 1..29 {
                for i in 0..40 {
                    let value = match i {
                        0..=9 => 0,
                        12..=30 => 150,
                        33..=37 if (10..20).contains(&j) && (5..15).contains(&k) => 0,
                        _ => continue,
                    };
                    voxels[i + dims[0] * (j + dims[1] * k)] = value;
                }
            }
        }
        let g = crate::Geometry::axis_aligned(dims, glam::DVec3::splat(3.0), glam::DVec3::ZERO)
            .unwrap();
        let map = crate::ValueMap::new(1.0, -1000.0).unwrap();
        let volume = Volume::new(g, voxels, map, crate::Modality::Ct).unwrap();
        let colon = find_colon(&volume, -500.0).unwrap();
        assert!(colon.contains([35, 15, 10]) && colon.voxel_count() == 5 * 10 * 10);
    }

    #[test]
    fn a_gas_tube_in_the_body_is_chosen_over_a_larger_hollow_in_the_table() {
        // Air (−1000 HU, stored 24) around a body (an ellipse of tissue, 40 HU) lying on a
        // table (plastic, 100 HU, walls 4 mm thick) whose hollow holds more gas than the
        // colon: a tube of 3 voxels' radius along k inside the body; voxels of 2 mm.
        let dims = [48, 40, 30];
        let mut voxels = vec![24u16; dims[0] * dims[1] * dims[2]];
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let (x, y) = (i as f64 - 24.0, j as f64 - 14.0);
                    let body = (x / 20.0).powi(2) + (y / 12.0).powi(2) <= 1.0;
                    let colon = x.hypot(y) <= 3.0 && (5..25).contains(&k);
                    let table = (4..44).contains(&i) && (30..38).contains(&j);
                    let hollow =
                        (6..42).contains(&i) && (32..36).contains(&j) && (2..28).contains(&k);
                    let value = match () {
                        _ if body && !colon => 1064,
                        _ if table && !hollow => 1124,
                        _ => continue,
                    };
                    voxels[i + dims[0] * (j + dims[1] * k)] = value;
                }
            }
        }
        let g = crate::Geometry::axis_aligned(dims, glam::DVec3::splat(2.0), glam::DVec3::ZERO)
            .unwrap();
        let map = crate::ValueMap::new(1.0, -1024.0).unwrap();
        let volume = Volume::new(g, voxels, map, crate::Modality::Ct).unwrap();
        // The largest gas inside the field of view is the table's hollow.
        let largest = Lumen::largest(&volume, -500.0, LumenSide::Below, true)
            .unwrap()
            .unwrap();
        assert!(largest.contains([24, 34, 15]));
        let colon = find_colon(&volume, -500.0).unwrap();
        assert!(colon.contains([24, 14, 15]) && !colon.contains([24, 34, 15]));
    }
}
