//! Rays traced through the hierarchy together (a block of pixels: neighbouring rays visit
//! nearly the same nodes). The packet walks the tree once: a node is entered when any of its rays
//! meets the node's box, and each ray still meets a leaf's triangles only where it meets the
//! leaf's box, with its own distance bound — so every ray finds exactly the hits it finds alone.
//!
//! A node's rays are tried from the first one that met its parent on (rays before it missed
//! the parent, and bounds only shrink): in a coherent packet the first try usually answers.
//! Before that, the packet's bounds (the ranges of its rays' starts, inverse directions and
//! distances) rule out at once the boxes that no ray of it can meet, with a margin that keeps
//! the test on the safe side of rounding. Boxes are tested against four rays at a time
//! (`Lanes`, in SSE registers through `glam::Vec4`).

use super::{Aabb, Bvh, PacketRay};
use glam::{BVec3A, Vec3, Vec3A, Vec4};

/// Relative margin of [`Bounds::misses`]: a box is ruled out only when every ray misses it by
/// more than this share of the distances involved (far above `f32` rounding).
const MARGIN: f32 = 1e-4;

/// Rays walked through the tree as one packet at most (longer slices go in parts).
pub const PACKET: usize = 64;

impl Bvh {
    /// [`Bvh::traverse`] for many rays at once: calls `on_hit(ray, t, triangle)` for every
    /// triangle ray `rays[ray]` meets with `t_min < t < t_max`; `on_hit` returns the ray's new
    /// `t_max` (written back into `rays`). Each ray gets the hits it gets alone, in another
    /// order.
    pub fn traverse_packet(
        &self,
        rays: &mut [PacketRay],
        mut on_hit: impl FnMut(usize, f32, u32) -> f32,
    ) {
        for (part, chunk) in rays.chunks_mut(PACKET).enumerate() {
            let base = part * PACKET;
            self.walk(chunk, &mut |ray, t, tri| on_hit(base + ray, t, tri));
        }
    }

    /// The nearest hit of each ray in `(t_min, t_max)`: distance and triangle, into `best`
    /// (one per ray, `None` where it meets nothing). Between hits at the same distance the
    /// lower triangle index wins, whatever the order of the walk.
    pub fn nearest_each(&self, rays: &mut [PacketRay], best: &mut [Option<(f32, u32)>]) {
        best.fill(None);
        self.traverse_packet(rays, |ray, t, tri| {
            // `t` is at most the best distance so far (the bound lies just above it).
            let keep = best[ray].is_some_and(|(bt, bi)| bt < t || (bt == t && bi < tri));
            if !keep {
                best[ray] = Some((t, tri));
            }
            best[ray].map_or(t, |(bt, _)| bt).next_up()
        });
    }

