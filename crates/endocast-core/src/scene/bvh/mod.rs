//! A bounding-volume hierarchy over a mesh's triangles: binned surface-area-heuristic build
//! (12 bins, leaves of up to four triangles), flat nodes, a stack traversal nearer child first,
//! one ray or a packet of neighbouring rays at a time ([`packet`]).
//!
//! Our own rather than a crate's: the tracer needs *every* hit along a ray up to a distance
//! that shrinks as opaque hits are found (translucent meshes are composited in depth order),
//! in `f32` on precomputed triangle edges. The `bvh` crate answers "which shapes' boxes does
//! the ray meet" (the nearest hit, let alone all hits, is left to the caller) and brings
//! nalgebra with it; this file is about 250 lines.

mod lanes;
mod packet;

/// Rays walked through the tree as one packet at most (longer slices go in parts).
pub const PACKET: usize = 64;

use super::mesh::TriangleMesh;
use glam::Vec3;

/// A ray of a packet ([`Bvh::traverse_packet`]): `origin + t·dir` for `t_min < t < t_max`
/// (world mm).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub struct PacketRay {
    /// Start, world mm.
    pub origin: Vec3,
    /// Direction (unit for distances in mm).
    pub dir: Vec3,
    /// Distances looked at lie above this.
    pub t_min: f32,
    /// Distances looked at lie below this (lowered as the walk's caller asks).
    pub t_max: f32,
}

/// Triangles per leaf at most.
const LEAF_SIZE: usize = 4;
/// Bins of the surface-area heuristic per split.
const BINS: usize = 12;
/// How far outside a triangle (in barycentric units) a hit still counts: rays through a shared
/// edge or corner then meet at least one of the triangles around it in `f32` (no cracks in a
/// closed mesh), at the price of a rare double hit there.
const EDGE_SLACK: f32 = 1e-5;
/// Cost of a node visit against one triangle test, in the heuristic.
const TRAVERSAL_COST: f32 = 1.0;

/// A box, world mm.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Aabb {
    lo: Vec3,
    hi: Vec3,
}

impl Aabb {
    const EMPTY: Self = Self {
        lo: Vec3::splat(f32::INFINITY),
        hi: Vec3::splat(f32::NEG_INFINITY),
    };

