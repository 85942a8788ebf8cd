//! Dynamic time warping of two tracks' tangent directions: the monotone pairing of their
//! samples, from end to end, that lines up their turns (the flexures) best.

use super::track::Track;
use glam::{DQuat, DVec3};

/// Extra cost of a step that advances along one track only: keeps the warp from stalling on
/// straight stretches, where every pairing costs the same.
const STALL_COST: f64 = 0.05;
/// How far the pairing may stray from equal fractions of the two lengths (a band around the
/// diagonal, as a fraction of the length): far enough for a stretch of a quarter, and it keeps
/// the work linear in the product of the lengths times this fraction.
const BAND: f64 = 0.25;

/// The warp of `a` onto `b` with `a`'s tangents turned by `turn`: for each sample of `a`, the
/// mean arc length (mm) of the samples of `b` paired with it, and the mean cost of the pairs.
pub(super) fn warp(a: &Track, b: &Track, turn: DQuat) -> (Vec<f64>, f64) {
    let (na, nb) = (a.points.len(), b.points.len());
    let turned: Vec<DVec3> = a.tangents.iter().map(|&t| turn * t).collect();
    let band = |i: usize| {
        let centre = i as f64 / (na - 1).max(1) as f64 * (nb - 1) as f64;
        let half = BAND * nb as f64 + 1.0;
        let lo = (centre - half).floor().max(0.0) as usize;
        let hi = ((centre + half).ceil() as usize).min(nb - 1);
        (lo, hi)
    };
    let cost = |i: usize, j: usize| turned[i].distance_squared(b.tangents[j]);
    // total[i][j]: the cheapest warp from (0, 0) to (i, j); infinite outside the band.
    let mut total = vec![f64::INFINITY; na * nb];
    for i in 0..na {
        let (lo, hi) = band(i);
        for j in lo..=hi {
            let best = if i == 0 && j == 0 {
                0.0
            } else {
                let at = |ii: usize, jj: usize| total[ii * nb + jj];
                let diagonal = if i > 0 && j > 0 {
                    at(i - 1, j - 1)
                } else {
                    f64::INFINITY
                };
                let up = if i > 0 {
                    at(i - 1, j) + STALL_COST
                } else {
                    f64::INFINITY
                };
                let left = if j > 0 {
                    at(i, j - 1) + STALL_COST
                } else {
                    f64::INFINITY
                };
                diagonal.min(up).min(left)
            };
            total[i * nb + j] = best + cost(i, j);
        }
    }
    backtrack(&total, [na, nb], b)
}

/// Follows the cheapest warp back from the far ends: each `a` sample's mean paired arc length
/// in `b`, and the mean cost per pair.
fn backtrack(total: &[f64], [na, nb]: [usize; 2], b: &Track) -> (Vec<f64>, f64) {
    let (mut sum, mut count) = (vec![0.0; na], vec![0usize; na]);
    let (mut i, mut j) = (na - 1, nb - 1);
    let mut pairs = 0usize;
    loop {
        sum[i] += b.arc_mm(j);
        count[i] += 1;
        pairs += 1;
        if i == 0 && j == 0 {
            break;
        }
        let at = |ii: usize, jj: usize| total[ii * nb + jj];
        let candidates = [
            (i > 0 && j > 0).then(|| (at(i - 1, j - 1), i - 1, j - 1)),
            (i > 0).then(|| (at(i - 1, j) + STALL_COST, i - 1, j)),
            (j > 0).then(|| (at(i, j - 1) + STALL_COST, i, j - 1)),
        ];
        let Some((_, pi, pj)) = candidates
            .into_iter()
            .flatten()
            .min_by(|x, y| x.0.total_cmp(&y.0))
        else {
            break;
        };
        (i, j) = (pi, pj);
    }
    let mapped = sum
        .iter()
        .zip(&count)
        .map(|(s, &c)| s / c.max(1) as f64)
        .collect();
    (mapped, total[na * nb - 1] / pairs as f64)
}
