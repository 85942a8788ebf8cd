//! The scalar sampler's unchecked reads: one bounds check for a whole 2×2×2 cell.

use crate::render::voxel_grid::VoxelGrid;
use glam::Vec4;

impl VoxelGrid<'_> {
    /// The 2×2×2 cell whose lowest corner is voxel `index`: the four corners at x and the four
    /// at x + 1, each ordered (y, z) = (0, 0), (1, 0), (0, 1), (1, 1).
    ///
    /// # Panics
    /// Where the cell is not inside the voxels (as indexing would).
    #[inline(always)]
    pub(in crate::render) fn corners(&self, index: usize) -> [Vec4; 2] {
        let [sx, sy, sz] = self.stride;
        // One bounds check for the whole cell (it panics like indexing would).
        let cell = &self.voxels[index..=index + sx + sy + sz];
        let at = |offset: usize| {
            debug_assert!(offset < cell.len());
            // SAFETY: every offset used below is a sum of a subset of {sx, sy, sz}, so it is at
            // most sx + sy + sz = cell.len() − 1: `VoxelGrid::new` makes each stride 0 or a
            // product of dimensions at most `voxels.len()`, so that sum cannot overflow (and an
            // `index` that makes the end overflow gives an empty range, refused above).
            f32::from(unsafe { *cell.get_unchecked(offset) })
        };
        let low = Vec4::new(at(0), at(sy), at(sz), at(sz + sy));
        let high = Vec4::new(at(sx), at(sy + sx), at(sz + sx), at(sz + sy + sx));
        [low, high]
    }
}
