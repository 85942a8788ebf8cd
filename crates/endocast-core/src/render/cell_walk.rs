//! The exact isosurface search: the march's brick walk skips the bricks that cannot hold the
//! isovalue, a cell walk (Amanatides and Woo, over the trilinear cells) visits the cells of each
//! active brick in ray order and skips those whose bit in the [`CellMask`] is clear, and in each
//! remaining cell the trilinear field along the ray is solved exactly for its first crossing
//! ([`CellCubic`]). No crossing is missed whatever the step, however thin the feature, and the
//! depth is the trilinear field's own to `f32` precision.

use super::bricks::BRICK_VOX;
use super::cell_mask::{is_set, BrickCells, CellMask};
use super::march::RayMarch;
use super::sample::SampleGrid;
use super::traverse::Segment;
use super::trilinear_root::CellCubic;
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

/// A ray's line with the reciprocals of its direction (voxel units per mm), for the cell
/// walk's face distances.
#[derive(Debug, Clone, Copy)]
struct CellRay {
    line: SampleGrid,
    inverse: Vec3,
}

impl CellWalk<'_> {
    /// The first crossing of the isovalue along `march` (from below to at or above it where
    /// `rising`, the other way otherwise), mm from the eye; the march is left with the brick of
    /// the hit pending and its next sample the first at or past the hit (what follows an
    /// isosurface search).
    /// `before`: whether the ray starts on the near side of that crossing (else it must
    /// first leave the far side).
    pub fn first_hit(&self, march: &mut RayMarch, (rising, before): (bool, bool)) -> Option<f32> {
        self.walk(march, (rising, before), |_| true)
    }

    /// The successive crossings along `march`, the first as [`Self::first_hit`] finds it, each
    /// next one in the other direction, into `depths_mm` (left as they are past the last).
    pub fn crossings(
        &self,
        march: &mut RayMarch,
        (rising, before): (bool, bool),
        depths_mm: &mut [f32],
    ) {
        let mut slots = depths_mm.iter_mut();
        let Some(first) = slots.next() else {
            return;
        };
        let mut slot = Some(first);
        self.walk(march, (rising, before), |t| {
            if let Some(depth) = slot.take() {
                *depth = t;
            }
            slot = slots.next();
            slot.is_none()
        });
    }

    /// Walks `march` handing each crossing in turn (the first in the direction `rising`, from
    /// the near side where `before`, then alternating) to `stop`, until it says to stop at one:
    /// that crossing, mm.
    fn walk(
        &self,
        march: &mut RayMarch,
        (mut rising, before): (bool, bool),
        mut stop: impl FnMut(f32) -> bool,
    ) -> Option<f32> {
        let line = march.grid();
        let ray = CellRay {
            line,
            inverse: line.direction.recip(),
        };
        let mut side = Side {
            rising: &mut rising,
            before,
            last_hit: f32::NEG_INFINITY,
            stop: &mut stop,
        };
        march.find(
            |brick| self.cells.of(brick),
            |segment, cells| self.in_brick(&ray, segment, cells, &mut side),
        )
    }

    /// The crossing inside one brick's `segment` of the ray (whose cells are `cells`) at which
    /// `side` stops.
    fn in_brick<F: FnMut(f32) -> bool>(
        &self,
        ray: &CellRay,
        segment: Segment,
        cells: &BrickCells,
        side: &mut Side<'_, F>,
    ) -> Option<f32> {
        let mut walk = CellDda::new(ray, segment, self.voxels.max_base)?;
        while let Some((cell, bit, span)) = walk.next() {
            if is_set(cells, bit) {
                if let Some(hit) = self.in_cell(&ray.line, cell, span, side) {
                    return Some(hit);
                }
            }
        }
        None
    }

    /// The crossing in cell `cell` (its lowest voxel) over `(ta, tb)` mm of `line` at which
    /// `side` stops.
    fn in_cell<F: FnMut(f32) -> bool>(
        &self,
        line: &SampleGrid,
        cell: [i32; 3],
        (ta, tb): (f32, f32),
        side: &mut Side<'_, F>,
    ) -> Option<f32> {
        let [sx, sy, sz] = self.voxels.stride;
        // Cells lie in [0, max_base] per axis (the walk keeps them there): the casts are exact.
        let index = cell[0] as usize * sx + cell[1] as usize * sy + cell[2] as usize * sz;
        let corners = self.voxels.corners(index);
        let base = Vec3::new(cell[0] as f32, cell[1] as f32, cell[2] as f32);
        let cubic = CellCubic::new(corners, line.at(ta) - base, line.direction);
        let (iso, len) = (f64::from(self.iso), f64::from(tb - ta));
        // Where the walk was on the near side and this cell's entry is past the isovalue, the
        // crossing is the shared face: the neighbours' cubics, each from its own entry point,
        // may differ there in the last bits. (Not where a crossing was just found there.)
        let at_face =
            side.before && cubic.is_past(iso, *side.rising, 0.0) && ta > side.last_hit + FACE_MM;
        let mut found = if at_face {
            Some(0.0)
        } else {
            cubic.first_crossing(iso, *side.rising, (0.0, len))
        };
        // A cubic crosses a value at most three times.
        for _ in 0..3 {
            let Some(s) = found else { break };
            let t = (ta + s as f32).min(tb);
            (*side.rising, side.last_hit) = (!*side.rising, t);
            if (side.stop)(t) {
                return Some(t);
            }
            found = cubic.first_crossing(iso, *side.rising, (s, len));
        }
        side.before = !cubic.is_past(iso, *side.rising, len);
        None
    }
}

