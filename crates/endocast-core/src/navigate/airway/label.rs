//! Anatomical names of the airway tree's branches, from the directions they take in the patient
//! frame (LPS: +x the patient's left, +y posterior, +z superior):
//! - the root's run is the trachea (generation 0);
//! - of the two largest runs leaving it, the one heading more to the patient's right is the right
//!   main bronchus, the other the left (generation 1);
//! - of the two largest runs leaving the right main bronchus, the one heading more upwards is the
//!   right upper lobe bronchus (generation 2), the other the bronchus intermedius (still
//!   generation 1: the right main bronchus continued);
//! - of the two largest runs leaving the bronchus intermedius, the more anterior is the right
//!   middle lobe bronchus, the other the right lower lobe bronchus (generation 2);
//! - of the two largest runs leaving the left main bronchus, the one heading more upwards is the
//!   left upper lobe bronchus, the other the left lower lobe bronchus (generation 2);
//! - every other run is a segmental bronchus of the lobe it lies in (generation 3 below a lobar
//!   bronchus; subsegmental, one generation more for each branching, beyond), or a side branch
//!   of a run not in a lobe (a run leaving the trachea or a main bronchus beside the two named).
//!
//! "Largest" is by the length of all the centrelines below a run; "heading" is the direction
//! over the first [`HEADING_MM`] of a run.

use super::branches::{direction, largest_two, length_mm, lengths_below, Run};
use super::skeleton::Node;

/// How far along a run its heading is measured, mm.
const HEADING_MM: f64 = 15.0;

/// A branch's name and generation (trachea 0, main bronchi 1, lobar 2, segmental 3, ...).
pub(super) type Label = (String, u32);

/// The label of every run (see the module doc).
pub(super) fn label(nodes: &[Node], runs: &[Run]) -> Vec<Label> {
    let mut children = vec![Vec::new(); runs.len()];
    for (r, run) in runs.iter().enumerate() {
        if let Some(p) = run.parent {
            children[p].push(r);
        }
    }
    let parents: Vec<Option<usize>> = runs.iter().map(|run| run.parent).collect();
    let own_mm = runs
        .iter()
        .map(|run| length_mm(nodes, &run.nodes))
        .collect();
    let below = lengths_below(&parents, own_mm);
    let heading = |r: usize| direction(nodes, &runs[r].nodes, HEADING_MM);
    let namer = Namer {
        children: &children,
        below: &below,
    };
    let mut labels: Vec<Option<Label>> = vec![None; runs.len()];
    let mut name = |r: Option<usize>, text: &str, generation: u32| {
        if let Some(r) = r {
            labels[r] = Some((text.to_owned(), generation));
        }
    };
    name(Some(0), "trachea", 0);
    let (right, left) = namer.pair(0, |r| -heading(r).x);
    name(right, "right main bronchus", 1);
    name(left, "left main bronchus", 1);
    let (rul, intermedius) = right.map_or((None, None), |r| namer.pair(r, |c| heading(c).z));
    name(rul, "right upper lobe bronchus", 2);
    name(intermedius, "bronchus intermedius", 1);
    let (rml, rll) = intermedius.map_or((None, None), |r| namer.pair(r, |c| -heading(c).y));
    name(rml, "right middle lobe bronchus", 2);
    name(rll, "right lower lobe bronchus", 2);
    let (lul, lll) = left.map_or((None, None), |r| namer.pair(r, |c| heading(c).z));
    name(lul, "left upper lobe bronchus", 2);
    name(lll, "left lower lobe bronchus", 2);
    fill_descendants(runs, labels)
}

/// Labels every run still unnamed after its parent: a segmental bronchus of its parent's lobe,
/// or a side branch.
fn fill_descendants(runs: &[Run], mut labels: Vec<Option<Label>>) -> Vec<Label> {
    for r in 0..runs.len() {
        if labels[r].is_some() {
            continue;
        }
        let Some((parent_name, parent_generation)) = runs[r].parent.and_then(|p| labels[p].clone())
        else {
            labels[r] = Some(("airway".to_owned(), 0));
            continue;
        };
        let level = if parent_generation < 3 {
            "segmental"
        } else {
            "subsegmental"
        };
        let text = match parent_name.split_once(" lobe ") {
            Some((lobe, _)) => format!("{lobe} lobe {level} bronchus"),
            None => format!("side branch of the {parent_name}"),
        };
        labels[r] = Some((text, parent_generation + 1));
    }
    labels.into_iter().map(Option::unwrap_or_default).collect()
}

/// The tree of runs, for picking children.
struct Namer<'a> {
    children: &'a [Vec<usize>],
    /// Length of the centrelines below each run (its own included), mm.
    below: &'a [f64],
}

impl Namer<'_> {
    /// Of the two largest runs leaving `parent`: the one scoring higher by `score`, then the
    /// other; neither when fewer than two leave it.
    fn pair(&self, parent: usize, score: impl Fn(usize) -> f64) -> (Option<usize>, Option<usize>) {
        // Only the two largest: a twig must not win by its heading.
        let Some([a, b]) = largest_two(&self.children[parent], self.below) else {
            return (None, None);
        };
        if score(a) >= score(b) {
            (Some(a), Some(b))
        } else {
            (Some(b), Some(a))
        }
    }
}
