//! The wall a flight never showed, split into connected patches, each with its area and
//! centroid: what a reader reviews after the flight (Pickhardt et al.: reviewing the missed
//! regions of 300 mm² or more brings a two-way flight from about 94 % to about 98 %).
//!
//! **Connectivity**: the wall is a one-voxel shell (non-lumen voxels 6-adjacent to the lumen).
//! Where the surface runs obliquely the shell steps diagonally: two consecutive wall voxels of
//! a smooth surface then share only an edge or a corner. Face (6-) connectivity would cut such a
//! surface into stair-step strips, so patches are **26-connected**. The price: two unseen
//! regions on either side of a fold thinner than about two voxels may join into one patch.
//!
//! **Area**: each wall voxel contributes the lumen-facing faces it has (the digital surface
//! between lumen and wall), divided by `|n_x| + |n_y| + |n_z|`, the sum of the absolute
//! components of the local surface normal `n` along the grid's axes. A plane of normal `n`
//! crosses `|n_a|` of face area normal to axis `a` per unit of its own area, so the faces
//! overcount a smooth surface by that sum (1 for a face-aligned wall, up to √3 diagonally: the
//! standard correction of digital surface area, here with a local normal instead of the
//! isotropic mean 3/2). The normal is the mean direction from the voxel to the lumen voxels
//! within [`NORMAL_REACH`] voxels (a ball, so that it has no preferred axis).
//!
//! **Extent**: a region wider than one view can show (the wall missed along a whole side of a
//! coarse colon is one connected region) may be listed in pieces of a given reach, each with
//! its own view.

use super::Coverage;
use glam::DVec3;

/// Radius of the ball of voxels whose lumen members give a wall voxel's normal, voxels.
const NORMAL_REACH: i64 = 2;

/// A connected region of the wall never seen.
#[derive(Debug, Clone, PartialEq)]
pub struct UnseenPatch {
    /// The patch's wall voxels (grid indices), in no particular order.
    pub voxels: Vec<[usize; 3]>,
    /// Its surface area, mm² (see the module documentation).
    pub area_mm2: f64,
    /// The patch's voxel nearest the mean position of its voxels (world mm): a point on the
    /// wall, inside the patch even when the patch is curved.
    pub centroid_mm: DVec3,
    /// Unit normal of the wall at the centroid, pointing into the lumen (`DVec3::ZERO` when
    /// no lumen voxel is near, which a wall voxel always has).
    pub normal: DVec3,
}

impl Coverage {
    /// The unseen wall split into 26-connected patches, largest area first; `is_lumen` says
    /// which voxels are lumen (the predicate the wall was made from), for the surface normals.
    /// A region reaching farther than `extent_mm` from the voxel it was started from is listed
    /// in pieces no wider than that (one view cannot show a whole unseen side of a colon);
    /// `f64::INFINITY` keeps every connected region whole.
    pub fn unseen_patches(
        &self,
        is_lumen: impl Fn([usize; 3]) -> bool,
        extent_mm: f64,
    ) -> Vec<UnseenPatch> {
        let mut visited = self.seen.clone();
        let mut patches = Vec::new();
        for n in 0..self.size.iter().product() {
            if self.wall.get(n) && !visited.get(n) {
                visited.set(n);
                let voxels = self.flood(n, extent_mm, &mut visited);
                patches.push(self.patch(voxels, &is_lumen));
            }
        }
        patches.sort_by(|a, b| b.area_mm2.total_cmp(&a.area_mm2));
        patches
    }

