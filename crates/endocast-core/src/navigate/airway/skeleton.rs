//! The airway tree's centrelines as a tree of voxels, by TEASAR (Sato et al., 2000): the
//! centred paths from the root to every lumen voxel (one Dijkstra search), then repeatedly the
//! path to the farthest voxel not yet covered, down to where it meets the tree; each path added
//! covers the lumen within a few radii of it, so that the wall's bumps give no branches.

use super::super::centreline::CentredPaths;
use super::super::distance::DistanceField;
use super::super::lumen::Lumen;
use crate::Volume;
use glam::DVec3;

/// A path covers the lumen within this many times its local radius of it.
const COVER_SCALE: f64 = 1.5;
/// ... plus this much, mm.
const COVER_MARGIN_MM: f64 = 2.0;
/// A branch is kept when it runs this much farther than the radius where it leaves the tree, mm:
/// shorter ones are the wall's bumps at a junction.
const MIN_BRANCH_MM: f64 = 3.0;
/// At most this many paths are tried (each covers some of the lumen, so all are needed only in
/// a lumen of scattered specks).
const MAX_PATHS: usize = 2000;

/// One centreline voxel of the tree.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Node {
    /// Its voxel (volume index).
    pub voxel: [usize; 3],
    /// Its centre, world mm.
    pub point_mm: DVec3,
    /// Its distance to the nearest wall voxel centre, mm.
    pub distance_mm: f64,
    /// The node before it towards the root (`None` for the root, node 0).
    pub parent: Option<usize>,
}

/// The tree of centreline voxels of `lumen` (with its distance `field`) grown from `root`,
/// root first, every node after its parent.
pub(super) fn skeletonise(
    volume: &Volume,
    lumen: &Lumen,
    field: &DistanceField,
    root: [usize; 3],
) -> Vec<Node> {
    let paths = CentredPaths::new(volume, lumen, field, root);
    let voxels: Vec<[usize; 3]> = lumen.voxels().collect();
    let mut farthest_first: Vec<(usize, f64)> = (0..voxels.len())
        .filter_map(|n| paths.length_mm(n).map(|l| (n, l)))
        .collect();
    farthest_first.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut tree = Tree {
        field,
        paths: &paths,
        spacing_mm: volume.geometry().spacing_mm(),
        covered: vec![false; voxels.len()],
        node_of: vec![u32::MAX; voxels.len()],
        nodes: Vec::new(),
    };
    tree.add(&[root], None);
    tree.cover(&[root]);
    let mut tried = 0;
    for &(n, length_mm) in &farthest_first {
        if tried == MAX_PATHS {
            break;
        }
        if !tree.covered[n] {
            tried += 1;
            tree.grow_to(voxels[n], length_mm);
        }
    }
    tree.nodes
}

/// The tree while it grows.
struct Tree<'a> {
    field: &'a DistanceField,
    paths: &'a CentredPaths<'a>,
    spacing_mm: DVec3,
    covered: Vec<bool>,
    /// Node index of each lumen voxel (by number), `u32::MAX` where none.
    node_of: Vec<u32>,
    nodes: Vec<Node>,
}

impl Tree<'_> {
    /// Adds the centred path to `tip` (whose path is `length_mm` long) from where it meets the
    /// tree, when it is a branch (see [`MIN_BRANCH_MM`]), and covers the lumen around it.
    fn grow_to(&mut self, tip: [usize; 3], length_mm: f64) {
        let numbering = self.paths.numbering();
        let mut chain = Vec::new();
        let mut v = tip;
        let junction = loop {
            let Some(n) = numbering.number(v) else { return };
            if self.node_of[n] != u32::MAX {
                break self.node_of[n] as usize;
            }
            chain.push(v);
            match self.paths.parent(v) {
                Some(up) => v = up,
                None => return,
            }
        };
        chain.reverse();
        let junction_length = numbering
            .number(v)
            .and_then(|n| self.paths.length_mm(n))
            .unwrap_or(0.0);
        let junction_radius = self.nodes[junction].distance_mm;
        if length_mm - junction_length >= junction_radius + MIN_BRANCH_MM {
            self.add(&chain, Some(junction));
        }
        self.cover(&chain);
    }

    /// Appends `chain` as a path of nodes below `parent`.
    fn add(&mut self, chain: &[[usize; 3]], mut parent: Option<usize>) {
        for &v in chain {
            let index = self.nodes.len();
            if let Some(n) = self.paths.numbering().number(v) {
                self.node_of[n] = index as u32;
            }
            self.nodes.push(Node {
                voxel: v,
                point_mm: self.field.world_of_voxel(v),
                distance_mm: self.field.distance_at_voxel(v),
                parent,
            });
            parent = Some(index);
        }
    }

    /// Marks the lumen within [`COVER_SCALE`] radii plus [`COVER_MARGIN_MM`] of `chain` covered.
    fn cover(&mut self, chain: &[[usize; 3]]) {
        let spacing = self.spacing_mm;
        let numbering = self.paths.numbering();
        let dims = numbering.lumen().volume_dims();
        for &v in chain {
            let centre = self.field.world_of_voxel(v);
            let reach_mm = COVER_SCALE * self.field.distance_at_voxel(v) + COVER_MARGIN_MM;
            let reach = [spacing.x, spacing.y, spacing.z].map(|s| (reach_mm / s).ceil() as usize);
            let range =
                |a: usize| v[a].saturating_sub(reach[a])..=(v[a] + reach[a]).min(dims[a] - 1);
            for k in range(2) {
                for j in range(1) {
                    for i in range(0) {
                        let Some(n) = numbering.number([i, j, k]) else {
                            continue;
                        };
                        if !self.covered[n]
                            && self.field.world_of_voxel([i, j, k]).distance(centre) <= reach_mm
                        {
                            self.covered[n] = true;
                        }
                    }
                }
            }
        }
    }
}
