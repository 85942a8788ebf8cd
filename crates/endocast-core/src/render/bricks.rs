//! The paper's culling structure: the minimum and maximum stored value of every brick of
//! [`BRICK_VOX`]³ voxels ([`BrickGrid`], built once per volume) and which bricks matter for the
//! current isovalues and transfer function ([`Activity`], re-classified in a few milliseconds
//! whenever they change).

use super::transfer::TfTable;
use crate::Volume;
use rayon::prelude::*;

/// Edge of a brick in voxels: the paper's 8³. 4³ was measured too (colon phantom 512×512×478,
/// 60 frames of the benchmark path; BENCHMARKS.md): with today's walks it is faster from the eye
/// (iso 0.94×, DVR ramp 0.92×, complex 0.94×) but slower behind the wall, where every brick is
/// active and 4³ only doubles the DDA steps (hybrid 50 % complex TF 1.06×). A 4³ level consulted
/// only by the isosurface walk inside active bricks halved its samples but not its time, so
/// there is one level.
pub const BRICK_VOX: usize = 8;

/// Minimum and maximum stored value per brick. Brick `b` along an axis covers the positions
/// `[Bb, Bb + B]` (B = [`BRICK_VOX`]) in voxel index space, so its range is taken over voxels
/// `Bb ..= Bb + B`: the extra voxel is the trilinear footprint of the positions next to the
/// upper face, so no value a sample inside the brick can take (no isosurface crossing) lies
/// outside `[min, max]`.
#[derive(Debug, Clone)]
pub struct BrickGrid {
    bricks: [usize; 3],
    min: Vec<u16>,
    max: Vec<u16>,
}

impl BrickGrid {
    /// Scans the volume once, slabs of bricks in parallel.
    pub fn new(volume: &Volume) -> Self {
        let dims = volume.dims();
        let bricks = dims.map(|n| bricks_along(n, BRICK_VOX));
        let voxels = volume.voxels();
        let slab = bricks[0] * bricks[1];
        let mut min = vec![0u16; slab * bricks[2]];
        let mut max = vec![0u16; slab * bricks[2]];
        min.par_chunks_mut(slab)
            .zip(max.par_chunks_mut(slab))
            .enumerate()
            .for_each(|(bk, (min_slab, max_slab))| {
                for bj in 0..bricks[1] {
                    for bi in 0..bricks[0] {
                        let (lo, hi) = brick_range(voxels, dims, [bi, bj, bk]);
                        min_slab[bi + bricks[0] * bj] = lo;
                        max_slab[bi + bricks[0] * bj] = hi;
                    }
                }
            });
        Self { bricks, min, max }
    }

    /// Number of bricks along `i`, `j`, `k`.
    pub fn bricks(&self) -> [usize; 3] {
        self.bricks
    }

    /// Total number of bricks.
    pub fn len(&self) -> usize {
        self.min.len()
    }

    /// Always false: a volume has at least one voxel, hence one brick.
    pub fn is_empty(&self) -> bool {
        self.min.is_empty()
    }

    /// Smallest stored value a sample in brick `index` can take.
    #[inline]
    pub fn min(&self, index: usize) -> u16 {
        self.min[index]
    }

    /// Largest stored value a sample in brick `index` can take.
    #[inline]
    pub fn max(&self, index: usize) -> u16 {
        self.max[index]
    }

    /// Linear index of the brick holding voxel position `p` (clamped to the grid; a position on
    /// a face between two bricks lies in both footprints, so either answer is right).
    #[inline]
    pub fn brick_at(&self, p: glam::Vec3) -> usize {
        let cell = |axis: usize| {
            // `as` saturates (NaN to 0), so a position outside the grid clamps to its border.
            ((p[axis] / BRICK_VOX as f32) as usize).min(self.bricks[axis] - 1)
        };
        self.index([cell(0), cell(1), cell(2)])
    }

    /// Linear index of brick `(bi, bj, bk)` (`bi` fastest).
    #[inline]
    pub fn index(&self, brick: [usize; 3]) -> usize {
        brick[0] + self.bricks[0] * (brick[1] + self.bricks[1] * brick[2])
    }
}

/// Bricks of `edge` cells needed along an axis of `n` voxels: positions run over `[0, n − 1]`.
pub(super) fn bricks_along(n: usize, edge: usize) -> usize {
    (n.saturating_sub(1)).div_ceil(edge).max(1)
}

