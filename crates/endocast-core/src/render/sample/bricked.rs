//! The volume's voxels re-laid brick by brick for the sample batches: each brick of [`VOX`]³
//! cells holds its (VOX + 1)³ voxels (the cells' trilinear footprint, the apron clamped to the
//! volume) contiguously, so the gathers of a batch along a ray, and of the rays of a tile, fall
//! on fewer cache lines than rows of the linear volume do. Measured on the colon phantom (each
//! frame rendered both ways in one process, BENCHMARKS.md): iso 0.96–0.99 of the linear
//! layout's time, DVR complex TF 0.91–0.92; 8³ bricks (1.42× memory) gained less, 32³ about
//! as much (iso 0.97, DVR 0.94), so 16³ at 1.2× memory.

use super::super::bricks::bricks_along;
use super::super::simd::Avx2;
use super::super::voxel_grid::{BRICK_LEN, EDGE, VOX};
use crate::Volume;
use rayon::prelude::*;

/// A volume's voxels brick by brick (x fastest inside a brick, bricks x fastest), each brick
/// with a one-voxel apron on its upper faces (clamped to the volume).
#[derive(Debug, Clone)]
pub struct BrickedVoxels {
    /// Bricks per axis.
    bricks: [usize; 3],
    voxels: Vec<u16>,
}

impl BrickedVoxels {
    /// Copies `volume`'s voxels into bricks (bricks in parallel, rows by slices); `None` where
    /// the batches could not read the copy — no AVX2 on this CPU, or more voxels than their
    /// `i32` indices reach — so no memory goes to it.
    pub fn new(volume: &Volume) -> Option<Self> {
        let dims = volume.dims();
        let bricks = bricks_for(dims);
        let len = bricks
            .iter()
            .try_fold(BRICK_LEN, |len, &b| len.checked_mul(b))
            .filter(|&len| i32::try_from(len).is_ok())?;
        Avx2::detect()?;
        let source = volume.voxels();
        let mut voxels = vec![0u16; len];
        voxels
            .par_chunks_mut(BRICK_LEN)
            .enumerate()
            .for_each(|(b, brick)| {
                let index = [
                    b % bricks[0],
                    b / bricks[0] % bricks[1],
                    b / (bricks[0] * bricks[1]),
                ];
                let at = |axis: usize, l: usize| (index[axis] * VOX + l).min(dims[axis] - 1);
                let x0 = index[0] * VOX;
                for (yz, out) in brick.chunks_exact_mut(EDGE).enumerate() {
                    let row = dims[0] * (at(1, yz % EDGE) + dims[1] * at(2, yz / EDGE));
                    if x0 + EDGE <= dims[0] {
                        out.copy_from_slice(&source[row + x0..][..EDGE]);
                    } else {
                        for (x, v) in out.iter_mut().enumerate() {
                            *v = source[row + at(0, x)];
                        }
                    }
                }
            });
        Some(Self { bricks, voxels })
    }

    /// Whether these are the bricks of a volume of `dims` voxels, each index of which fits the
    /// gathers' `i32`.
    pub fn fits(&self, dims: [usize; 3]) -> bool {
        self.bricks == bricks_for(dims) && i32::try_from(self.voxels.len()).is_ok()
    }

    /// Bricks per axis.
    pub fn bricks(&self) -> [usize; 3] {
        self.bricks
    }

    /// The voxels, brick by brick.
    pub fn voxels(&self) -> &[u16] {
        &self.voxels
    }
}

/// Bricks needed per axis for `dims` voxels.
fn bricks_for(dims: [usize; 3]) -> [usize; 3] {
    dims.map(|n| bricks_along(n, VOX))
}
