//! Marching cubes' case table, generated from one rule instead of typed in: on every face of a
//! cube, each run of inside corners (consecutive around the face) is cut off by its own segment,
//! so two inside corners diagonal on a face are kept apart (the inside is 6-connected, as a
//! [`Lumen`](crate::navigate::Lumen) is). The rule looks at a face's four corners only, so the
//! two cubes sharing a face cut it alike and the surface has no cracks; the classic 15-case
//! table, which resolves a face differently from its complement, does not have this property.
//! A cube's segments join into closed loops around the cube; each loop is fanned into
//! triangles that face from the inside corners to the outside ones.
//!
//! Corners are numbered by their offsets (bit 0 = +i, bit 1 = +j, bit 2 = +k). Edge `4a + o`
//! runs along axis `a` from the corner whose offsets along the two other axes (the lower axis
//! first) are the bits of `o`.

use std::sync::LazyLock;

/// The most triangles one cube's case gives (the table's own maximum is checked by a test).
pub(super) const MAX_TRIANGLES: usize = 5;

/// The triangles of one case, as the cube edges their vertices lie on.
#[derive(Debug, Clone, Copy)]
pub(super) struct Case {
    /// How many of `triangles` are used.
    pub count: u8,
    /// Each triangle's three edges, counter-clockwise seen from the outside corners.
    pub triangles: [[u8; 3]; MAX_TRIANGLES],
}

/// The case of every set of inside corners (bit `c` set: corner `c` inside).
pub(super) static CASES: LazyLock<[Case; 256]> =
    LazyLock::new(|| std::array::from_fn(|flags| case_of(flags as u8)));

/// The two corners of edge `e`: (lower, upper) along its axis.
pub(super) const fn edge_corners(e: usize) -> (u8, u8) {
    let axis = e / 4;
    let (a1, a2) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let lo = ((e & 1) << a1 | (e >> 1 & 1) << a2) as u8;
    (lo, lo | 1 << axis)
}

/// True when edge `e` joins an inside and an outside corner of the case `flags`.
pub(super) const fn crossed(flags: u8, e: usize) -> bool {
    let (lo, hi) = edge_corners(e);
    (flags >> lo & 1) != (flags >> hi & 1)
}

/// The edge joining corners `p` and `q` (which differ in one bit).
fn edge_between(p: u8, q: u8) -> usize {
    let axis = (p ^ q).trailing_zeros() as usize;
    (0..12)
        .find(|&e| e / 4 == axis && edge_corners(e).0 == p & q)
        .unwrap_or(0)
}

/// The four corners of face `f` (axis `f / 2`, side `f % 2`) in order around it, counter-clockwise
/// seen from outside the cube.
fn face_cycle(f: usize) -> [u8; 4] {
    let (axis, side) = (f / 2, f % 2);
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let base = (side << axis) as u8;
    let at = |du: u8, dv: u8| base | du << u | dv << v;
    let cycle = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
    if side == 1 {
        cycle
    } else {
        [cycle[0], cycle[3], cycle[2], cycle[1]]
    }
}

/// For each crossed edge, the crossed edge that follows it around the loop: on each face, a run
/// of inside corners joins the edge where the face's cycle enters it to the edge where it leaves.
fn successors(flags: u8) -> [Option<usize>; 12] {
    let inside = |c: u8| flags >> c & 1 == 1;
    let mut next = [None; 12];
    for f in 0..6 {
        let cycle = face_cycle(f);
        let edge = |m: usize| edge_between(cycle[m % 4], cycle[(m + 1) % 4]);
        for m in 0..4 {
            let enters = !inside(cycle[m]) && inside(cycle[(m + 1) % 4]);
            if enters {
                let run = (1..4)
                    .find(|&d| !inside(cycle[(m + 1 + d) % 4]))
                    .unwrap_or(3);
                next[edge(m)] = Some(edge(m + run));
            }
        }
    }
    next
}