    /// Walks one packet of at most [`PACKET`] rays.
    fn walk(&self, rays: &mut [PacketRay], on_hit: &mut dyn FnMut(usize, f32, u32) -> f32) {
        let n = rays.len();
        let mut inv_dir = [Vec3::ZERO; PACKET];
        for (inv, ray) in inv_dir.iter_mut().zip(rays.iter()) {
            *inv = ray.dir.recip();
        }
        let mut packet = Bounds::of(rays, &inv_dir[..n]);
        let mut lanes = Lanes::of(rays, &inv_dir[..n]);
        // The first ray, from `from` on, that meets node `node`'s box, and where it enters it.
        let enters = |node: usize, from: usize, lanes: &Lanes, packet: &Option<Bounds>| {
            let bounds = &self.nodes[node].bounds;
            if packet.as_ref().is_some_and(|p| p.misses(bounds)) {
                return None;
            }
            lanes.first_meeting(bounds, from)
        };
        let mut stack = [(0u32, 0u32); 64];
        let mut top = 0usize;
        let Some((mut first, _)) = enters(0, 0, &lanes, &packet) else {
            return;
        };
        let mut node = 0usize;
        loop {
            let nd = self.nodes[node];
            if nd.count > 0 {
                if self.leaf(node, first, rays, &mut lanes, on_hit) {
                    if let Some(p) = &mut packet {
                        p.t_max = rays.iter().fold(f32::NEG_INFINITY, |m, r| m.max(r.t_max));
                    }
                }
            } else {
                let (l, r) = (nd.index as usize, nd.index as usize + 1);
                match (
                    enters(l, first, &lanes, &packet),
                    enters(r, first, &lanes, &packet),
                ) {
                    (Some((fl, tl)), Some((fr, tr))) => {
                        let ((near, fnear), far) = if tl <= tr {
                            ((l, fl), (r, fr))
                        } else {
                            ((r, fr), (l, fl))
                        };
                        if top < stack.len() {
                            stack[top] = (far.0 as u32, far.1 as u32);
                            top += 1;
                        }
                        (node, first) = (near, fnear);
                        continue;
                    }
                    (Some((fl, _)), None) => {
                        (node, first) = (l, fl);
                        continue;
                    }
                    (None, Some((fr, _))) => {
                        (node, first) = (r, fr);
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop the next subtree still in reach of a ray.
            loop {
                if top == 0 {
                    return;
                }
                top -= 1;
                let (next, from) = (stack[top].0 as usize, stack[top].1 as usize);
                if let Some((f, _)) = enters(next, from, &lanes, &packet) {
                    (node, first) = (next, f);
                    break;
                }
            }
        }
    }

    /// Tests leaf `node`'s triangles against rays `first..` that meet its box; whether any
    /// ray hit one.
    fn leaf(
        &self,
        node: usize,
        first: usize,
        rays: &mut [PacketRay],
        lanes: &mut Lanes,
        on_hit: &mut dyn FnMut(usize, f32, u32) -> f32,
    ) -> bool {
        let nd = self.nodes[node];
        let mut any = false;
        let tris = nd.index as usize..(nd.index + nd.count) as usize;
        for group in first / LANES..lanes.groups {
            let mut mask = lanes.meet(group, &nd.bounds, first).0;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let l = LANES * group + lane;
                let ray = &mut rays[l];
                let (o, d) = (ray.origin, ray.dir);
                for k in tris.clone() {
                    if let Some(t) = self.tris[k].hit(o, d, ray.t_min, ray.t_max) {
                        ray.t_max = on_hit(l, t, self.order[k]);
                        lanes.t_max[group][lane] = ray.t_max;
                        any = true;
                    }
                }
            }
        }
        any
    }
}

/// Rays per group of [`Lanes`].
const LANES: usize = 4;
/// Groups of a packet.
const GROUPS: usize = PACKET / LANES;

/// A packet's rays four at a time (a structure of arrays): one box against four rays at once.
/// Lanes past the packet's rays meet nothing.
struct Lanes {
    origin: [[Vec4; 3]; GROUPS],
    inv_dir: [[Vec4; 3]; GROUPS],
    t_min: [Vec4; GROUPS],
    t_max: [Vec4; GROUPS],
    /// Groups holding rays.
    groups: usize,
}

impl Lanes {
    /// The lanes of `rays` (with their inverse directions).
    fn of(rays: &[PacketRay], inv_dir: &[Vec3]) -> Self {
        let mut lanes = Self {
            origin: [[Vec4::ZERO; 3]; GROUPS],
            inv_dir: [[Vec4::ZERO; 3]; GROUPS],
            t_min: [Vec4::INFINITY; GROUPS],
            t_max: [Vec4::NEG_INFINITY; GROUPS],
            groups: rays.len().div_ceil(LANES),
        };
        for (l, (ray, inv)) in rays.iter().zip(inv_dir).enumerate() {
            let (g, k) = (l / LANES, l % LANES);
            for axis in 0..3 {
                lanes.origin[g][axis][k] = ray.origin[axis];
                lanes.inv_dir[g][axis][k] = inv[axis];
            }
            lanes.t_min[g][k] = ray.t_min;
            lanes.t_max[g][k] = ray.t_max;
        }
        lanes
    }

    /// Which rays of group `group`, from ray `from` of the packet on, meet `bounds` within
    /// their intervals (bit `k`: lane `k`), and where each enters it.
    #[inline]
    fn meet(&self, group: usize, bounds: &Aabb, from: usize) -> (u32, Vec4) {
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
        let mask = near.cmple(far).bitmask();
        let skip = from.saturating_sub(LANES * group).min(LANES);
        (mask & (0xf << skip) & 0xf, near)
    }

    /// The first ray, from ray `from` on, that meets `bounds`, and where it enters it.
    fn first_meeting(&self, bounds: &Aabb, from: usize) -> Option<(usize, f32)> {
        (from / LANES..self.groups).find_map(|group| {
            let (mask, near) = self.meet(group, bounds, from);
            let lane = mask.trailing_zeros() as usize;
            (mask != 0).then(|| (LANES * group + lane, near[lane]))
        })
    }
}

/// What all rays of a packet share: the ranges of their starts, inverse directions and
/// distances. Only for packets whose inverse directions are finite and of one sign per axis.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    origin_lo: Vec3A,
    origin_hi: Vec3A,
    inv_lo: Vec3A,
    inv_hi: Vec3A,
    /// Axes along which the rays run toward lower coordinates.
    negative: BVec3A,
    t_min: f32,
    t_max: f32,
}

impl Bounds {
    /// The bounds of `rays` (with their inverse directions), or `None` where the rays' inverse
    /// directions differ in sign or are not finite along an axis.
    fn of(rays: &[PacketRay], inv_dir: &[Vec3]) -> Option<Self> {
        let first = Vec3A::from(*inv_dir.first()?);
        let negative = first.cmplt(Vec3A::ZERO);
        let mut b = Self {
            origin_lo: Vec3A::INFINITY,
            origin_hi: Vec3A::NEG_INFINITY,
            inv_lo: Vec3A::INFINITY,
            inv_hi: Vec3A::NEG_INFINITY,
            negative,
            t_min: f32::INFINITY,
            t_max: f32::NEG_INFINITY,
        };
        for (ray, &inv) in rays.iter().zip(inv_dir) {
            let (o, inv) = (Vec3A::from(ray.origin), Vec3A::from(inv));
            if !inv.is_finite() || !o.is_finite() || inv.cmplt(Vec3A::ZERO) != negative {
                return None;
            }
            b.origin_lo = b.origin_lo.min(o);
            b.origin_hi = b.origin_hi.max(o);
            b.inv_lo = b.inv_lo.min(inv);
            b.inv_hi = b.inv_hi.max(inv);
            b.t_min = b.t_min.min(ray.t_min);
            b.t_max = b.t_max.max(ray.t_max);
        }
        Some(b)
    }

    /// Whether no ray of the packet can meet `bounds` (safely: a box that a ray only grazes is
    /// left to the ray's own test).
    #[inline]
    fn misses(&self, bounds: &Aabb) -> bool {
        let (lo, hi) = (Vec3A::from(bounds.lo), Vec3A::from(bounds.hi));
        // Per axis, the slab's near and far plane for these directions.
        let near_plane = Vec3A::select(self.negative, hi, lo);
        let far_plane = Vec3A::select(self.negative, lo, hi);
        let products = |plane: Vec3A| {
            let (d0, d1) = (plane - self.origin_hi, plane - self.origin_lo);
            let (a, b) = (d0 * self.inv_lo, d0 * self.inv_hi);
            let (c, d) = (d1 * self.inv_lo, d1 * self.inv_hi);
            (a.min(b).min(c.min(d)), a.max(b).max(c.max(d)))
        };
        let enter = products(near_plane).0.max_element().max(self.t_min);
        let leave = products(far_plane).1.min_element().min(self.t_max);
        enter - leave > MARGIN * (enter.abs() + leave.abs() + 1.0)
    }
}
