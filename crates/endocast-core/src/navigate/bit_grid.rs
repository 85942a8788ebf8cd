//! One bit per voxel of a box: the masks of lumens, of allowed regions and of bone cores.

/// One bit per voxel of a box, `i` fastest.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BitGrid {
    pub(super) dims: [usize; 3],
    pub(super) words: Vec<u64>,
}

impl BitGrid {
    /// A grid of `dims` voxels, every bit clear.
    pub(crate) fn new(dims: [usize; 3]) -> Self {
        let n = dims[0] * dims[1] * dims[2];
        Self {
            dims,
            words: vec![0; n.div_ceil(64)],
        }
    }

    /// The linear index of voxel `v` (`i` fastest).
    #[inline]
    pub(super) fn index(&self, [i, j, k]: [usize; 3]) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// The bit of voxel `v` (which must lie in the box).
    #[inline]
    pub(crate) fn get(&self, v: [usize; 3]) -> bool {
        let n = self.index(v);
        self.words[n >> 6] >> (n & 63) & 1 == 1
    }

    /// The bit of the voxel at linear index `n` (`i` fastest).
    #[inline]
    pub(crate) fn get_linear(&self, n: usize) -> bool {
        self.words[n >> 6] >> (n & 63) & 1 == 1
    }

    /// Sets the bit of voxel `v` (which must lie in the box).
    #[inline]
    pub(crate) fn set(&mut self, v: [usize; 3]) {
        let n = self.index(v);
        self.words[n >> 6] |= 1 << (n & 63);
    }

    /// Clears every bit whose index along `axis` (0 `i`, 1 `j`, 2 `k`) lies outside `range`.
    pub(crate) fn keep_along(&mut self, axis: usize, range: std::ops::RangeInclusive<usize>) {
        let [nx, ny, nz] = self.dims;
        for n in 0..nx * ny * nz {
            let at = [n % nx, n / nx % ny, n / (nx * ny)];
            if !range.contains(&at[axis]) {
                self.words[n >> 6] &= !(1 << (n & 63));
            }
        }
    }
}
