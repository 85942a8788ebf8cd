//! The data the samplers read, with no code that depends on the CPU: a ray's sample grid, a
//! batch's lanes, and the voxels with their layout (linear, and brick by brick for the
//! batches). The scalar sampler (`sample`) and the AVX2 batches (`simd`) both read these.

use crate::Volume;
use glam::Vec3;

/// Cells per brick edge of the bricked layout (a power of two).
pub(in crate::render) const VOX: usize = 16;
/// Voxels per brick edge, with the apron.
pub(in crate::render) const EDGE: usize = VOX + 1;
/// Voxels per brick.
pub(in crate::render) const BRICK_LEN: usize = EDGE * EDGE * EDGE;

/// A ray's fixed sample grid in voxel space: sample `n` lies `t_n = t_start + (n + offset) · step`
/// mm from the eye, at voxel position `origin + direction · t_n` (`Copy`, so closures can read
/// it while a walk holds the march).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleGrid {
    /// The eye, voxel index space.
    pub origin: Vec3,
    /// Voxel index units per mm along the ray.
    pub direction: Vec3,
    /// Where the ray starts, mm from the eye.
    pub t_start: f32,
    /// Offset of the grid from `t_start`, in steps (0–1).
    pub offset: f32,
    /// Distance between samples, mm.
    pub step: f32,
}

impl SampleGrid {
    /// Voxel position at distance `t` (mm).
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.direction * t
    }

    /// Distance of sample `n` from the eye, mm.
    #[inline]
    pub fn t_of(&self, n: i32) -> f32 {
        self.t_start + (n as f32 + self.offset) * self.step
    }
}

/// Eight stored values, one per lane of a batch.
pub type Lanes = [f32; 8];

/// A volume's voxels as the samplers read them: the linear array with its strides and clamps,
/// and, where the batches read them that way, the same voxels brick by brick.
#[derive(Debug, Clone, Copy)]
pub(crate) struct VoxelGrid<'a> {
    pub(in crate::render) voxels: &'a [u16],
    /// Largest position per axis (`n − 1`).
    pub(in crate::render) extent: Vec3,
    /// Largest base index per axis of the 2×2×2 cell (`n − 2`, or 0 for a single voxel).
    pub(in crate::render) max_base: [i32; 3],
    /// Memory strides to the next voxel per axis; 0 along an axis of one voxel.
    pub(in crate::render) stride: [usize; 3],
    /// The voxels brick by brick, where the batches read them that way, and bricks per axis.
    pub(in crate::render) bricked: Option<(&'a [u16], [i32; 3])>,
}

impl<'a> VoxelGrid<'a> {
    /// `volume`'s voxels in their linear layout.
    pub(in crate::render) fn new(volume: &'a Volume) -> Self {
        let [nx, ny, nz] = volume.dims();
        let step = |n: usize, s: usize| if n > 1 { s } else { 0 };
        // Volumes are limited far below 2³¹ voxels per axis; saturate rather than wrap anyway.
        let max_base = [nx, ny, nz].map(|n| i32::try_from(n.saturating_sub(2)).unwrap_or(i32::MAX));
        Self {
            voxels: volume.voxels(),
            extent: Vec3::new((nx - 1) as f32, (ny - 1) as f32, (nz - 1) as f32),
            max_base,
            stride: [step(nx, 1), step(ny, nx), step(nz, nx * ny)],
            bricked: None,
        }
    }
}
