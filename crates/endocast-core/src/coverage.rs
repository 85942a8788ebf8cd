//! Which part of the lumen wall a fly-through has shown: every primary ray that hits the wall
//! marks the wall voxels around its hit point as seen (virtual colonoscopy shows only about 94 %
//! of the surface on a one-way flight, Vos et al. 2003; the rest is where polyps are missed).
//!
//! **The wall** is a set of voxels the caller names, normally the non-lumen voxels 6-adjacent to
//! the lumen, inside a box of the grid (the lumen's bounding box keeps the two bit sets small).
//!
//! **The marking rule**: a hit point (eye + direction · depth, world mm) lies in one cell of the
//! voxel grid, the cube between 8 voxel centres; the wall voxels among those 8 corners are
//! marked. Why it is fair: the isosurface between a lumen voxel and its 6-adjacent wall voxel
//! crosses the edge joining them, so every wall voxel has the surface passing through a cell it
//! is a corner of and can be marked; and a voxel is marked only when a ray landed within one
//! voxel of it (in each index direction). A fold thinner than two voxels may be counted as seen
//! from both sides when only one was shown.
//!
//! **Ray density**: coverage is measured with the rays of the frames recorded, so with the
//! video's own density when the video frames are recorded. A 512² frame at 90° has pixels
//! 0.004 rad wide: 0.2 mm on a wall 50 mm away, well below a voxel, so each frame marks nearly all
//! of the wall it shows; at 128² a far wall seen at a grazing angle is marked in patches, which
//! later frames, closer to it, fill in. For a finer measurement record frames rendered only for
//! coverage (a larger image or more poses) — the rule does not depend on the image size.

mod patches;

pub use patches::UnseenPatch;

use crate::render::{Camera, Frame};
use crate::views::{Image, Rgb};
use crate::{Geometry, Modality, ValueMap, Volume, VolumeError};
use glam::{DAffine3, DVec3};
use rayon::prelude::*;
use std::ops::Range;
use thiserror::Error;

/// Mask value of voxels that are not wall (see [`Coverage::mask`]).
pub const MASK_NONE: u8 = 0;
/// Mask value of wall voxels seen.
pub const MASK_SEEN: u8 = 1;
/// Mask value of wall voxels never seen.
pub const MASK_UNSEEN: u8 = 2;

/// Coverage that cannot be set up or updated.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum CoverageError {
    /// The box is empty or reaches beyond the grid.
    #[error("box {lo:?}..{hi:?} must be non-empty and inside the grid {dims:?}")]
    BadBox {
        /// First voxel of the box.
        lo: [usize; 3],
        /// One past the last voxel of the box.
        hi: [usize; 3],
        /// The grid's dimensions.
        dims: [usize; 3],
    },
    /// No voxel in the box is wall.
    #[error("the box holds no wall voxel: is the lumen predicate right?")]
    NoWall,
    /// A frame's buffers do not match its camera.
    #[error("the camera is {camera:?} pixels but the frame's depth holds {depth} values")]
    FrameSize {
        /// The camera's width and height.
        camera: [usize; 2],
        /// Length of the depth buffer.
        depth: usize,
    },
    /// Two coverages over different grids or boxes cannot be merged.
    #[error("coverages over different grids or boxes cannot be merged")]
    DifferentWall,
}

/// The seen and unseen wall voxels of a fly-through.
#[derive(Debug, Clone, PartialEq)]
pub struct Coverage {
    geometry: Geometry,
    voxel_from_world: DAffine3,
    lo: [usize; 3],
    size: [usize; 3],
    wall: Bits,
    seen: Bits,
    wall_count: usize,
    seen_count: usize,
}

