//! Rays traced through the hierarchy together (a block of pixels: neighbouring rays visit
//! nearly the same nodes). The packet walks the tree once: a node is entered when any of its rays
//! meets the node's box, and each ray still meets a leaf's triangles only where it meets the
//! leaf's box, with its own distance bound — so every ray finds exactly the hits it finds alone.
//!
//! A node's rays are tried from the first one that met its parent on (rays before it missed
//! the parent, and bounds only shrink): in a coherent packet the first try usually answers.
//! Before that, the packet's bounds (the ranges of its rays' starts, inverse directions and
//! distances) rule out at once the boxes that no ray of it can meet, with a margin that keeps
//! the test on the safe side of rounding. Boxes and triangles are tested against four rays at a
//! time ([`Lanes`], in SSE registers through `glam::Vec4`).

use super::lanes::{from_lane, Lanes, ALL_LANES, LANES};
use super::{Aabb, Bvh, PacketRay, PACKET};
use glam::{BVec3A, Vec3A};
use std::cell::Cell;

/// Relative margin of [`Bounds::misses`]: a box is ruled out only when every ray misses it by
/// more than this share of the distances involved (far above `f32` rounding).
const MARGIN: f32 = 1e-4;

thread_local! {
    /// Each thread's lanes, kept from walk to walk.
    static SPARE: Cell<Option<Box<Lanes>>> = const { Cell::new(None) };
}

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
        if rays.is_empty() {
            return;
        }
        // The thread's lanes from walk to walk (a nested walk makes its own).
        let mut lanes = SPARE.take().unwrap_or_else(|| Box::new(Lanes::new()));
        lanes.fill(rays);
        self.walk_lanes(rays, &mut lanes, on_hit);
        SPARE.set(Some(lanes));
    }

    /// [`Self::walk`] with the packet's rays in `lanes` too.
    fn walk_lanes(
        &self,
        rays: &mut [PacketRay],
        lanes: &mut Lanes,
        on_hit: &mut dyn FnMut(usize, f32, u32) -> f32,
    ) {
        let mut packet = Bounds::of(lanes);
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
        let Some((mut first, _)) = enters(0, 0, lanes, &packet) else {
            return;
        };
        let mut node = 0usize;
        loop {
            let nd = self.nodes[node];
            if nd.count > 0 {
                if self.leaf(node, first, rays, lanes, on_hit) {
                    if let Some(p) = &mut packet {
                        p.t_max = lanes.highest_t_max();
                    }
                }
            } else {
                let (l, r) = (nd.index as usize, nd.index as usize + 1);
                match (
                    enters(l, first, lanes, &packet),
                    enters(r, first, lanes, &packet),
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
                if let Some((f, _)) = enters(next, from, lanes, &packet) {
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
        let mut counted = from_lane(first);
        for group in first / LANES..lanes.groups {
            let mask = lanes.meet(group, &nd.bounds).0 & counted;
            counted = ALL_LANES;
            if mask == 0 {
                continue;
            }
            // Triangle after triangle, each against the group's rays at once: each ray still
            // meets the triangles in order, with the bound its earlier hits left.
            for k in tris.clone() {
                let (mut hits, t) = lanes.hit(group, &self.tris[k], mask);
                while hits != 0 {
                    let lane = hits.trailing_zeros() as usize;
                    hits &= hits - 1;
                    let l = LANES * group + lane;
                    let t_max = on_hit(l, t[lane], self.order[k]);
                    rays[l].t_max = t_max;
                    lanes.t_max[group][lane] = t_max;
                    any = true;
                }
            }
        }
        any
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
    /// The bounds of the rays in `lanes`, or `None` where the rays' inverse directions differ
    /// in sign or are not finite along an axis.
    fn of(lanes: &Lanes) -> Option<Self> {
        let r = lanes.ranges()?;
        let (inv_lo, inv_hi) = r.inv_dir;
        let negative = inv_hi.cmplt(Vec3A::ZERO);
        // One sign per axis: all below zero, or none.
        if (negative | inv_lo.cmpge(Vec3A::ZERO)) != BVec3A::TRUE {
            return None;
        }
        Some(Self {
            origin_lo: r.origin.0,
            origin_hi: r.origin.1,
            inv_lo,
            inv_hi,
            negative,
            t_min: r.t_min,
            t_max: r.t_max,
        })
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