/// The direction of the next crossing, whether the walk is on its near side (up to the last
/// cell solved: the cells and bricks skipped since lie wholly on one side), and what decides
/// where a walk stops.
struct Side<'a, F> {
    rising: &'a mut bool,
    before: bool,
    /// The last crossing found, mm (−∞ before the first).
    last_hit: f32,
    stop: &'a mut F,
}

/// The cells of one brick a ray segment crosses, in order (Amanatides and Woo).
#[derive(Debug, Clone, Copy)]
struct CellDda {
    /// The cell the walk is in (its lowest voxel), and its place in the brick's bits
    /// (`i + 8 j + 64 k` inside the brick).
    cell: [i32; 3],
    bit: i32,
    /// Cells left to step through per axis before the brick's face.
    left: [i32; 3],
    /// −1, 0 or +1 per axis, and the same step in bit places.
    step: [i32; 3],
    bit_step: [i32; 3],
    /// Where the ray meets the next cell face per axis, and the distance between faces, mm.
    t_next: [f32; 3],
    t_delta: [f32; 3],
    /// Where the walk is and where the segment ends, mm; NaN once the walk has ended.
    t: f32,
    t_end: f32,
}

impl CellDda {
    /// The walk over `segment` (one brick's part of `ray`) in a volume whose last cell per
    /// axis is `max_base`; `None` where the segment is empty.
    fn new(ray: &CellRay, segment: Segment, max_base: [i32; 3]) -> Option<Self> {
        let (t, t_end) = (segment.t0, segment.t1);
        // NaN-safe: an empty or NaN segment has no cell.
        if t_end.partial_cmp(&t) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let line = &ray.line;
        // The brick from the segment's middle (inside it, unlike its ends on the faces), the
        // first cell from its entry, kept inside the brick.
        let (mid, start) = (line.at(0.5 * (t + t_end)), line.at(t));
        let edge = BRICK_VOX as i32;
        let mut walk = Self {
            cell: [0; 3],
            bit: 0,
            left: [0; 3],
            step: [0; 3],
            bit_step: [0; 3],
            t_next: [f32::INFINITY; 3],
            t_delta: [f32::INFINITY; 3],
            t,
            t_end,
        };
        for (axis, place) in [1, edge, edge * edge].into_iter().enumerate() {
            let brick = ((mid[axis] / edge as f32).max(0.0) as i32).min(max_base[axis] / edge);
            let first = brick * edge;
            let last = (first + edge - 1).min(max_base[axis]);
            let c = (start[axis] as i32).clamp(first, last);
            walk.cell[axis] = c;
            walk.bit += (c - first) * place;
            let (o, d, inverse) = (line.origin[axis], line.direction[axis], ray.inverse[axis]);
            if d > 0.0 {
                (walk.step[axis], walk.left[axis]) = (1, last - c);
                walk.t_next[axis] = (c as f32 + 1.0 - o) * inverse;
                walk.t_delta[axis] = inverse;
            } else if d < 0.0 {
                (walk.step[axis], walk.left[axis]) = (-1, c - first);
                walk.t_next[axis] = (c as f32 - o) * inverse;
                walk.t_delta[axis] = -inverse;
            }
            walk.bit_step[axis] = walk.step[axis] * place;
        }
        Some(walk)
    }

    /// The cell the walk is in (its lowest voxel, and its bit place) and the ray's span in
    /// it, mm; then steps into the next cell. `None` once the segment or the brick has been
    /// left.
    #[inline]
    fn next(&mut self) -> Option<([i32; 3], usize, (f32, f32))> {
        if self.t.is_nan() {
            return None;
        }
        let axis = next_axis(self.t_next);
        let (t, cell, bit) = (self.t, self.cell, self.bit);
        let t_exit = self.t_next[axis].max(t).min(self.t_end);
        if t_exit >= self.t_end || self.left[axis] == 0 {
            self.t = f32::NAN;
        } else {
            self.t = t_exit;
            self.cell[axis] += self.step[axis];
            self.bit += self.bit_step[axis];
            self.left[axis] -= 1;
            self.t_next[axis] += self.t_delta[axis];
        }
        // `bit` stays in 0..512: each axis's place moves only while cells are left.
        Some((cell, bit as usize, (t, t_exit)))
    }
}

/// The axis whose cell face comes next (ties to the lower axis). Selects, not branches, as
/// the brick walk does: which axis comes next is data.
#[inline]
fn next_axis([x, y, z]: [f32; 3]) -> usize {
    let (nearer, t) = if y < x { (1, y) } else { (0, x) };
    std::hint::select_unpredictable(z < t, 2, nearer)
}
