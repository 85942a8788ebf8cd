//! Ray set-up in voxel space and the 3-D DDA over bricks: the CPU form of the paper's ray-start
//! and ray-length images (§3.2). Instead of rasterising brick faces, every ray walks the brick
//! grid (Amanatides & Woo) and yields one [`Segment`] per brick it crosses; the sampler skips the
//! inactive ones.
//!
//! Distances along a ray (`t`) are millimetres from the eye in every space: the ray is moved
//! into voxel space once, keeping its world parametrisation, so its voxel-space direction is
//! not a unit vector (and not even of constant length per mm on sheared or anisotropic grids).

use super::bricks::BRICK_VOX;
use glam::{DAffine3, DVec3, Vec3};

/// A ray in voxel index space, parametrised by millimetres from the eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VoxelRay {
    /// The eye, voxel index space.
    pub origin: DVec3,
    /// Voxel index units per millimetre travelled along the ray.
    pub direction: DVec3,
}

impl VoxelRay {
    /// Moves a world ray (eye in mm, unit direction) into voxel space.
    pub fn new(voxel_from_world: &DAffine3, eye_mm: DVec3, direction: DVec3) -> Self {
        Self {
            origin: voxel_from_world.transform_point3(eye_mm),
            direction: voxel_from_world.transform_vector3(direction),
        }
    }

    /// The point at `t_mm`, voxel index space.
    pub fn at(&self, t_mm: f64) -> DVec3 {
        self.origin + self.direction * t_mm
    }

    /// The interval of `t` (mm) inside the box `[0, extent]` of voxel positions (voxel centres'
    /// hull), clipped to `t ≥ t_min`; `None` when empty.
    pub fn clip(&self, extent: DVec3, t_min: f64) -> Option<(f64, f64)> {
        let (mut t0, mut t1) = (t_min, f64::INFINITY);
        for axis in 0..3 {
            let (o, d, hi) = (self.origin[axis], self.direction[axis], extent[axis]);
            if d == 0.0 {
                if o < 0.0 || o > hi {
                    return None;
                }
                continue;
            }
            let (a, b) = ((0.0 - o) / d, (hi - o) / d);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        (t0 <= t1 && t1.is_finite()).then_some((t0, t1))
    }
}

/// The part `[t0, t1]` (mm) of a ray inside one brick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Where the ray enters the brick (or starts), mm from the eye.
    pub t0: f32,
    /// Where it leaves the brick (or ends), mm from the eye.
    pub t1: f32,
    /// Linear index of the brick in its [`super::BrickGrid`].
    pub brick: u32,
}

/// The bricks a ray crosses between two distances, in order, as [`Segment`]s that are contiguous
/// (`t1` of one is `t0` of the next) and cover the interval exactly. A small `Copy` state on the
/// stack; no allocation.
#[derive(Debug, Clone, Copy)]
pub struct BrickDda {
    /// The brick the walk is in.
    pub(crate) cell: [i32; 3],
    /// −1, 0 or +1 per axis: the direction the walk moves in.
    pub(crate) step: [i32; 3],
    /// Where the ray meets the next brick face per axis, mm.
    pub(crate) t_next: [f32; 3],
    /// Distance between brick faces per axis, mm.
    pub(crate) t_delta: [f32; 3],
    /// Where the walk is, mm.
    pub(crate) t: f32,
    /// Where the walk ends, mm.
    pub(crate) t_end: f32,
    /// Bricks per axis.
    pub(crate) bricks: [i32; 3],
}

impl BrickDda {
    /// The walk along `ray` over `[t_start, t_end]` (mm, already clipped to the volume) through
    /// a grid of `bricks` bricks of [`BRICK_VOX`] voxels.
    pub fn new(ray: &VoxelRay, (t_start, t_end): (f64, f64), bricks: [usize; 3]) -> Self {
        let brick = BRICK_VOX as f64;
        let start = ray.at(t_start) / brick;
        let bricks = bricks.map(|b| i32::try_from(b).unwrap_or(i32::MAX));
        let mut dda = Self {
            cell: [0; 3],
            step: [0; 3],
            t_next: [f32::INFINITY; 3],
            t_delta: [f32::INFINITY; 3],
            t: t_start as f32,
            t_end: t_end as f32,
            bricks,
        };
        for axis in 0..3 {
            // Truncation instead of `floor` (a library call on baseline x86-64): the two differ
            // only below 0, which the clamp maps to brick 0 either way.
            let cell = (start[axis] as i32).clamp(0, bricks[axis] - 1);
            dda.cell[axis] = cell;
            let (o, d) = (ray.origin[axis], ray.direction[axis]);
            if d > 0.0 {
                dda.step[axis] = 1;
                dda.t_next[axis] = ((f64::from(cell + 1) * brick - o) / d) as f32;
                dda.t_delta[axis] = (brick / d) as f32;
            } else if d < 0.0 {
                dda.step[axis] = -1;
                dda.t_next[axis] = ((f64::from(cell) * brick - o) / d) as f32;
                dda.t_delta[axis] = (-brick / d) as f32;
            }
        }
        dda
    }

