//! A uniform grid of bins listing, per bin, the shapes that can touch it, so that a voxel tests
//! a few dozen nearby shapes instead of all of them (the colon's curve has hundreds of segments).

use glam::DVec3;

/// Shapes binned by their bounding boxes; item ids are positions in the list given to
/// [`BinGrid::new`], and each bin lists its ids in increasing order.
pub(crate) struct BinGrid {
    bin_vox: f64,
    bins: [usize; 3],
    /// `items[offsets[b]..offsets[b + 1]]` are the ids in bin `b` (compressed rows).
    offsets: Vec<usize>,
    items: Vec<u32>,
}

impl BinGrid {
    /// Bins of `bin_vox` voxels over a `dims` grid; `bounds` are each shape's box (voxel index
    /// space, already grown by everything that can make the shape change a voxel's value).
    pub(crate) fn new(dims: [usize; 3], bin_vox: usize, bounds: &[(DVec3, DVec3)]) -> Self {
        let bins = dims.map(|n| n.div_ceil(bin_vox));
        let bin_vox = bin_vox as f64;
        let ranges: Vec<Option<[(usize, usize); 3]>> = bounds
            .iter()
            .map(|&(lo, hi)| Self::bin_range(bins, bin_vox, lo, hi))
            .collect();
        let mut counts = vec![0usize; bins.iter().product::<usize>() + 1];
        Self::for_each_bin(bins, &ranges, |bin, _| counts[bin + 1] += 1);
        for b in 1..counts.len() {
            counts[b] += counts[b - 1];
        }
        let offsets = counts;
        let mut fill = offsets.clone();
        let mut items = vec![0u32; offsets[offsets.len() - 1]];
        Self::for_each_bin(bins, &ranges, |bin, id| {
            items[fill[bin]] = id;
            fill[bin] += 1;
        });
        Self {
            bin_vox,
            bins,
            offsets,
            items,
        }
    }

    /// Bin index ranges (inclusive) along each axis covered by `lo..=hi`, or `None` when the box
    /// misses the grid.
    fn bin_range(
        bins: [usize; 3],
        bin_vox: f64,
        lo: DVec3,
        hi: DVec3,
    ) -> Option<[(usize, usize); 3]> {
        let mut range = [(0, 0); 3];
        for axis in 0..3 {
            let last = bins[axis] as f64 - 1.0;
            let a = (lo[axis] / bin_vox).floor();
            let b = (hi[axis] / bin_vox).floor();
            if b < 0.0 || a > last || a.is_nan() || b.is_nan() {
                return None;
            }
            range[axis] = (a.max(0.0) as usize, b.min(last) as usize);
        }
        Some(range)
    }

    /// Calls `f(bin, id)` for every bin each shape covers, shapes in id order.
    fn for_each_bin(
        bins: [usize; 3],
        ranges: &[Option<[(usize, usize); 3]>],
        mut f: impl FnMut(usize, u32),
    ) {
        for (id, range) in ranges.iter().enumerate() {
            let Some([(x0, x1), (y0, y1), (z0, z1)]) = *range else {
                continue;
            };
            for z in z0..=z1 {
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        f(x + bins[0] * (y + bins[1] * z), id as u32);
                    }
                }
            }
        }
    }

    /// Ids of the shapes whose boxes touch the bin holding `p` (increasing order).
    #[inline]
    pub(crate) fn near(&self, p: DVec3) -> &[u32] {
        let cell = |axis: usize| {
            let c = (p[axis] / self.bin_vox).floor().max(0.0) as usize;
            c.min(self.bins[axis] - 1)
        };
        let bin = cell(0) + self.bins[0] * (cell(1) + self.bins[1] * cell(2));
        &self.items[self.offsets[bin]..self.offsets[bin + 1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_are_listed_in_the_bins_their_boxes_touch() {
        let boxes = [
            (DVec3::splat(1.0), DVec3::splat(2.0)),
            (DVec3::new(5.0, 0.0, 0.0), DVec3::new(12.0, 3.0, 3.0)),
            (DVec3::splat(-20.0), DVec3::splat(-10.0)),
        ];
        let grid = BinGrid::new([16, 8, 8], 4, &boxes);
        assert_eq!(grid.near(DVec3::new(1.0, 1.0, 1.0)), &[0]);
        assert_eq!(grid.near(DVec3::new(4.0, 0.0, 0.0)), &[1]);
        assert_eq!(grid.near(DVec3::new(15.0, 0.0, 0.0)), &[1]);
        assert_eq!(grid.near(DVec3::new(2.0, 5.0, 5.0)), &[] as &[u32]);
        assert_eq!(grid.near(DVec3::new(0.0, 7.0, 7.0)), &[] as &[u32]);
    }
}