impl Coverage {
    /// The wall voxels of `geometry`'s grid inside `bbox` (voxel index ranges), those for which
    /// `is_wall([i, j, k])` holds; none seen yet. The predicate runs once per voxel of the box,
    /// slices in parallel.
    pub fn new(
        geometry: &Geometry,
        is_wall: impl Fn([usize; 3]) -> bool + Sync,
        bbox: &[Range<usize>; 3],
    ) -> Result<Self, CoverageError> {
        let dims = geometry.dims();
        let lo = [0, 1, 2].map(|a| bbox[a].start);
        let hi = [0, 1, 2].map(|a| bbox[a].end);
        if (0..3).any(|a| lo[a] >= hi[a] || hi[a] > dims[a]) {
            return Err(CoverageError::BadBox { lo, hi, dims });
        }
        let size = [0, 1, 2].map(|a| hi[a] - lo[a]);
        let slice = size[0] * size[1];
        let per_slice: Vec<Vec<usize>> = (0..size[2])
            .into_par_iter()
            .map(|k| {
                let mut set = Vec::new();
                for j in 0..size[1] {
                    for i in 0..size[0] {
                        if is_wall([lo[0] + i, lo[1] + j, lo[2] + k]) {
                            set.push(i + size[0] * j + slice * k);
                        }
                    }
                }
                set
            })
            .collect();
        let mut wall = Bits::new(slice * size[2]);
        let mut wall_count = 0;
        for index in per_slice.iter().flatten() {
            wall.set(*index);
            wall_count += 1;
        }
        if wall_count == 0 {
            return Err(CoverageError::NoWall);
        }
        Ok(Self {
            geometry: *geometry,
            voxel_from_world: geometry.voxel_from_world(),
            lo,
            size,
            seen: Bits::new(slice * size[2]),
            wall,
            wall_count,
            seen_count: 0,
        })
    }

    /// The grid the coverage was made for.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The same wall with nothing seen yet: a fresh coverage for another pass over it (its
    /// result can be [merged](Coverage::merge) with this one's).
    pub fn cleared(&self) -> Self {
        Self {
            seen: Bits::new(self.size.iter().product()),
            seen_count: 0,
            ..self.clone()
        }
    }

    /// Number of wall voxels.
    pub fn total(&self) -> usize {
        self.wall_count
    }

    /// Number of wall voxels seen.
    pub fn seen_count(&self) -> usize {
        self.seen_count
    }

    /// Fraction of the wall voxels seen, 0–1.
    pub fn seen_fraction(&self) -> f64 {
        self.seen_count as f64 / self.wall_count as f64
    }

    /// Whether voxel `[i, j, k]` is wall, and if so whether it was seen.
    pub fn state(&self, voxel: [usize; 3]) -> Option<bool> {
        let n = self.box_index(voxel.map(|v| v as i64))?;
        self.wall.get(n).then(|| self.seen.get(n))
    }

    /// Index into the bit sets of a voxel, or `None` outside the box.
    fn box_index(&self, voxel: [i64; 3]) -> Option<usize> {
        let mut n = 0;
        for a in (0..3).rev() {
            let local = usize::try_from(voxel[a] - self.lo[a] as i64).ok()?;
            if local >= self.size[a] {
                return None;
            }
            n = n * self.size[a] + local;
        }
        Some(n)
    }

    /// The box indices of the 8 voxels around world point `p_mm` (the corners of its grid cell);
    /// `None` for corners outside the box, all `None` for a point that is not finite.
    fn cell_corners(&self, p_mm: DVec3) -> [Option<usize>; 8] {
        let v = self.voxel_from_world.transform_point3(p_mm);
        // Far-away or NaN points give no corner (casting NaN would give 0).
        if !(v.is_finite() && v.abs().max_element() < 1e15) {
            return [None; 8];
        }
        let base = v.floor();
        let (x, y, z) = (base.x as i64, base.y as i64, base.z as i64);
        std::array::from_fn(|c| {
            let c = c as i64;
            self.box_index([x + (c & 1), y + (c >> 1 & 1), z + (c >> 2 & 1)])
        })
    }

    /// Marks the wall voxels around one surface point (world mm) as seen (see the module doc);
    /// returns how many were newly seen.
    pub fn mark_point(&mut self, p_mm: DVec3) -> usize {
        let mut newly = 0;
        for n in self.cell_corners(p_mm).into_iter().flatten() {
            if self.wall.get(n) && !self.seen.get(n) {
                self.seen.set(n);
                newly += 1;
            }
        }
        self.seen_count += newly;
        newly
    }

    /// Marks what the rays of `frame` (rendered with `camera`) hit: for every pixel with a
    /// finite depth, the point `depth` along its ray. Returns how many wall voxels were
    /// newly seen.
    pub fn record(&mut self, camera: &Camera, frame: &Frame) -> Result<usize, CoverageError> {
        let [w, h] = camera.size();
        if frame.depth_mm.len() != w * h || [frame.width, frame.height] != [w, h] {
            return Err(CoverageError::FrameSize {
                camera: [w, h],
                depth: frame.depth_mm.len(),
            });
        }
        let mut newly = 0;
        for (n, depth) in frame.depth_mm.iter().enumerate() {
            if depth.is_finite() {
                if let Some(hit) = camera.point_at(n % w, n / w, f64::from(*depth)) {
                    newly += self.mark_point(hit);
                }
            }
        }
        Ok(newly)
    }

