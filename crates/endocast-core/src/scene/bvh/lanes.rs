//! A packet's rays four at a time (a structure of arrays in SSE registers through
//! `glam::Vec4`): one box, or one triangle, against four rays at once.
//!
//! The triangle test is the scalar [`Tri::hit`]'s arithmetic, operation for operation, in
//! lanes (no fused multiply-adds either way), so a lane finds bit for bit what the scalar test
//! finds for its ray.

use super::{Aabb, PacketRay, Tri, EDGE_SLACK, PACKET};
use glam::{BVec4A, Mat4, Vec3A, Vec4};

/// Rays per group of [`Lanes`].
pub(super) const LANES: usize = 4;
/// Groups of a packet.
const GROUPS: usize = PACKET / LANES;

/// Every lane of a group (bit `k`: lane `k`).
pub(super) const ALL_LANES: u32 = 0b1111;

/// The lanes of ray `from`'s group from that ray on.
#[inline]
pub(super) fn from_lane(from: usize) -> u32 {
    (ALL_LANES << (from % LANES)) & ALL_LANES
}

/// Three coordinates of four rays (x, y and z lanes).
type Vec3x4 = [Vec4; 3];

/// A packet's rays in groups of four. Lanes past the packet's rays repeat its first ray's
/// start and direction (so that ranges over all lanes are the rays' ranges) with an empty
/// interval: they meet nothing.
pub(super) struct Lanes {
    pub(super) origin: [Vec3x4; GROUPS],
    pub(super) dir: [Vec3x4; GROUPS],
    pub(super) inv_dir: [Vec3x4; GROUPS],
    pub(super) t_min: [Vec4; GROUPS],
    pub(super) t_max: [Vec4; GROUPS],
    /// Groups holding rays.
    pub(super) groups: usize,
}

impl Lanes {
    /// Lanes of no ray.
    pub(super) fn new() -> Self {
        Self {
            origin: [[Vec4::ZERO; 3]; GROUPS],
            dir: [[Vec4::ZERO; 3]; GROUPS],
            inv_dir: [[Vec4::ZERO; 3]; GROUPS],
            t_min: [Vec4::ZERO; GROUPS],
            t_max: [Vec4::ZERO; GROUPS],
            groups: 0,
        }
    }

    /// Sets the lanes to `rays` (at least one, at most [`PACKET`]); the groups past them keep
    /// what they held.
    pub(super) fn fill(&mut self, rays: &[PacketRay]) {
        let pad = PacketRay {
            t_min: f32::INFINITY,
            t_max: f32::NEG_INFINITY,
            ..rays[0]
        };
        let groups = rays.len().div_ceil(LANES);
        self.groups = groups;
        let lanes = self;
        for g in 0..groups {
            let ray = |k: usize| rays.get(LANES * g + k).unwrap_or(&pad);
            // Four rays' first and last four numbers as columns, transposed into lanes.
            let head = |r: &PacketRay| Vec4::new(r.origin.x, r.origin.y, r.origin.z, r.dir.x);
            let tail = |r: &PacketRay| Vec4::new(r.dir.y, r.dir.z, r.t_min, r.t_max);
            let [r0, r1, r2, r3] = [ray(0), ray(1), ray(2), ray(3)];
            let a = Mat4::from_cols(head(r0), head(r1), head(r2), head(r3)).transpose();
            let b = Mat4::from_cols(tail(r0), tail(r1), tail(r2), tail(r3)).transpose();
            lanes.origin[g] = [a.x_axis, a.y_axis, a.z_axis];
            lanes.dir[g] = [a.w_axis, b.x_axis, b.y_axis];
            lanes.inv_dir[g] = lanes.dir[g].map(Vec4::recip);
            lanes.t_min[g] = b.z_axis;
            lanes.t_max[g] = b.w_axis;
        }
    }

    /// The highest `t_max` of the rays.
    pub(super) fn highest_t_max(&self) -> f32 {
        let t = self.t_max[..self.groups].iter();
        t.fold(Vec4::NEG_INFINITY, |m, &t| m.max(t)).max_element()
    }

    /// Which rays of group `group` meet `bounds` within their intervals (bit `k`: lane `k`),
    /// and where each enters it.
    #[inline]
    pub(super) fn meet(&self, group: usize, bounds: &Aabb) -> (u32, Vec4) {
        let (o, inv) = (&self.origin[group], &self.inv_dir[group]);
        let (mut near, mut far) = (self.t_min[group], self.t_max[group]);
        for axis in 0..3 {
            let t0 = (Vec4::splat(bounds.lo[axis]) - o[axis]) * inv[axis];
            let t1 = (Vec4::splat(bounds.hi[axis]) - o[axis]) * inv[axis];
            // A NaN (a ray in the plane of a slab, along it) leaves the interval as it is:
            // `min`/`max` return their second operand where either is NaN.
            near = t0.min(t1).max(near);
            far = t0.max(t1).min(far);
        }
        (near.cmple(far).bitmask(), near)
    }