/// Min and max over voxels `8b ..= 8b + 8` (clamped to the grid) of brick `b`.
fn brick_range(voxels: &[u16], dims: [usize; 3], brick: [usize; 3]) -> (u16, u16) {
    let span = |axis: usize| {
        let start = brick[axis] * BRICK_VOX;
        start..=(start + BRICK_VOX).min(dims[axis] - 1)
    };
    let (mut lo, mut hi) = (u16::MAX, u16::MIN);
    for k in span(2) {
        for j in span(1) {
            let row = dims[0] * (j + dims[1] * k);
            let i = span(0);
            for &v in &voxels[row + i.start()..=row + i.end()] {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
    }
    (lo, hi)
}

/// A bit per brick.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BitSet {
    words: Vec<u64>,
}

impl BitSet {
    /// Bits `index` for which `is_set(index)`, for `index < len`.
    fn from_fn(len: usize, is_set: impl Fn(usize) -> bool + Sync) -> Self {
        let words = (0..len.div_ceil(64))
            .into_par_iter()
            .map(|w| {
                (0..64)
                    .map(|b| w * 64 + b)
                    .take_while(|&i| i < len)
                    .fold(0u64, |word, i| word | (u64::from(is_set(i)) << (i % 64)))
            })
            .collect();
        Self { words }
    }

    /// Whether bit `index` is set (false past the end).
    #[inline]
    pub fn get(&self, index: usize) -> bool {
        self.words
            .get(index / 64)
            .is_some_and(|w| w >> (index % 64) & 1 == 1)
    }

    /// The bits, 64 to a word, bit `i` of word `w` standing for index `64 w + i`.
    pub(crate) fn words(&self) -> &[u64] {
        &self.words
    }

    /// Number of set bits.
    pub fn count(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// The bits of a grid of `bricks` set where a brick or one of its 26 neighbours is set here.
    pub fn dilated(&self, bricks: [usize; 3]) -> Self {
        let [nx, ny, nz] = bricks;
        let near = |i: usize, n: usize| i.saturating_sub(1)..=(i + 1).min(n - 1);
        Self::from_fn(nx * ny * nz, |b| {
            let (i, j, k) = (b % nx, b / nx % ny, b / (nx * ny));
            near(k, nz)
                .any(|k| near(j, ny).any(|j| near(i, nx).any(|i| self.get(i + nx * (j + ny * k)))))
        })
    }
}

/// The paper's two bit arrays (§3.2): bricks a sample of which can cross one of the isovalues,
/// and bricks a sample of which has non-zero opacity under the transfer function.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Activity {
    /// Active for an isosurface: `min ≤ iso ≤ max` for one of the isovalues.
    pub iso: BitSet,
    /// Active for the transfer function: some value in `[min, max]` is not transparent.
    pub tf: BitSet,
}

impl Activity {
    /// Classifies every brick against isovalues given in stored units and a lookup table.
    /// Half a stored unit of margin absorbs the rounding of `f32` trilinear samples.
    pub fn classify(grid: &BrickGrid, isovalues_stored: &[f32], table: &TfTable) -> Self {
        const MARGIN: f32 = 0.5;
        let iso = BitSet::from_fn(grid.len(), |b| {
            let (lo, hi) = (f32::from(grid.min(b)), f32::from(grid.max(b)));
            isovalues_stored
                .iter()
                .any(|&iso| lo - MARGIN <= iso && iso <= hi + MARGIN)
        });
        let tf = BitSet::from_fn(grid.len(), |b| table.any_opacity(grid.min(b), grid.max(b)));
        Self { iso, tf }
    }

    /// The classification for samples whose footprint reaches up to two voxels past their
    /// brick (the tricubic B-spline's): every brick next to an active one is active too.
    /// Exact for a spline whose coefficients are the voxels; the interpolating spline's values
    /// may also ring past the voxels' range near an edge, but by a factor 0.27 a voxel away
    /// from it, so past the neighbouring brick (8 voxels) by under 10⁻⁴ of the edge's height.
    pub fn dilated(&self, grid: &BrickGrid) -> Self {
        Self {
            iso: self.iso.dilated(grid.bricks()),
            tf: self.tf.dilated(grid.bricks()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::transfer::TransferFunction;
    use super::*;
    use crate::{Geometry, Modality, ValueMap};
    use glam::DVec3;

    fn ramp_volume(dims: [usize; 3]) -> Volume {
        let g = Geometry::axis_aligned(dims, DVec3::ONE, DVec3::ZERO).unwrap();
        let voxels = (0..dims[0] * dims[1] * dims[2])
            .map(|n| (n % dims[0]) as u16)
            .collect();
        Volume::new(g, voxels, ValueMap::IDENTITY, Modality::Unknown).unwrap()
    }

    #[test]
    fn ranges_cover_the_trilinear_footprint() {
        // Value = i: brick 0 spans voxels 0..=B, brick 1 B..=2B, brick 2 2B..=2B+3.
        let b = BRICK_VOX;
        let grid = BrickGrid::new(&ramp_volume([2 * b + 4, 3, 1]));
        assert_eq!(grid.bricks(), [3, 1, 1]);
        let v = |n: usize| n as u16;
        assert_eq!((grid.min(0), grid.max(0)), (0, v(b)));
        assert_eq!((grid.min(1), grid.max(1)), (v(b), v(2 * b)));
        assert_eq!((grid.min(2), grid.max(2)), (v(2 * b), v(2 * b + 3)));
        // 2B + 1 voxels: positions [0, 2B] fit two bricks exactly.
        assert_eq!(
            BrickGrid::new(&ramp_volume([2 * b + 1, 1, 1])).bricks(),
            [2, 1, 1]
        );
        assert_eq!(BrickGrid::new(&ramp_volume([1, 1, 1])).bricks(), [1, 1, 1]);
    }

    #[test]
    fn classification_follows_isovalues_and_the_transfer_function() {
        let b = BRICK_VOX as f64;
        let volume = ramp_volume([2 * BRICK_VOX + 4, 3, 1]);
        let grid = BrickGrid::new(&volume);
        let tf = TransferFunction::from_points(
            &[(0.0, 0.0), (2.0 * b + 1.0, 0.0), (2.0 * b + 2.0, 1.0)],
            &[(0.0, [1.0; 3])],
        )
        .unwrap();
        let table = TfTable::new(&tf, volume.value_map(), volume.stored_range(), 1.0);
        let activity = Activity::classify(&grid, &[1.5 * b as f32], &table);
        let bits = |set: &BitSet| (0..3).map(|b| set.get(b)).collect::<Vec<_>>();
        assert_eq!(bits(&activity.iso), [false, true, false]);
        // Brick 1 reaches 2B; with one stored unit of margin the table is read up to 2B + 1,
        // which is still transparent.
        assert_eq!(bits(&activity.tf), [false, false, true]);
        assert_eq!(activity.iso.count(), 1);
        let both = Activity::classify(&grid, &[b as f32, 30.0 * b as f32], &table);
        assert_eq!(bits(&both.iso), [true, true, false]);
        assert!(!both.iso.get(1000));
    }
}