    /// The axis whose brick face comes next (ties go to the lower axis). Selects, not branches:
    /// which axis comes next is data, and a mispredicted branch per step cost more than the
    /// step.
    #[inline]
    fn next_axis(&self) -> usize {
        let [x, y, z] = self.t_next;
        let (nearer, t) = if y < x { (1, y) } else { (0, x) };
        std::hint::select_unpredictable(z < t, 2, nearer)
    }
}

impl Iterator for BrickDda {
    type Item = Segment;

    #[inline]
    fn next(&mut self) -> Option<Segment> {
        // NaN-safe: a NaN distance ends the walk too.
        if self.t.partial_cmp(&self.t_end) != Some(std::cmp::Ordering::Less) {
            return None;
        }
        let axis = self.next_axis();
        let next_cell = self.cell[axis] + self.step[axis];
        // The grid's faces lie at or beyond the volume's (positions [0, n − 1]), so a walk that
        // steps out of the grid before t_end does so by rounding only: the brick runs to t_end.
        let leaving = !(0..self.bricks[axis]).contains(&next_cell);
        let t1 = if leaving {
            self.t_end
        } else {
            self.t_next[axis].clamp(self.t, self.t_end)
        };
        let [i, j, k] = self.cell;
        let brick = (i + self.bricks[0] * (j + self.bricks[1] * k)) as u32;
        let segment = Segment {
            t0: self.t,
            t1,
            brick,
        };
        self.t = t1;
        self.cell[axis] = next_cell;
        self.t_next[axis] += self.t_delta[axis];
        Some(segment)
    }
}

/// A ray's voxel-space origin and direction in `f32`, for the sample loop.
#[inline]
pub(crate) fn ray_f32(ray: &VoxelRay) -> (Vec3, Vec3) {
    (ray.origin.as_vec3(), ray.direction.as_vec3())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;

    fn check_walk(ray: &VoxelRay, dims: [usize; 3]) {
        let extent = DVec3::from(dims.map(|n| (n - 1) as f64));
        let bricks = dims.map(|n| (n - 1).div_ceil(BRICK_VOX).max(1));
        let Some(range) = ray.clip(extent, 0.0) else {
            return;
        };
        let segments: Vec<Segment> = BrickDda::new(ray, range, bricks).collect();
        let (t0, t1) = (range.0 as f32, range.1 as f32);
        if t1 > t0 {
            assert_eq!(segments.first().map(|s| s.t0), Some(t0), "{ray:?}");
            assert_eq!(segments.last().map(|s| s.t1), Some(t1), "{ray:?}");
        }
        for pair in segments.windows(2) {
            assert_eq!(pair[0].t1, pair[1].t0, "{ray:?}");
        }
        let total = bricks[0] * bricks[1] * bricks[2];
        for s in &segments {
            assert!(s.t0 <= s.t1 && (s.brick as usize) < total);
            // The middle of a segment lies in its brick (within rounding).
            if s.t1 - s.t0 > 1e-3 {
                let p = ray.at(f64::from(0.5 * (s.t0 + s.t1))) / BRICK_VOX as f64;
                let b = s.brick as usize;
                let cell = [
                    b % bricks[0],
                    b / bricks[0] % bricks[1],
                    b / bricks[0] / bricks[1],
                ];
                for axis in 0..3 {
                    let c = cell[axis] as f64;
                    assert!(p[axis] >= c - 1e-3 && p[axis] <= c + 1.0 + 1e-3, "{ray:?}");
                }
            }
        }
    }

    #[test]
    fn segments_are_contiguous_and_cover_the_box_interval() {
        let mut rng = Rng::new(7);
        let dims = [37, 20, 29];
        for _ in 0..2000 {
            let mut r = || rng.unit();
            let origin = DVec3::new(r() * 60.0 - 10.0, r() * 40.0 - 10.0, r() * 50.0 - 10.0);
            let direction = DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize() * (0.5 + r());
            check_walk(&VoxelRay { origin, direction }, dims);
        }
        // Axis-parallel rays, rays on brick faces and corners.
        for origin in [DVec3::splat(8.0), DVec3::new(8.0, 8.0, -3.0), DVec3::ZERO] {
            for direction in [DVec3::X, -DVec3::X, DVec3::Z, DVec3::new(1.0, 1.0, 1.0)] {
                check_walk(&VoxelRay { origin, direction }, dims);
            }
        }
    }

    #[test]
    fn clip_misses_and_looks_away() {
        let extent = DVec3::splat(10.0);
        let away = VoxelRay {
            origin: DVec3::splat(-1.0),
            direction: -DVec3::X,
        };
        assert_eq!(away.clip(extent, 0.0), None);
        let parallel_outside = VoxelRay {
            origin: DVec3::new(5.0, 11.0, 5.0),
            direction: DVec3::X,
        };
        assert_eq!(parallel_outside.clip(extent, 0.0), None);
        let through = VoxelRay {
            origin: DVec3::new(-2.0, 5.0, 5.0),
            direction: DVec3::X * 2.0,
        };
        assert_eq!(through.clip(extent, 0.0), Some((1.0, 6.0)));
        assert_eq!(through.clip(extent, 3.0), Some((3.0, 6.0)));
    }
}