    /// The first ray, from ray `from` on, that meets `bounds`, and where it enters it.
    #[inline]
    pub(super) fn first_meeting(&self, bounds: &Aabb, from: usize) -> Option<(usize, f32)> {
        let mut counted = from_lane(from);
        for group in from / LANES..self.groups {
            let (mask, near) = self.meet(group, bounds);
            let mask = mask & counted;
            if mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                return Some((LANES * group + lane, near[lane]));
            }
            counted = ALL_LANES;
        }
        None
    }

    /// Which rays of group `group` among `mask` (bit `k`: lane `k`) meet `tri` inside their
    /// intervals, and at what distance: [`Tri::hit`] four rays at a time.
    #[inline]
    pub(super) fn hit(&self, group: usize, tri: &Tri, mask: u32) -> (u32, Vec4) {
        let (o, d) = (&self.origin[group], &self.dir[group]);
        hit4(tri, o, d, (self.t_min[group], self.t_max[group]), mask)
    }

    /// The ranges over all lanes of the starts and inverse directions, the lowest `t_min` and
    /// the highest `t_max`; `None` where a start or an inverse direction is not finite.
    pub(super) fn ranges(&self) -> Option<Ranges> {
        let mut finite = BVec4A::splat(true);
        let (mut lo, mut hi) = ([[Vec4::INFINITY; 3]; 2], [[Vec4::NEG_INFINITY; 3]; 2]);
        let (mut t_min, mut t_max) = (Vec4::INFINITY, Vec4::NEG_INFINITY);
        for g in 0..self.groups {
            for (k, v) in [&self.origin[g], &self.inv_dir[g]].into_iter().enumerate() {
                for axis in 0..3 {
                    finite &= v[axis].is_finite_mask();
                    lo[k][axis] = lo[k][axis].min(v[axis]);
                    hi[k][axis] = hi[k][axis].max(v[axis]);
                }
            }
            t_min = t_min.min(self.t_min[g]);
            t_max = t_max.max(self.t_max[g]);
        }
        let low = |v: [Vec4; 3]| Vec3A::from_array(v.map(Vec4::min_element));
        let high = |v: [Vec4; 3]| Vec3A::from_array(v.map(Vec4::max_element));
        finite.all().then(|| Ranges {
            origin: (low(lo[0]), high(hi[0])),
            inv_dir: (low(lo[1]), high(hi[1])),
            t_min: t_min.min_element(),
            t_max: t_max.max_element(),
        })
    }
}

/// The ranges of a packet's rays ([`Lanes::ranges`]): (lowest, highest) per axis.
pub(super) struct Ranges {
    pub(super) origin: (Vec3A, Vec3A),
    pub(super) inv_dir: (Vec3A, Vec3A),
    pub(super) t_min: f32,
    pub(super) t_max: f32,
}

/// `a × b` per lane, in the scalar `Vec3::cross`'s order of operations.
#[inline]
fn cross(a: &Vec3x4, b: &Vec3x4) -> Vec3x4 {
    [
        a[1] * b[2] - b[1] * a[2],
        a[2] * b[0] - b[2] * a[0],
        a[0] * b[1] - b[0] * a[1],
    ]
}