/// The triangles of the case `flags`: each loop of crossed edges triangulated by [`cover`].
fn case_of(flags: u8) -> Case {
    let next = successors(flags);
    let mut triangles = Vec::new();
    let mut seen = [false; 12];
    for start in 0..12 {
        if seen[start] || next[start].is_none() {
            continue;
        }
        let mut lp = vec![start];
        seen[start] = true;
        while let Some(e) = next[lp[lp.len() - 1]].filter(|&e| e != start) {
            seen[e] = true;
            lp.push(e);
        }
        if !cover(&lp, &mut triangles) {
            panic!("case {flags:#010b}: no triangulation of a loop without a diagonal on a face");
        }
    }
    let mut case = Case {
        count: triangles.len() as u8,
        triangles: [[0; 3]; MAX_TRIANGLES],
    };
    for (slot, t) in case.triangles.iter_mut().zip(&triangles) {
        *slot = t.map(|e| e as u8);
    }
    case
}

/// Adds triangles covering the loop `lp` (edges in loop order; triangles keep its turn) such
/// that no inner diagonal joins two edges of one face: the cube across that face could draw the
/// same diagonal, and the mesh edge would then have four triangles. False when there is none.
fn cover(lp: &[usize], triangles: &mut Vec<[usize; 3]>) -> bool {
    let n = lp.len();
    if n < 3 {
        return true;
    }
    let allowed = |a: usize, b: usize| !on_one_face(a, b);
    for k in 2..n {
        if (k > 2 && !allowed(lp[1], lp[k])) || (k < n - 1 && !allowed(lp[k], lp[0])) {
            continue;
        }
        let before = triangles.len();
        triangles.push([lp[0], lp[1], lp[k]]);
        let rest: Vec<usize> = lp[k..].iter().chain(&lp[..1]).copied().collect();
        if cover(&lp[1..=k], triangles) && cover(&rest, triangles) {
            return true;
        }
        triangles.truncate(before);
    }
    false
}

/// True when edges `a` and `b` lie on one face of the cube.
fn on_one_face(a: usize, b: usize) -> bool {
    let (pa, qa) = edge_corners(a);
    let (pb, qb) = edge_corners(b);
    let corners = [pa, qa, pb, qb];
    (0..3).any(|axis| corners.iter().all(|&c| (c ^ pa) >> axis & 1 == 0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn corner(c: u8) -> DVec3 {
        DVec3::new(
            f64::from(c & 1),
            f64::from(c >> 1 & 1),
            f64::from(c >> 2 & 1),
        )
    }

    fn midpoint(e: u8) -> DVec3 {
        let (p, q) = edge_corners(usize::from(e));
        (corner(p) + corner(q)) * 0.5
    }

    #[test]
    fn every_case_cuts_exactly_its_crossed_edges_and_closes_its_loops() {
        let mut most = 0;
        for flags in 0..=255u8 {
            let case = CASES[usize::from(flags)];
            most = most.max(case.count);
            let mut used = [0usize; 12];
            // Directed edges between vertices: each must be matched by its reverse or lie on
            // a face (shared with the neighbouring cube).
            let mut directed = Vec::new();
            for t in &case.triangles[..usize::from(case.count)] {
                for k in 0..3 {
                    used[usize::from(t[k])] += 1;
                    directed.push((t[k], t[(k + 1) % 3]));
                }
            }
            for (e, &n) in used.iter().enumerate() {
                assert_eq!(n > 0, crossed(flags, e), "case {flags:#010b} edge {e}");
            }
            for &(a, b) in &directed {
                let on_face = on_one_face(usize::from(a), usize::from(b));
                assert!(on_face || directed.contains(&(b, a)), "case {flags:#010b}");
            }
        }
        assert_eq!(usize::from(most), MAX_TRIANGLES);
    }

    #[test]
    fn triangles_face_from_inside_corners_to_outside_ones() {
        for flags in (0..8).map(|c| 1u8 << c).chain((0..8).map(|c| !(1u8 << c))) {
            let case = CASES[usize::from(flags)];
            assert_eq!(case.count, 1);
            let [a, b, c] = case.triangles[0].map(midpoint);
            let normal = (b - a).cross(c - a);
            let lone = (0..8).find(|&c| (flags.count_ones() == 1) == (flags >> c & 1 == 1));
            let away = a - corner(lone.unwrap());
            let outward = if flags.count_ones() == 1 { away } else { -away };
            assert!(normal.dot(outward) > 0.0, "case {flags:#010b}");
        }
    }
}