    /// Adds what `other` saw (e.g. the backward pass to the forward one). Both must cover the
    /// same wall of the same grid.
    pub fn merge(&mut self, other: &Coverage) -> Result<(), CoverageError> {
        let same = self.geometry == other.geometry
            && self.lo == other.lo
            && self.size == other.size
            && self.wall == other.wall;
        if !same {
            return Err(CoverageError::DifferentWall);
        }
        self.seen.or(&other.seen);
        self.seen_count = self.seen.count();
        Ok(())
    }

    /// A label volume over the whole grid (`i` fastest, the volume's layout): [`MASK_SEEN`] and
    /// [`MASK_UNSEEN`] on wall voxels, [`MASK_NONE`] elsewhere — for writing as NIfTI or NRRD
    /// with the volume's geometry.
    pub fn mask(&self) -> Vec<u8> {
        let [nx, ny, nz] = self.geometry.dims();
        let mut out = vec![MASK_NONE; nx * ny * nz];
        out.par_chunks_mut(nx * ny)
            .enumerate()
            .for_each(|(k, slice)| {
                for (m, label) in slice.iter_mut().enumerate() {
                    let voxel = [(m % nx) as i64, (m / nx) as i64, k as i64];
                    if let Some(n) = self.box_index(voxel).filter(|&n| self.wall.get(n)) {
                        *label = if self.seen.get(n) {
                            MASK_SEEN
                        } else {
                            MASK_UNSEEN
                        };
                    }
                }
            });
        out
    }

    /// [`Coverage::mask`] as a volume on the grid the coverage was made for (the scan's
    /// geometry, unit value map, no modality), ready to write as NIfTI or NRRD.
    pub fn mask_volume(&self) -> Result<Volume, VolumeError> {
        let voxels = self.mask().into_iter().map(u16::from).collect();
        let map = ValueMap::new(1.0, 0.0)?;
        Volume::new(self.geometry, voxels, map, Modality::Unknown)
    }

    /// Tints in `color` (blended by `amount`, 0–1) the pixels of an overview `image`, rendered
    /// with `camera` and with per-pixel hit distances `depth_mm`, whose hit point lies next to an
    /// unseen wall voxel. Returns the number of pixels tinted. The overview must be an isosurface
    /// render of the same wall (its hits are then on the surface the wall voxels line).
    pub fn tint_unseen(
        &self,
        image: &mut Image,
        camera: &Camera,
        depth_mm: &[f32],
        color: Rgb,
        amount: f32,
    ) -> Result<usize, CoverageError> {
        let [w, h] = camera.size();
        if depth_mm.len() != w * h || [image.width(), image.height()] != [w, h] {
            return Err(CoverageError::FrameSize {
                camera: [w, h],
                depth: depth_mm.len(),
            });
        }
        let mut tinted = 0;
        for (n, depth) in depth_mm.iter().enumerate() {
            if !depth.is_finite() {
                continue;
            }
            let (x, y) = (n % w, n / w);
            let Some(hit) = camera.point_at(x, y, f64::from(*depth)) else {
                continue;
            };
            if self.unseen_near(hit) {
                image.blend(x as i64, y as i64, color, amount);
                tinted += 1;
            }
        }
        Ok(tinted)
    }

    /// Whether an unseen wall voxel is a corner of the grid cell holding `p_mm` (world mm): a
    /// hit there shows wall never seen.
    pub fn unseen_near(&self, p_mm: DVec3) -> bool {
        self.cell_corners(p_mm)
            .into_iter()
            .flatten()
            .any(|c| self.wall.get(c) && !self.seen.get(c))
    }
}

/// A fixed-size set of bits.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Bits(Vec<u64>);

impl Bits {
    fn new(len: usize) -> Self {
        Self(vec![0; len.div_ceil(64)])
    }

    fn get(&self, n: usize) -> bool {
        self.0[n / 64] >> (n % 64) & 1 == 1
    }

    fn set(&mut self, n: usize) {
        self.0[n / 64] |= 1 << (n % 64);
    }

    fn or(&mut self, other: &Bits) {
        for (a, b) in self.0.iter_mut().zip(&other.0) {
            *a |= b;
        }
    }

    fn count(&self) -> usize {
        self.0.iter().map(|w| w.count_ones() as usize).sum()
    }
}

#[cfg(test)]
mod tests;
