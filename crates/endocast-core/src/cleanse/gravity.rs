//! Which way is down in a scan's index space.

use crate::Geometry;

/// Gravity along one index axis: depth grows with `sign` × the index on `axis`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Gravity {
    /// The index axis (0 = i, 1 = j, 2 = k) closest to the patient's anterior–posterior axis.
    pub axis: usize,
    /// +1 when gravity points to growing indices on `axis`, −1 otherwise.
    pub sign: i8,
}

impl Gravity {
    /// Gravity for a patient lying supine (posterior is down) or prone (anterior is down) in
    /// `geometry`'s scanner: the two directions along the index axis closest to LPS +y, supine
    /// first.
    pub fn supine_or_prone(geometry: &Geometry) -> [Self; 2] {
        let direction = geometry.direction();
        let posterior = |axis: usize| direction.col(axis).y;
        let axis = (0..3)
            .max_by(|&a, &b| posterior(a).abs().total_cmp(&posterior(b).abs()))
            .unwrap_or(1);
        let sign = if posterior(axis) >= 0.0 { 1 } else { -1 };
        [Self { axis, sign }, Self { axis, sign: -sign }]
    }

    /// How deep voxel `ijk` lies, in voxels along gravity (up to an offset).
    pub fn depth(&self, ijk: [usize; 3]) -> f64 {
        f64::from(self.sign) * ijk[self.axis] as f64
    }

    /// The voxel one step up (against gravity) from `ijk`, `None` past the grid's edge.
    pub(crate) fn up(&self, mut ijk: [usize; 3], dims: [usize; 3]) -> Option<[usize; 3]> {
        let n = &mut ijk[self.axis];
        if self.sign > 0 {
            *n = n.checked_sub(1)?;
        } else if *n + 1 < dims[self.axis] {
            *n += 1;
        } else {
            return None;
        }
        Some(ijk)
    }

    /// The voxel one step down (with gravity) from `ijk`, `None` past the grid's edge.
    pub(crate) fn down(&self, ijk: [usize; 3], dims: [usize; 3]) -> Option<[usize; 3]> {
        Self {
            axis: self.axis,
            sign: -self.sign,
        }
        .up(ijk, dims)
    }
}
