//! The airway tree skeletonised and labelled by generation (trachea, main, lobar and segmental
//! bronchi: see [`label`]), and routes through it to a target for a bronchoscope of a given
//! diameter ([`AirwayTree::route`]).
//!
//! The centrelines come from the centred paths of [`super::centreline`] from the trachea's top
//! ([`skeleton`]); a lumen diameter along them is twice the distance to the nearest wall voxel
//! centre on the distance field's ridge beside a node, less half a voxel (the wall's surface
//! lies on average half a voxel inside that centre, see [`DistanceField`]).

mod body;
mod branches;
mod label;
mod route;
mod skeleton;
mod split;
#[cfg(test)]
mod tests;

pub use route::{AirwayRoute, RouteError, DEFAULT_SCOPE_DIAMETER_MM};

use super::distance::DistanceField;
use super::lumen::Lumen;
use crate::Volume;
use glam::DVec3;
use skeleton::Node;

/// One branch of the airway tree: the centreline from the branch point it leaves (the root, for
/// the trachea) to the next branch point or its tip.
#[derive(Debug, Clone, PartialEq)]
pub struct AirwayBranch {
    /// Its anatomical name: "trachea", "right main bronchus", "left upper lobe bronchus",
    /// "right lower lobe segmental bronchus", ...
    pub name: String,
    /// Trachea 0, main bronchi (and the bronchus intermedius) 1, lobar 2, segmental 3, ...
    pub generation: u32,
    /// The branch it leaves (`None` for the trachea).
    pub parent: Option<usize>,
    /// Centreline voxel centres, world mm (LPS), from the branch point it leaves.
    pub points_mm: Vec<DVec3>,
    /// The lumen's diameter at each point, mm.
    pub diameters_mm: Vec<f64>,
    /// Where its two largest branches part in the lumen, world mm: the top of the spur of wall
    /// between them (the carina, for the trachea), about a radius below its last point, where
    /// the centrelines fork (see [`split`]); `None` for a branch that does not fork.
    pub split_mm: Option<DVec3>,
}

impl AirwayBranch {
    /// Length of its centreline, mm.
    pub fn length_mm(&self) -> f64 {
        self.points_mm.windows(2).map(|w| w[0].distance(w[1])).sum()
    }
}

/// The lumen's diameter at a centreline node, mm: twice the distance to the nearest wall voxel
/// centre on the lumen's medial ridge beside the node ([`ridge_distance_mm`]) less half a voxel;
/// infinite where the scan's border is as near as the wall (the lumen runs on out of the scan,
/// as the trachea does at its top).
fn diameter_mm(volume: &Volume, field: &DistanceField, node: &Node) -> f64 {
    let spacing = volume.geometry().spacing_mm().to_array();
    let dims = volume.dims();
    let border_mm = (0..3)
        .map(|a| ((node.voxel[a] + 1).min(dims[a] - node.voxel[a]) as f64) * spacing[a])
        .fold(f64::INFINITY, f64::min);
    if node.distance_mm >= border_mm - 1e-6 {
        return f64::INFINITY;
    }
    let ridge_mm = ridge_distance_mm(field, node, volume.geometry().spacing_mm().length());
    2.0 * (ridge_mm - 0.5 * field.min_spacing_mm()).max(0.0)
}

/// The distance to the wall on the lumen's medial ridge beside a centreline node, mm. A node
/// is a voxel centre, up to half a voxel diagonal off the ridge, where the distance is smaller
/// by that offset (a tube's distance field is a cone around its axis): a 6.5 mm scope did not
/// fit an 8 mm bronchus whose nodes lay half a voxel off its axis. Along the field's gradient
/// the distance rises to the ridge and falls back to the node's value as far beyond it, so
/// the ridge adds half that chord. Where it does not fall back within `reach_mm` (the voxel
/// diagonal) the node lies on a slope along the lumen (a narrowing), not beside its ridge,
/// and keeps its own distance.
fn ridge_distance_mm(field: &DistanceField, node: &Node, reach_mm: f64) -> f64 {
    let Some(up) = field.gradient(node.point_mm).try_normalize() else {
        return node.distance_mm;
    };
    let step_mm = 0.05 * field.min_spacing_mm();
    let chord_mm = (1..)
        .map(|n| f64::from(n) * step_mm)
        .take_while(|&t| t <= reach_mm)
        .find(|&t| field.distance_mm(node.point_mm + up * t) <= node.distance_mm);
    node.distance_mm + chord_mm.map_or(0.0, |t| 0.5 * t)
}

/// An airway tree: its branches, the trachea first, every branch after the one it leaves.
#[derive(Debug, Clone, PartialEq)]
pub struct AirwayTree {
    branches: Vec<AirwayBranch>,
    /// The lumen's threshold and side, for telling a target outside the body.
    threshold: f64,
}

impl AirwayTree {
    /// The tree of `lumen` (the airways found in `volume`, with their distance `field`) from the
    /// widest voxel near its seed, which lies at the trachea's top (see [`super::find_trachea`]).
    pub fn new(volume: &Volume, lumen: &Lumen, field: &DistanceField) -> Self {
        let root = skeleton::root_near(lumen, field, lumen.seed());
        let nodes = skeleton::skeletonise(volume, lumen, field, root);
        let runs = branches::runs(&nodes);
        let labels = label::label(&nodes, &runs);
        // The entry from the scan's top (nodes before the root) is taken as wide as the root:
        // the cut limits its distance to the wall, and so does noise (the chest CT's top
        // slices hold voxels of −900 to −830 HU inside the trachea, 3 mm wide holes in its
        // lumen below −900); the scope comes from above it.
        let root_node = nodes.iter().position(|n| n.voxel == root).unwrap_or(0);
        let diameter = |n: usize| diameter_mm(volume, field, &nodes[n.max(root_node)]);
        let mut branches: Vec<AirwayBranch> = runs
            .into_iter()
            .zip(labels)
            .map(|(run, (name, generation))| AirwayBranch {
                name,
                generation,
                parent: run.parent,
                points_mm: run.nodes.iter().map(|&n| nodes[n].point_mm).collect(),
                diameters_mm: run.nodes.iter().map(|&n| diameter(n)).collect(),
                split_mm: None,
            })
            .collect();
        for (b, split) in split::splits(&branches, field).into_iter().enumerate() {
            branches[b].split_mm = split;
        }
        Self {
            branches,
            threshold: lumen.threshold(),
        }
    }

    /// The branches, the trachea first, every branch after the one it leaves.
    pub fn branches(&self) -> &[AirwayBranch] {
        &self.branches
    }

    /// The branches from the trachea down to branch `b`, in order.
    pub fn lineage(&self, b: usize) -> Vec<usize> {
        let mut line = vec![b];
        while let Some(p) = self.branches[line[line.len() - 1]].parent {
            line.push(p);
        }
        line.reverse();
        line
    }

    /// The carina: where the trachea's lumen splits into the main bronchi (the trachea's
    /// [`AirwayBranch::split_mm`]), world mm; `None` when the tree does not fork.
    pub fn carina_mm(&self) -> Option<DVec3> {
        self.branches.first().and_then(|b| b.split_mm)
    }

    /// The first branch named `name`.
    pub fn find(&self, name: &str) -> Option<&AirwayBranch> {
        self.branches.iter().find(|b| b.name == name)
    }
}