    fn grow(&mut self, p: Vec3) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    fn union(self, other: Self) -> Self {
        Self {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    fn half_area(&self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A node: its box, and either two children (`count == 0`: the left child is `index`, the
/// right one `index + 1`) or a leaf of `count` triangles from `index` on.
#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Aabb,
    index: u32,
    count: u32,
}

/// A triangle ready for the Möller–Trumbore test: a corner and the two edges from it.
#[derive(Debug, Clone, Copy)]
struct Tri {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
}

impl Tri {
    /// The distance along the ray to the triangle, if it lies in `(t_min, t_max)`: the
    /// scalar reference of the four-ray test the walk runs ([`lanes`]), for the tests.
    #[cfg(test)]
    fn hit(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
        let p = dir.cross(self.e2);
        let det = self.e1.dot(p);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let s = origin - self.v0;
        let u = s.dot(p) * inv;
        if !(-EDGE_SLACK..=1.0 + EDGE_SLACK).contains(&u) {
            return None;
        }
        let q = s.cross(self.e1);
        let v = dir.dot(q) * inv;
        if v < -EDGE_SLACK || u + v > 1.0 + EDGE_SLACK {
            return None;
        }
        let t = self.e2.dot(q) * inv;
        (t > t_min && t < t_max).then_some(t)
    }
}

/// The hierarchy over one mesh (triangles reordered; the original index kept).
#[derive(Debug, Clone)]
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
    /// Original triangle index of each reordered triangle.
    order: Vec<u32>,
    /// Unit normal of each original triangle (computed in `f64`).
    normals: Vec<Vec3>,
}

impl Bvh {
    /// Builds the hierarchy over `mesh`'s triangles.
    pub fn new(mesh: &TriangleMesh) -> Self {
        let n = mesh.triangles().len();
        let corners: Vec<[Vec3; 3]> = (0..n)
            .map(|i| mesh.corners(i).map(|c| c.as_vec3()))
            .collect();
        let centroids: Vec<Vec3> = corners.iter().map(|c| (c[0] + c[1] + c[2]) / 3.0).collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n.div_ceil(LEAF_SIZE));
        nodes.push(Node {
            bounds: Aabb::EMPTY,
            index: 0,
            count: 0,
        });
        let mut builder = Builder {
            corners: &corners,
            centroids: &centroids,
            order: &mut order,
            nodes: &mut nodes,
        };
        builder.build(0, 0, n);
        let tris = order
            .iter()
            .map(|&i| {
                let [a, b, c] = corners[i as usize];
                Tri {
                    v0: a,
                    e1: b - a,
                    e2: c - a,
                }
            })
            .collect();
        let normals = (0..n)
            .map(|i| {
                let [a, b, c] = mesh.corners(i);
                (b - a).cross(c - a).normalize_or_zero().as_vec3()
            })
            .collect();
        Self {
            nodes,
            tris,
            order,
            normals,
        }
    }

    /// Calls `on_hit(t, triangle)` for every triangle the ray `origin + t·dir` meets with
    /// `t_min < t < t_max`, nearer subtrees first; `on_hit` returns the new `t_max` (return the
    /// hit's `t` to look only for nearer hits, or the old bound to collect every hit).
    pub fn traverse(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
        mut on_hit: impl FnMut(f32, u32) -> f32,
    ) {
        let mut ray = [PacketRay {
            origin,
            dir,
            t_min,
            t_max,
        }];
        self.traverse_packet(&mut ray, |_, t, tri| on_hit(t, tri));
    }

    /// The nearest hit in `(t_min, t_max)`: distance and triangle (the lower index between hits
    /// at the same distance, as [`Bvh::nearest_each`]).
    pub fn nearest(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Option<(f32, u32)> {
        let mut ray = [PacketRay {
            origin,
            dir,
            t_min,
            t_max,
        }];
        let mut best = [None];
        self.nearest_each(&mut ray, &mut best);
        best[0]
    }

    /// The geometric unit normal of (original) triangle `tri` (right-handed corner order).
    pub fn normal(&self, tri: u32) -> Vec3 {
        self.normals[tri as usize]
    }
}

/// The recursive build's shared state.
struct Builder<'a> {
    corners: &'a [[Vec3; 3]],
    centroids: &'a [Vec3],
    order: &'a mut [u32],
    nodes: &'a mut Vec<Node>,
}

impl Builder<'_> {
    fn bounds(&self, first: usize, end: usize) -> (Aabb, Aabb) {
        let (mut b, mut c) = (Aabb::EMPTY, Aabb::EMPTY);
        for &i in &self.order[first..end] {
            for p in self.corners[i as usize] {
                b.grow(p);
            }
            c.grow(self.centroids[i as usize]);
        }
        (b, c)
    }

    /// Fills node `node` with triangles `first..end` of the order (depth-first; an explicit
    /// depth is not needed: SAH splits of up to millions of triangles stay far below the
    /// traversal's stack of 64).
    fn build(&mut self, node: usize, first: usize, end: usize) {
        let (bounds, centres) = self.bounds(first, end);
        self.nodes[node].bounds = bounds;
        let count = end - first;
        let split = if count <= LEAF_SIZE {
            None
        } else {
            self.best_split(first, end, &bounds, &centres)
        };
        let Some((axis, position)) = split else {
            self.nodes[node].index = first as u32;
            self.nodes[node].count = count as u32;
            return;
        };
        let centroids = self.centroids;
        let slice = &mut self.order[first..end];
        let mut mid = 0;
        for k in 0..slice.len() {
            if centroids[slice[k] as usize][axis] < position {
                slice.swap(k, mid);
                mid += 1;
            }
        }
        if mid == 0 || mid == count {
            mid = count / 2;
        }
        let left = self.nodes.len();
        let empty = Node {
            bounds: Aabb::EMPTY,
            index: 0,
            count: 0,
        };
        self.nodes.extend([empty, empty]);
        self.nodes[node].index = left as u32;
        self.nodes[node].count = 0;
        self.build(left, first, first + mid);
        self.build(left + 1, first + mid, end);
    }

    /// The axis and position of the cheapest binned split, or `None` when a leaf is cheaper.
    fn best_split(
        &self,
        first: usize,
        end: usize,
        bounds: &Aabb,
        centres: &Aabb,
    ) -> Option<(usize, f32)> {
        let mut best: Option<(f32, usize, f32)> = None;
        for axis in 0..3 {
            let (lo, hi) = (centres.lo[axis], centres.hi[axis]);
            if hi <= lo || hi.is_nan() || lo.is_nan() {
                continue;
            }
            let scale = BINS as f32 / (hi - lo);
            let mut boxes = [Aabb::EMPTY; BINS];
            let mut counts = [0usize; BINS];
            for &i in &self.order[first..end] {
                let c = self.centroids[i as usize][axis];
                let b = (((c - lo) * scale) as usize).min(BINS - 1);
                counts[b] += 1;
                for p in self.corners[i as usize] {
                    boxes[b].grow(p);
                }
            }
            // Sweep from the right, then from the left.
            let mut right_area = [0.0f32; BINS];
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            let mut right_count = [0usize; BINS];
            for b in (1..BINS).rev() {
                acc = acc.union(boxes[b]);
                n += counts[b];
                right_area[b] = acc.half_area();
                right_count[b] = n;
            }
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            for b in 0..BINS - 1 {
                acc = acc.union(boxes[b]);
                n += counts[b];
                let (nr, ar) = (right_count[b + 1], right_area[b + 1]);
                if n == 0 || nr == 0 {
                    continue;
                }
                let cost = acc.half_area() * n as f32 + ar * nr as f32;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, lo + (b + 1) as f32 / scale));
                }
            }
        }
        let (cost, axis, position) = best?;
        let leaf = (end - first) as f32 * bounds.half_area();
        (cost + TRAVERSAL_COST * bounds.half_area() < leaf).then_some((axis, position))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;
    use glam::DVec3;

    #[test]
    fn every_hit_equals_brute_force() {
        let mut s = Rng::new(11);
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for k in 0..500u32 {
            let c = DVec3::new(s.unit(), s.unit(), s.unit()) * 40.0;
            for _ in 0..3 {
                let d = DVec3::new(s.unit(), s.unit(), s.unit()) - 0.5;
                vertices.push(c + d * 6.0);
            }
            triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        let mesh = TriangleMesh::new(vertices, triangles).unwrap();
        let bvh = Bvh::new(&mesh);
        let tris: Vec<Tri> = (0..mesh.triangles().len())
            .map(|i| {
                let [a, b, c] = mesh.corners(i).map(|p| p.as_vec3());
                Tri {
                    v0: a,
                    e1: b - a,
                    e2: c - a,
                }
            })
            .collect();
        for _ in 0..300 {
            let o = (DVec3::new(s.unit(), s.unit(), s.unit()) * 60.0 - 10.0).as_vec3();
            let d = (DVec3::new(s.unit(), s.unit(), s.unit()) - 0.5)
                .normalize()
                .as_vec3();
            let mut expected: Vec<(f32, u32)> = tris
                .iter()
                .enumerate()
                .filter_map(|(i, t)| t.hit(o, d, 0.0, 1e9).map(|t| (t, i as u32)))
                .collect();
            expected.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut all = Vec::new();
            bvh.traverse(o, d, 0.0, 1e9, |t, i| {
                all.push((t, i));
                1e9
            });
            all.sort_by(|a, b| a.0.total_cmp(&b.0));
            assert_eq!(all, expected);
            assert_eq!(bvh.nearest(o, d, 0.0, 1e9), expected.first().copied());
        }
    }

    #[test]
    fn a_packet_of_rays_finds_what_each_ray_finds_alone() {
        let mut s = Rng::new(5);
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for k in 0..2000u32 {
            let c = DVec3::new(s.unit(), s.unit(), s.unit()) * 40.0;
            for _ in 0..3 {
                let d = DVec3::new(s.unit(), s.unit(), s.unit()) - 0.5;
                vertices.push(c + d * 4.0);
            }
            triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        let mesh = TriangleMesh::new(vertices, triangles).unwrap();
        let bvh = Bvh::new(&mesh);
        let eye = Vec3::new(-5.0, 20.0, 20.0);
        // Rows of a fan of rays (a packet and part of one: a group of lanes only partly
        // filled), bounds varying along the row.
        let columns = PACKET + 13;
        for row in 0..40 {
            let mut rays: Vec<PacketRay> = (0..columns)
                .map(|col| PacketRay {
                    origin: eye,
                    dir: Vec3::new(1.0, (col as f32 - 38.0) * 0.01, (row as f32 - 20.0) * 0.02)
                        .normalize(),
                    t_min: 0.5,
                    t_max: 20.0 + col as f32 / 2.0,
                })
                .collect();
            let alone: Vec<_> = rays
                .iter()
                .map(|r| bvh.nearest(r.origin, r.dir, r.t_min, r.t_max))
                .collect();
            let every: Vec<Vec<(f32, u32)>> = rays
                .iter()
                .map(|r| {
                    let mut all = Vec::new();
                    bvh.traverse(r.origin, r.dir, r.t_min, r.t_max, |t, i| {
                        all.push((t, i));
                        r.t_max
                    });
                    all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                    all
                })
                .collect();
            let mut packet_every = vec![Vec::new(); rays.len()];
            let bounds: Vec<f32> = rays.iter().map(|r| r.t_max).collect();
            bvh.traverse_packet(&mut rays.clone(), |ray, t, i| {
                packet_every[ray].push((t, i));
                bounds[ray]
            });
            for all in &mut packet_every {
                all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            }
            assert_eq!(packet_every, every, "row {row}");
            let mut best = vec![None; rays.len()];
            bvh.nearest_each(&mut rays, &mut best);
            assert_eq!(best, alone, "row {row}");
            assert!(
                best.iter().filter(|b| b.is_some()).count() > 3,
                "row {row} meets little"
            );
        }
    }
}
