//! The skeleton's nodes cut into branches: runs of nodes between branch points (nodes with more
//! than one child), a branch point and the short run between two branch points that lie closer
//! than a radius merged into one (a trifurcation seen on a voxel grid).

use super::skeleton::Node;
use glam::DVec3;

/// Two branch points closer than this many radii (of the first) are one.
const MERGE_RADII: f64 = 1.0;

/// A run of skeleton nodes from a branch point (or the root) to the next branch point or a tip.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Run {
    /// Node indices, the branch point it leaves first (except for the root's run).
    pub nodes: Vec<usize>,
    /// The run it leaves (`None` for the root's).
    pub parent: Option<usize>,
}

/// The runs of `nodes` (root first, every node after its parent), the root's first, every run
/// after its parent.
pub(super) fn runs(nodes: &[Node]) -> Vec<Run> {
    let mut children = vec![Vec::new(); nodes.len()];
    for (n, node) in nodes.iter().enumerate() {
        if let Some(p) = node.parent {
            children[p].push(n);
        }
    }
    let mut runs = Vec::new();
    let mut pending = vec![(vec![0], None)];
    while let Some((mut chain, parent)) = pending.pop() {
        let mut last = chain[chain.len() - 1];
        while let [only] = children[last][..] {
            chain.push(only);
            last = only;
        }
        let index = runs.len();
        let short =
            parent.is_some() && length_mm(nodes, &chain) < MERGE_RADII * radius(nodes, &chain);
        match (short, parent) {
            // Too short to be a branch of its own: its children leave its parent.
            (true, Some(p)) if !children[last].is_empty() => {
                for &c in &children[last] {
                    let mut merged = chain.clone();
                    merged.push(c);
                    pending.push((merged, Some(p)));
                }
            }
            _ => {
                runs.push(Run {
                    nodes: chain,
                    parent,
                });
                for &c in &children[last] {
                    pending.push((vec![last, c], Some(index)));
                }
            }
        }
    }
    runs
}

/// Length of a chain of nodes, mm.
pub(super) fn length_mm(nodes: &[Node], chain: &[usize]) -> f64 {
    chain
        .windows(2)
        .map(|w| nodes[w[0]].point_mm.distance(nodes[w[1]].point_mm))
        .sum()
}

/// The length of the centrelines below each branch, its own (`own_mm`) included, mm, from each
/// branch's parent (every branch after its parent).
pub(super) fn lengths_below(parents: &[Option<usize>], mut own_mm: Vec<f64>) -> Vec<f64> {
    for r in (1..parents.len()).rev() {
        if let Some(p) = parents[r] {
            own_mm[p] += own_mm[r];
        }
    }
    own_mm
}

/// The two of `kids` with the most centreline below them (`below`, by index), the larger
/// first; `None` when fewer than two.
pub(super) fn largest_two(kids: &[usize], below: &[f64]) -> Option<[usize; 2]> {
    let mut by_size = kids.to_vec();
    by_size.sort_by(|&a, &b| below[b].total_cmp(&below[a]));
    match by_size[..] {
        [a, b, ..] => Some([a, b]),
        _ => None,
    }
}

/// The radius at a chain's first node, mm.
fn radius(nodes: &[Node], chain: &[usize]) -> f64 {
    nodes[chain[0]].distance_mm
}

/// The direction a chain takes over its first `reach_mm` (or all of it, when shorter).
pub(super) fn direction(nodes: &[Node], chain: &[usize], reach_mm: f64) -> DVec3 {
    let start = nodes[chain[0]].point_mm;
    let mut along = 0.0;
    let mut end = start;
    for w in chain.windows(2) {
        along += nodes[w[0]].point_mm.distance(nodes[w[1]].point_mm);
        end = nodes[w[1]].point_mm;
        if along >= reach_mm {
            break;
        }
    }
    (end - start).normalize_or_zero()
}
