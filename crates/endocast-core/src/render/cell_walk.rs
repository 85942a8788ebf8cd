//! The exact isosurface search: a cell walk (Amanatides and Woo, over the trilinear cells of the
//! whole volume) visits the cells along a ray in order, steps over each brick whose cells cannot
//! hold the isovalue at once (the brick level of the [`CellMask`]), skips the cells whose bit is
//! clear, and in each remaining cell solves the trilinear field along the ray exactly for its
//! first crossing ([`CellCubic`]). No crossing is missed whatever the step, however thin the
//! feature, and the depth is the trilinear field's own to `f32` precision.
//!
//! [`CellDda`] is the walk of one ray; `simd::cells8` walks eight rays at once, one per lane,
//! operation for operation the same (the same cells, the same distances, the same bits).

use super::bricks::BRICK_VOX;
use super::cell_mask::{is_set, CellMask};
use super::march::RayMarch;
use super::sample::SampleGrid;
use super::trilinear_root::{range_over_box, CellCubic};
use super::voxel_grid::VoxelGrid;
use glam::Vec3;

/// How far past the last crossing found a cell face may be taken as a crossing of its own, mm:
/// far above the rounding of a face's position, far below any feature.
const FACE_MM: f32 = 1e-4;

/// What the exact search reads: the voxels, the cells that can hold the isovalue, and the
/// isovalue (stored units).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CellWalk<'a> {
    pub voxels: &'a VoxelGrid<'a>,
    pub cells: &'a CellMask,
    pub iso: f32,
}

/// Where a ray's walk stands with the crossings: the direction of the next one, whether the
/// walk is on its near side (up to the last cell solved: the cells and bricks skipped since lie
/// wholly on one side), and the last crossing found, mm (−∞ before the first).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Side {
    pub rising: bool,
    pub before: bool,
    pub last_hit: f32,
}

impl Side {
    /// The side of a fresh walk: its first crossing rises where `rising`, and it starts on the
    /// near side of it where `before` (else it must first leave the far side).
    pub fn new((rising, before): (bool, bool)) -> Self {
        Self {
            rising,
            before,
            last_hit: f32::NEG_INFINITY,
        }
    }
}