/// `a · b` per lane, in the scalar `Vec3::dot`'s order of operations.
#[inline]
fn dot(a: &Vec3x4, b: &Vec3x4) -> Vec4 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// [`Tri::hit`] for the four rays `origin + t·dir` with `t` inside `(t_min, t_max)` per lane,
/// of which only the `lanes` (bit `k`: lane `k`) count: which lanes hit and the distances
/// (meaningful where they hit).
#[inline]
pub(super) fn hit4(
    tri: &Tri,
    origin: &Vec3x4,
    dir: &Vec3x4,
    (t_min, t_max): (Vec4, Vec4),
    lanes: u32,
) -> (u32, Vec4) {
    let splat = |v: glam::Vec3| [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)];
    let (e1, e2) = (splat(tri.e1), splat(tri.e2));
    let p = cross(dir, &e2);
    let det = dot(&e1, &p);
    let usable = det.cmpne(Vec4::ZERO) & det.is_finite_mask();
    let inv = Vec4::ONE / det;
    let v0 = splat(tri.v0);
    let s = [origin[0] - v0[0], origin[1] - v0[1], origin[2] - v0[2]];
    let u = dot(&s, &p) * inv;
    let in_u = u.cmpge(Vec4::splat(-EDGE_SLACK)) & u.cmple(Vec4::splat(1.0 + EDGE_SLACK));
    let candidates = (usable & in_u).bitmask() & lanes;
    if candidates == 0 {
        // Coherent rays mostly miss a triangle together.
        return (0, Vec4::ZERO);
    }
    let q = cross(&s, &e1);
    let v = dot(dir, &q) * inv;
    let out_v = v.cmplt(Vec4::splat(-EDGE_SLACK)) | (u + v).cmpgt(Vec4::splat(1.0 + EDGE_SLACK));
    let t = dot(&e2, &q) * inv;
    let inside = t.cmpgt(t_min) & t.cmplt(t_max);
    ((!out_v & inside).bitmask() & candidates, t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;
    use glam::Vec3;

    fn random(s: &mut Rng) -> Vec3 {
        (s.vec() * 10.0).as_vec3()
    }

    /// Triangles of every kind: ordinary, slivers, with two equal corners, with three
    /// collinear corners, of zero size.
    fn triangles(s: &mut Rng) -> Vec<Tri> {
        let mut tris = Vec::new();
        for k in 0..200 {
            let (a, b, c) = (random(s), random(s), random(s));
            let corners = match k % 5 {
                0 | 1 => [a, b, c],
                2 => [a, b, a + (b - a) * 0.5 + (c - a) * 1e-6],
                3 => [a, b, b],
                _ => [a, a, a],
            };
            let [a, b, c] = if k % 10 == 4 {
                [a, b, a + (b - a) * 2.0]
            } else {
                corners
            };
            tris.push(Tri {
                v0: a,
                e1: b - a,
                e2: c - a,
            });
        }
        tris
    }

    /// Points aimed at on `tri`: its corners, the middles of its edges, points just outside
    /// its edges, inside, and anywhere near it.
    fn targets(tri: &Tri, s: &mut Rng) -> Vec<Vec3> {
        let at = |u: f32, v: f32| tri.v0 + tri.e1 * u + tri.e2 * v;
        let (u, v) = (s.unit() as f32, s.unit() as f32);
        vec![
            at(0.0, 0.0),
            at(1.0, 0.0),
            at(0.0, 1.0),
            at(0.5, 0.0),
            at(0.0, 0.5),
            at(0.5, 0.5),
            at(-EDGE_SLACK, 0.3),
            at(0.5 + EDGE_SLACK, 0.5),
            at(u * 0.5, v * 0.5),
            at(u, v),
            at(u, v) + random(s) * 0.01,
        ]
    }

    #[test]
    fn four_lanes_find_bit_for_bit_what_the_scalar_test_finds() {
        let mut s = Rng::new(19);
        let (mut hits, mut tests) = (0, 0);
        for tri in triangles(&mut s) {
            let aims = targets(&tri, &mut s);
            for chunk in aims.chunks(LANES) {
                let mut rays = [(Vec3::ZERO, Vec3::X, 0.0f32, 0.0f32); LANES];
                for (ray, &aim) in rays.iter_mut().zip(chunk) {
                    let origin = random(&mut s) * 3.0;
                    // Some rays along the plane of the triangle, some of length 0.
                    let dir = match s.next_u64() % 8 {
                        0 => tri.e1.normalize_or_zero(),
                        1 => Vec3::ZERO,
                        _ => (aim - origin).normalize_or_zero(),
                    };
                    let t_max = if s.unit() < 0.2 { 1.0 } else { 1e6 };
                    *ray = (origin, dir, 0.0, t_max);
                }
                let lane = |f: fn(&(Vec3, Vec3, f32, f32)) -> Vec3| -> Vec3x4 {
                    let v: Vec<Vec3> = rays.iter().map(f).collect();
                    [0, 1, 2].map(|a| Vec4::new(v[0][a], v[1][a], v[2][a], v[3][a]))
                };
                let (o, d) = (lane(|r| r.0), lane(|r| r.1));
                let bounds = (Vec4::from(rays.map(|r| r.2)), Vec4::from(rays.map(|r| r.3)));
                // Now and then only some lanes count.
                let counted = if s.unit() < 0.3 {
                    (s.next_u64() % 16) as u32
                } else {
                    ALL_LANES
                };
                let (mask, t) = hit4(&tri, &o, &d, bounds, counted);
                for (k, ray) in rays.iter().enumerate() {
                    let scalar = tri.hit(ray.0, ray.1, ray.2, ray.3);
                    let scalar = scalar.filter(|_| counted >> k & 1 == 1);
                    let four = (mask >> k & 1 == 1).then(|| t[k]);
                    assert_eq!(
                        scalar.map(f32::to_bits),
                        four.map(f32::to_bits),
                        "{tri:?} ray {ray:?}"
                    );
                    hits += usize::from(scalar.is_some());
                    tests += 1;
                }
            }
        }
        assert!(hits > tests / 8 && hits < tests, "{hits} hits of {tests}");
    }
}