    /// The grid voxels of the unseen wall 26-connected to box index `start` within `extent_mm`
    /// of it, marking each in `visited`.
    fn flood(&self, start: usize, extent_mm: f64, visited: &mut super::Bits) -> Vec<[usize; 3]> {
        let world = |v: [i64; 3]| self.geometry.world_of(DVec3::from(v.map(|x| x as f64)));
        let origin = world(self.grid_voxel(start).map(|x| x as i64));
        let mut stack = vec![start];
        let mut voxels = Vec::new();
        while let Some(n) = stack.pop() {
            let v = self.grid_voxel(n);
            voxels.push(v);
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let w = [v[0] as i64 + dx, v[1] as i64 + dy, v[2] as i64 + dz];
                        let Some(m) = self.box_index(w) else { continue };
                        let near = || world(w).distance(origin) <= extent_mm;
                        if self.wall.get(m) && !visited.get(m) && near() {
                            visited.set(m);
                            stack.push(m);
                        }
                    }
                }
            }
        }
        voxels
    }

    /// The grid index of box index `n`.
    fn grid_voxel(&self, n: usize) -> [usize; 3] {
        let [sx, sy, _] = self.size;
        [
            self.lo[0] + n % sx,
            self.lo[1] + n / sx % sy,
            self.lo[2] + n / (sx * sy),
        ]
    }

    /// A patch of `voxels` with its area, centroid and normal.
    fn patch(
        &self,
        voxels: Vec<[usize; 3]>,
        is_lumen: &impl Fn([usize; 3]) -> bool,
    ) -> UnseenPatch {
        let world = |v: [usize; 3]| self.geometry.world_of(DVec3::from(v.map(|x| x as f64)));
        let area_mm2 = voxels.iter().map(|&v| self.voxel_area(v, is_lumen)).sum();
        let mean = voxels.iter().map(|&v| world(v)).sum::<DVec3>() / voxels.len() as f64;
        let centre = *voxels
            .iter()
            .min_by(|a, b| {
                world(**a)
                    .distance(mean)
                    .total_cmp(&world(**b).distance(mean))
            })
            .expect("a patch holds a voxel");
        UnseenPatch {
            area_mm2,
            centroid_mm: world(centre),
            normal: self.normal(centre, is_lumen),
            voxels,
        }
    }

    /// The surface area wall voxel `v` carries, mm²: its lumen-facing faces over the sum of
    /// the absolute components of its normal along the grid's axes.
    fn voxel_area(&self, v: [usize; 3], is_lumen: &impl Fn([usize; 3]) -> bool) -> f64 {
        let s = self.geometry.spacing_mm();
        let face = [s.y * s.z, s.x * s.z, s.x * s.y];
        let mut faces = 0.0;
        for a in 0..3 {
            for step in [-1i64, 1] {
                let mut w = v.map(|x| x as i64);
                w[a] += step;
                if w[a] >= 0 && is_lumen(w.map(|x| x as usize)) {
                    faces += face[a];
                }
            }
        }
        let n = self.normal(v, is_lumen);
        let axes = self.geometry.direction();
        let spread = (0..3).map(|a| n.dot(axes.col(a)).abs()).sum::<f64>();
        // A lone voxel without a normal keeps its faces.
        if spread > 0.0 {
            faces / spread
        } else {
            faces
        }
    }

    /// The unit direction (world) from wall voxel `v` to the lumen voxels around it.
    fn normal(&self, v: [usize; 3], is_lumen: &impl Fn([usize; 3]) -> bool) -> DVec3 {
        let r = NORMAL_REACH;
        let mut sum = DVec3::ZERO;
        for dz in -r..=r {
            for dy in -r..=r {
                for dx in -r..=r {
                    let w = [v[0] as i64 + dx, v[1] as i64 + dy, v[2] as i64 + dz];
                    let inside = dx * dx + dy * dy + dz * dz <= r * r + r;
                    if inside && w.iter().all(|&x| x >= 0) && is_lumen(w.map(|x| x as usize)) {
                        sum += DVec3::new(dx as f64, dy as f64, dz as f64);
                    }
                }
            }
        }
        let s = self.geometry.spacing_mm();
        (self.geometry.direction() * (sum * s)).normalize_or_zero()
    }
}

impl UnseenPatch {
    /// How many of the patch's voxels `coverage` (over the same wall) has seen.
    pub fn seen_in(&self, coverage: &Coverage) -> usize {
        let seen = |v: &&[usize; 3]| coverage.state(**v) == Some(true);
        self.voxels.iter().filter(seen).count()
    }
}

#[cfg(test)]
mod tests;