impl CellWalk<'_> {
    /// The first crossing of the isovalue along `march` (from below to at or above it where
    /// `rising`, the other way otherwise), mm from the eye; the march is left with the brick of
    /// the hit pending and its next sample the first at or past the hit (what follows an
    /// isosurface search).
    /// `before`: whether the ray starts on the near side of that crossing (else it must
    /// first leave the far side).
    pub fn first_hit(&self, march: &mut RayMarch, side: (bool, bool)) -> Option<f32> {
        let hit = self.walk(march, side, |_| true)?;
        march.found_at(hit);
        Some(hit)
    }

    /// The successive crossings along `march`, the first as [`Self::first_hit`] finds it, each
    /// next one in the other direction, into `depths_mm` (left as they are past the last).
    pub fn crossings(&self, march: &mut RayMarch, side: (bool, bool), depths_mm: &mut [f32]) {
        let mut slots = depths_mm.iter_mut();
        let Some(first) = slots.next() else {
            return;
        };
        let mut slot = Some(first);
        let last = self.walk(march, side, |t| {
            if let Some(depth) = slot.take() {
                *depth = t;
            }
            slot = slots.next();
            slot.is_none()
        });
        if let Some(t) = last {
            march.found_at(t);
        }
    }

    /// The walk of a fresh march's ray ([`CellDda::new`]).
    pub fn dda(&self, march: &RayMarch) -> CellDda {
        let (t_start, t_end) = march.span();
        CellDda::new(&march.grid(), (t_start, t_end), self.voxels.max_base)
    }

    /// Walks `march` handing each crossing in turn (the first as `side` says, then
    /// alternating) to `stop`, until it says to stop at one: that crossing, mm.
    fn walk(
        &self,
        march: &RayMarch,
        side: (bool, bool),
        mut stop: impl FnMut(f32) -> bool,
    ) -> Option<f32> {
        let line = march.grid();
        let mut dda = self.dda(march);
        let mut side = Side::new(side);
        while dda.running() {
            let Some(cells) = self.cells.of(self.cells.brick_of(dda.cell)) else {
                dda.leave_brick(&line, self.voxels.max_base);
                continue;
            };
            let (cell, span) = dda.step(self.voxels.max_base);
            let [i, j, k] = cell.map(|c| c as usize % BRICK_VOX);
            if is_set(cells, i + BRICK_VOX * (j + BRICK_VOX * k)) {
                if let Some(hit) = self.in_cell(&line, cell, span, &mut side, &mut stop) {
                    return Some(hit);
                }
            }
        }
        None
    }

    /// The crossing in cell `cell` (its lowest voxel) over `(ta, tb)` mm of `line` at which
    /// `stop` says to stop, `side` kept up to date.
    pub fn in_cell(
        &self,
        line: &SampleGrid,
        cell: [i32; 3],
        (ta, tb): (f32, f32),
        side: &mut Side,
        stop: &mut impl FnMut(f32) -> bool,
    ) -> Option<f32> {
        let [sx, sy, sz] = self.voxels.stride;
        // Cells lie in [0, max_base] per axis (the walk keeps them there): the casts are exact.
        let index = cell[0] as usize * sx + cell[1] as usize * sy + cell[2] as usize * sz;
        let corners = self.voxels.corners(index);
        let base = Vec3::new(cell[0] as f32, cell[1] as f32, cell[2] as f32);
        let entry = line.at(ta) - base;
        if let Some(above) = self.one_side(corners, (entry, line.at(tb) - base)) {
            let past = above == side.rising;
            // No crossing in the segment, and none at its entry face unless the walk comes
            // from the near side into values past the isovalue (the face rule below).
            if !(past && side.before) {
                side.before = !past;
                return None;
            }
        }
        let cubic = CellCubic::new(corners, entry, line.direction);
        let (iso, len) = (f64::from(self.iso), f64::from(tb - ta));
        // Where the walk was on the near side and this cell's entry is past the isovalue, the
        // crossing is the shared face: the neighbours' cubics, each from its own entry point,
        // may differ there in the last bits. (Not where a crossing was just found there.)
        let at_face =
            side.before && cubic.is_past(iso, side.rising, 0.0) && ta > side.last_hit + FACE_MM;
        let mut found = if at_face {
            Some(0.0)
        } else {
            cubic.first_crossing(iso, side.rising, (0.0, len))
        };
        // A cubic crosses a value at most three times.
        for _ in 0..3 {
            let Some(s) = found else { break };
            let t = (ta + s as f32).min(tb);
            (side.rising, side.last_hit) = (!side.rising, t);
            if stop(t) {
                return Some(t);
            }
            found = cubic.first_crossing(iso, side.rising, (s, len));
        }
        side.before = !cubic.is_past(iso, side.rising, len);
        None
    }
}

impl CellWalk<'_> {
    /// Whether the field on the segment `(a, b)` (cell-local) of the cell with corners
    /// `corners` lies wholly above the isovalue (`Some(true)`) or wholly below it
    /// (`Some(false)`), clear of it by more than the
    /// rounding of the segment's ends and values; `None` where it may cross. The cheap test
    /// ahead of the cubic: a cell whose corners straddle the isovalue often holds no crossing on
    /// the ray's short segment through it (a corner clipped, a wall grazed).
    #[inline]
    fn one_side(&self, corners: [glam::Vec4; 2], (a, b): (Vec3, Vec3)) -> Option<bool> {
        let (least, greatest) = range_over_box(corners, a, b);
        let spread =
            corners[0].max(corners[1]).max_element() - corners[0].min(corners[1]).min_element();
        let margin = 1e-3 * (spread + self.iso.abs()) + 1e-3;
        if greatest < self.iso - margin {
            Some(false)
        } else if least >= self.iso + margin {
            Some(true)
        } else {
            None
        }
    }
}

/// One ray's walk over the trilinear cells of the volume (Amanatides and Woo), in the order the
/// ray meets them; a brick at a time where its cells need not be visited
/// ([`Self::leave_brick`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CellDda {
    /// The cell the walk is in (its lowest voxel).
    pub cell: [i32; 3],
    /// −1, 0 or +1 per axis.
    pub step: [i32; 3],
    /// The reciprocal of the ray's direction per axis (mm per voxel unit).
    pub inverse: [f32; 3],
    /// Where the ray meets the next cell face per axis (∞ along an axis it does not move
    /// along), and the distance between faces, mm.
    pub t_next: [f32; 3],
    pub t_delta: [f32; 3],
    /// Where the walk is and where it ends, mm: it runs while `t < t_end`.
    pub t: f32,
    pub t_end: f32,
}

