//! A uniform grid of bins listing, per bin, the shapes that can matter to its voxels, so that a
//! voxel tests a handful of nearby shapes instead of all of them (the colon's curve has hundreds
//! of segments).

use glam::DVec3;

/// Shapes binned by where they can matter; item ids are positions in the list given to
/// [`BinGrid::new`], and each bin lists its ids in increasing order.
pub(crate) struct BinGrid {
    bin_vox: usize,
    bins: [usize; 3],
    /// `items[offsets[b]..offsets[b + 1]]` are the ids in bin `b` (compressed rows).
    offsets: Vec<u32>,
    items: Vec<u32>,
}

/// The ball around a bin's centre that holds the centres of all its voxels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BinBall {
    /// Centre, voxel index.
    pub(crate) centre: DVec3,
    /// Radius, voxels.
    pub(crate) radius: f64,
}

impl BinGrid {
    /// Bins of `bin_vox` voxels over a `dims` grid. `bounds` are each shape's box (voxel index
    /// space, grown by everything that can make the shape matter); the boxes only propose ids to
    /// a bin, and `keep(ball, proposed, kept)` pushes onto `kept` those of the `proposed` ids (in
    /// increasing order) that can matter to voxels in the bin's `ball`, keeping their order.
    pub(crate) fn new(
        dims: [usize; 3],
        bin_vox: usize,
        bounds: &[(DVec3, DVec3)],
        keep: impl Fn(BinBall, &[u32], &mut Vec<u32>),
    ) -> Self {
        let bins = dims.map(|n| n.div_ceil(bin_vox));
        let proposed = Self::propose(bins, bin_vox as f64, bounds);
        // Voxel centres of bin c along an axis run from c · bin to c · bin + bin − 1.
        let half = (bin_vox as f64 - 1.0) / 2.0;
        let radius = half * 3f64.sqrt();
        let mut offsets = Vec::with_capacity(proposed.offsets.len());
        let mut items = Vec::new();
        let mut kept = Vec::new();
        offsets.push(0);
        for z in 0..bins[2] {
            for y in 0..bins[1] {
                for x in 0..bins[0] {
                    let bin = x + bins[0] * (y + bins[1] * z);
                    let ids = &proposed.items
                        [proposed.offsets[bin] as usize..proposed.offsets[bin + 1] as usize];
                    kept.clear();
                    if !ids.is_empty() {
                        let cell = DVec3::new(x as f64, y as f64, z as f64);
                        let centre = cell * bin_vox as f64 + half;
                        keep(BinBall { centre, radius }, ids, &mut kept);
                    }
                    items.extend_from_slice(&kept);
                    offsets.push(items.len() as u32);
                }
            }
        }
        Self {
            bin_vox,
            bins,
            offsets,
            items,
        }
    }

    /// The grid listing every shape in each bin its box covers.
    fn propose(bins: [usize; 3], bin_vox: f64, bounds: &[(DVec3, DVec3)]) -> Self {
        let ranges: Vec<_> = bounds
            .iter()
            .map(|&(lo, hi)| Self::bin_range(bins, bin_vox, lo, hi))
            .collect();
        let mut offsets = vec![0u32; bins.iter().product::<usize>() + 1];
        Self::for_each_bin(bins, &ranges, |bin, _| offsets[bin + 1] += 1);
        for b in 1..offsets.len() {
            offsets[b] += offsets[b - 1];
        }
        let mut fill = offsets.clone();
        let mut items = vec![0u32; offsets[offsets.len() - 1] as usize];
        Self::for_each_bin(bins, &ranges, |bin, id| {
            items[fill[bin] as usize] = id;
            fill[bin] += 1;
        });
        Self {
            bin_vox: bin_vox as usize,
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

    /// Calls `f(bin, id)` for every bin each shape's box covers, shapes in id order.
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

    /// The first `i` past the bin holding voxel column `i`.
    #[inline]
    pub(crate) fn run_end(&self, i: usize) -> usize {
        (i / self.bin_vox + 1) * self.bin_vox
    }

    /// Ids of the shapes kept for the bin holding `p` (increasing order).
    #[inline]
    pub(crate) fn near(&self, p: DVec3) -> &[u32] {
        // Truncation is the floor for the non-negative coordinates of voxel centres (negative
        // ones saturate to bin 0), and avoids a call to `floor` per voxel.
        let cell =
            |axis: usize| (p[axis].max(0.0) as usize / self.bin_vox).min(self.bins[axis] - 1);
        let bin = cell(0) + self.bins[0] * (cell(1) + self.bins[1] * cell(2));
        &self.items[self.offsets[bin] as usize..self.offsets[bin + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_are_listed_in_the_bins_their_boxes_touch_and_kept_by_the_test() {
        let boxes = [
            (DVec3::splat(1.0), DVec3::splat(2.0)),
            (DVec3::new(5.0, 0.0, 0.0), DVec3::new(12.0, 3.0, 3.0)),
            (DVec3::splat(-20.0), DVec3::splat(-10.0)),
        ];
        let all = BinGrid::new([16, 8, 8], 4, &boxes, |_, ids, kept| kept.extend(ids));
        assert_eq!(all.near(DVec3::new(1.0, 1.0, 1.0)), &[0]);
        assert_eq!(all.near(DVec3::new(4.0, 0.0, 0.0)), &[1]);
        assert_eq!(all.near(DVec3::new(15.0, 0.0, 0.0)), &[1]);
        assert_eq!(all.near(DVec3::new(2.0, 5.0, 5.0)), &[] as &[u32]);
        assert_eq!(all.near(DVec3::new(0.0, 7.0, 7.0)), &[] as &[u32]);
        // Bins are 4 voxels: centres at 1.5, 5.5, ... with radius 1.5·√3.
        let refined = BinGrid::new([16, 8, 8], 4, &boxes, |ball, ids, kept| {
            assert!((ball.radius - 1.5 * 3f64.sqrt()).abs() < 1e-12);
            kept.extend(ids.iter().filter(|&&id| id != 1 || ball.centre.x < 8.0));
        });
        assert_eq!(refined.near(DVec3::new(7.0, 0.0, 0.0)), &[1]);
        assert_eq!(refined.near(DVec3::new(8.0, 0.0, 0.0)), &[] as &[u32]);
        assert_eq!(refined.near(DVec3::new(2.0, 2.0, 2.0)), &[0]);
    }
}
