//! The cell level under the brick level for exact isosurface hits: for every brick active for
//! the isovalue, one bit per trilinear cell (a 2×2×2 block of voxels) that says whether the
//! isovalue lies in the cell's corner range, so that the isosurface can cross it (Wald et al.
//! 2005 and Knoll et al. 2006 keep such ranges in a tree; a brick's 8³ cells in eight 64-bit
//! words are the two-level form of it). Built for one isovalue in parallel over the active
//! bricks only.

use super::bricks::{Activity, BrickGrid, BRICK_VOX};
use crate::Volume;
use rayon::prelude::*;

/// Bricks without a cell mask (no crossing can lie in them) in [`CellMask::slots`].
pub(crate) const NONE: u32 = u32::MAX;

/// One brick's cells: word `k` holds the cells of z-layer `k`, bit `i + 8 j` the cell `(i, j)`
/// (all inside the brick).
pub(crate) type BrickCells = [u64; BRICK_VOX];

/// `log2(BRICK_VOX)`: a cell's brick is its index shifted right by this.
pub(crate) const BRICK_SHIFT: u32 = BRICK_VOX.trailing_zeros();

/// The cells of the iso-active bricks whose trilinear field can reach the isovalue.
#[derive(Debug, Clone, Default)]
pub(crate) struct CellMask {
    /// Per brick, its entry in `cells`, or [`NONE`].
    slot: Vec<u32>,
    cells: Vec<BrickCells>,
    /// Bricks per axis.
    bricks: [i32; 3],
}

impl CellMask {
    /// The cells of `volume` whose corner range holds `iso` (stored units: some corner below it
    /// and some at or above it), for the bricks set in `activity.iso`; a brick none of whose
    /// cells holds it gets no entry (the cell walk leaves it in one jump).
    pub fn new(volume: &Volume, grid: &BrickGrid, activity: &Activity, iso: f32) -> Self {
        let bricks = grid.bricks();
        let found: Vec<(usize, BrickCells)> = (0..grid.len())
            .into_par_iter()
            .filter(|&b| activity.iso.get(b))
            .filter_map(|b| {
                let brick = [
                    b % bricks[0],
                    b / bricks[0] % bricks[1],
                    b / bricks[0] / bricks[1],
                ];
                let cells = brick_cells(volume, brick, iso);
                (cells != [0; BRICK_VOX]).then_some((b, cells))
            })
            .collect();
        let mut slot = vec![NONE; grid.len()];
        for (n, &(b, _)) in found.iter().enumerate() {
            // Fewer bricks than `u32::MAX`: `BrickDda` numbers them in `u32` already.
            slot[b] = n as u32;
        }
        let cells = found.into_iter().map(|(_, cells)| cells).collect();
        // Bricks per axis fit `i32`: their product is numbered in `u32` above.
        let bricks = bricks.map(|n| i32::try_from(n).unwrap_or(i32::MAX));
        Self {
            slot,
            cells,
            bricks,
        }
    }

    /// Bricks per axis.
    #[inline]
    pub fn bricks(&self) -> [i32; 3] {
        self.bricks
    }

    /// The brick holding cell `cell` (its lowest voxel, inside the volume).
    #[inline]
    pub fn brick_of(&self, cell: [i32; 3]) -> u32 {
        let [i, j, k] = cell.map(|c| c >> BRICK_SHIFT);
        let [bx, by, _] = self.bricks;
        // Cells inside the volume lie in bricks of the grid, numbered in `u32`.
        (i + bx * (j + by * k)) as u32
    }

    /// Per brick, the place of its cells in [`Self::words`] (in bricks), or [`NONE`].
    #[inline]
    pub fn slots(&self) -> &[u32] {
        &self.slot
    }

    /// Every brick's cells ([`BrickCells`]) in slot order.
    #[inline]
    pub fn words(&self) -> &[u64] {
        self.cells.as_flattened()
    }

    /// The cells of brick `brick`, or `None` where no crossing can lie in it.
    #[inline]
    pub fn of(&self, brick: u32) -> Option<&BrickCells> {
        match self.slot.get(brick as usize) {
            Some(&n) if n != NONE => self.cells.get(n as usize),
            _ => None,
        }
    }
}

/// Whether the cell at bit place `bit` (`i + 8 j + 64 k` for cell `(i, j, k)` inside its
/// brick) is set in `cells`.
#[inline]
pub(crate) fn is_set(cells: &BrickCells, bit: usize) -> bool {
    cells[bit / 64] >> (bit % 64) & 1 == 1
}

/// The cells of brick `brick` whose corner range holds `iso`. A cell past the volume's last
/// one stands for that last one (the clamped position the sampler reads).
fn brick_cells(volume: &Volume, brick: [usize; 3], iso: f32) -> BrickCells {
    let dims = volume.dims();
    let voxels = volume.voxels();
    let corner_of_cell = |axis: usize, c: usize| {
        // The cell's base is clamped to `n − 2` (the sampler's last cell), its far corner follows.
        let base = (brick[axis] * BRICK_VOX + c).min(dims[axis].saturating_sub(2));
        [base, (base + 1).min(dims[axis] - 1)]
    };
    let mut cells = [0u64; BRICK_VOX];
    for (k, word) in cells.iter_mut().enumerate() {
        for j in 0..BRICK_VOX {
            // The range of each x-column of voxels over the cells' four rows, then of pairs of
            // columns (column `c` is voxel `8 bx + c`, clamped to the volume).
            let mut low = [f32::INFINITY; BRICK_VOX + 1];
            let mut high = [f32::NEG_INFINITY; BRICK_VOX + 1];
            for z in corner_of_cell(2, k) {
                for y in corner_of_cell(1, j) {
                    let row = dims[0] * (y + dims[1] * z);
                    for (c, (lo, hi)) in low.iter_mut().zip(high.iter_mut()).enumerate() {
                        let v =
                            f32::from(voxels[row + (brick[0] * BRICK_VOX + c).min(dims[0] - 1)]);
                        *lo = lo.min(v);
                        *hi = hi.max(v);
                    }
                }
            }
            for i in 0..BRICK_VOX {
                let [x0, x1] = corner_of_cell(0, i).map(|x| x - brick[0] * BRICK_VOX);
                let lo = low[x0].min(low[x1]);
                let hi = high[x0].max(high[x1]);
                let straddles = lo < iso && hi >= iso;
                *word |= u64::from(straddles) << (i + BRICK_VOX * j);
            }
        }
    }
    cells
}