impl CellDda {
    /// The walk along `line` over `(t, t_end)` mm (inside the volume) in a volume whose last
    /// cell per axis is `max_base`.
    pub fn new(line: &SampleGrid, (t, t_end): (f32, f32), max_base: [i32; 3]) -> Self {
        let start = line.at(t);
        let mut walk = Self {
            cell: [0; 3],
            step: [0; 3],
            inverse: line.direction.recip().to_array(),
            t_next: [f32::INFINITY; 3],
            t_delta: [f32::INFINITY; 3],
            t,
            t_end,
        };
        for axis in 0..3 {
            let d = line.direction[axis];
            walk.step[axis] = i32::from(d > 0.0) - i32::from(d < 0.0);
            walk.t_delta[axis] = walk.inverse[axis].abs();
            walk.cell[axis] = cell_at(start[axis], (0, max_base[axis]));
        }
        walk.t_next = walk.faces(line);
        walk
    }

    /// Whether the walk has cells left.
    #[inline]
    pub fn running(&self) -> bool {
        self.t < self.t_end
    }

    /// The cell the walk is in and the ray's span in it, mm; then steps into the next cell (the
    /// walk ends where that lies past the volume's last cell).
    #[inline]
    pub fn step(&mut self, max_base: [i32; 3]) -> ([i32; 3], (f32, f32)) {
        let axis = next_axis(self.t_next);
        let (t, cell) = (self.t, self.cell);
        let t_exit = self.t_next[axis].max(t).min(self.t_end);
        let next = cell[axis] + self.step[axis];
        self.cell[axis] = next;
        self.t_next[axis] += self.t_delta[axis];
        self.t = if next < 0 || next > max_base[axis] {
            self.t_end
        } else {
            t_exit
        };
        (cell, (t, t_exit))
    }

    /// Leaves the brick the walk is in at once, through the face the ray meets first: the walk
    /// is then in the cell behind that face (and ends where that lies past the volume).
    pub fn leave_brick(&mut self, line: &SampleGrid, max_base: [i32; 3]) {
        let edge = BRICK_VOX as i32;
        let first = self.cell.map(|c| c & !(edge - 1));
        let exits: [f32; 3] = std::array::from_fn(|axis| {
            let face = first[axis] + if self.step[axis] > 0 { edge } else { 0 };
            self.face_t(line, axis, face as f32)
        });
        let axis = next_axis(exits);
        let t = exits[axis].max(self.t);
        let at = line.at(t);
        for other in 0..3 {
            let last = (first[other] + edge - 1).min(max_base[other]);
            self.cell[other] = cell_at(at[other], (first[other], last));
        }
        let next = if self.step[axis] > 0 {
            first[axis] + edge
        } else {
            first[axis] - 1
        };
        self.cell[axis] = next;
        self.t_next = self.faces(line);
        self.t = if next < 0 || next > max_base[axis] {
            self.t_end
        } else {
            t
        };
    }

    /// Where the ray meets the next cell face per axis from the cell it is in.
    fn faces(&self, line: &SampleGrid) -> [f32; 3] {
        std::array::from_fn(|axis| {
            let up = if self.step[axis] > 0 { 1.0 } else { 0.0 };
            self.face_t(line, axis, self.cell[axis] as f32 + up)
        })
    }

    /// Where the ray meets the plane at `face` of `axis`, mm (∞ where it does not move along
    /// the axis).
    #[inline]
    fn face_t(&self, line: &SampleGrid, axis: usize, face: f32) -> f32 {
        if self.step[axis] == 0 {
            f32::INFINITY
        } else {
            (face - line.origin[axis]) * self.inverse[axis]
        }
    }
}

/// The cell along one axis holding position `p`, kept in `[lo, hi]`.
#[inline]
fn cell_at(p: f32, (lo, hi): (i32, i32)) -> i32 {
    // Clamped as a float first, then truncated (no `floor` call; a NaN clamps to `lo`).
    p.max(lo as f32).min(hi as f32) as i32
}

/// The axis whose cell face comes next (ties to the lower axis). Selects, not branches, as
/// the brick walk does: which axis comes next is data.
#[inline]
fn next_axis([x, y, z]: [f32; 3]) -> usize {
    let (nearer, t) = if y < x { (1, y) } else { (0, x) };
    std::hint::select_unpredictable(z < t, 2, nearer)
}
