//! The airway tree's centrelines as a tree of voxels, by TEASAR (Sato et al., 2000): the
//! centred paths from the root to every lumen voxel (one Dijkstra search), then repeatedly the
//! path to the farthest voxel not yet covered, down to where it meets the tree; each path added
//! covers the lumen within a few radii of it, so that the wall's bumps give no branches.
//!
//! The tree starts in the middle of the trachea's section where the scan's top cuts it
//! ([`top_middle`]) and runs down the centred path to the root ([`root_near`]), so that a route
//! starts on the trachea's axis as high as the scan shows it; a branch is joined to the tree by
//! the centred path from its branch point ([`Tree::link`]), so that every branch runs on
//! without a gap, voxel by voxel, on the lumen's medial ridge.

use super::super::centreline::CentredPaths;
use super::super::distance::DistanceField;
use super::super::lumen::Lumen;
use super::body::long_axis;
use crate::Volume;
use glam::DVec3;

/// A path covers the lumen within this many times its local radius of it.
const COVER_SCALE: f64 = 1.5;
/// ... plus this much, mm.
const COVER_MARGIN_MM: f64 = 2.0;
/// A branch is kept when it runs this far beyond the lumen around the tree, mm: shorter ones
/// are the wall's bumps.
const MIN_BRANCH_MM: f64 = 3.0;
/// The root is the widest lumen voxel this near the seed, mm, and no branch starts this near
/// the seed: the seed lies on the scan's top face, where the border, not the wall, limits the
/// distance to the wall, and the rim of the trachea's cut is no branch.
const ROOT_REACH_MM: f64 = 25.0;
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

/// The tree of centreline voxels of `lumen` (with its distance `field`) grown from `root` (see
/// [`root_near`]), its entry from the scan's top first ([`entry`]: nodes 0 up to the root),
/// every node after its parent. No
/// branch starts within [`ROOT_REACH_MM`] of the lumen's seed (the trachea's top, above the
/// root); a branch the scan's face cuts ends in the middle of the cut ([`Tree::trimmed`]).
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
    let seed_mm = field.world_of_voxel(lumen.seed());
    let settled = |v: &[usize; 3]| field.world_of_voxel(*v).distance(seed_mm) <= ROOT_REACH_MM;
    let mut tree = Tree {
        field,
        paths: &paths,
        spacing_mm: volume.geometry().spacing_mm(),
        covered: voxels.iter().map(settled).collect(),
        node_of: vec![u32::MAX; voxels.len()],
        nodes: Vec::new(),
    };
    let entry = entry(&paths, top_middle(volume, lumen, field), root);
    tree.add(&entry, None);
    tree.cover(&entry);
    let mut tried = 0;
    for &(n, _) in &farthest_first {
        if tried == MAX_PATHS {
            break;
        }
        if !tree.covered[n] {
            tried += 1;
            tree.grow_to(voxels[n]);
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
    /// Adds the centred path to `tip` from where it leaves the lumen around the tree (see
    /// [`Tree::leaving`]), when it is a branch (see [`MIN_BRANCH_MM`]), and covers the lumen
    /// around it.
    fn grow_to(&mut self, tip: [usize; 3]) {
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
        let (junction, start) = self.leaving(&chain, junction);
        let new = &chain[start..];
        let points: Vec<DVec3> = std::iter::once(self.nodes[junction].point_mm)
            .chain(new.iter().map(|&v| self.field.world_of_voxel(v)))
            .collect();
        let length: f64 = points.windows(2).map(|w| w[0].distance(w[1])).sum();
        if let (true, Some(&first)) = (length >= MIN_BRANCH_MM, new.first()) {
            let (junction, link) = self.link(junction, first);
            let branch: Vec<[usize; 3]> = link
                .into_iter()
                .chain(self.trimmed(new)[1..].iter().copied())
                .collect();
            self.add(&branch, Some(junction));
        }
        self.cover(&chain);
    }

    /// The centred path from tree node `junction` to voxel `first` (off the tree), from where
    /// it last leaves the tree: that node and the voxels after it, `first` the last. The
    /// branch's own path parts from the tree above its branch point (see [`Tree::leaving`]),
    /// and a straight link from the branch point to where it leaves its parent's lumen (up to
    /// a radius and a half away) would cut the corner; this one runs along the ridge between
    /// the parent's and the branch's lumens.
    fn link(&self, junction: usize, first: [usize; 3]) -> (usize, Vec<[usize; 3]>) {
        let numbering = self.paths.numbering();
        let node = |v: [usize; 3]| {
            numbering
                .number(v)
                .map(|n| self.node_of[n])
                .filter(|&n| n != u32::MAX)
        };
        let path = self
            .paths
            .between(self.nodes[junction].voxel, first)
            .unwrap_or_else(|| vec![self.nodes[junction].voxel, first]);
        match path.iter().rposition(|&v| node(v).is_some()) {
            Some(last) => (
                node(path[last]).map_or(junction, |n| n as usize),
                path[last + 1..].to_vec(),
            ),
            None => (junction, path),
        }
    }

    /// Where a path from the tree's node `junction` down `chain` leaves the lumen around the tree:
    /// the tree node within [`COVER_SCALE`] radii of the path's last point inside, and the index of the
    /// path's first point outside. The centred paths to two branches part where the lumen is
    /// wide enough for both, above the branch point; this moves the branch point down to where
    /// the new branch leaves its parent's lumen.
    fn leaving(&self, chain: &[[usize; 3]], mut junction: usize) -> (usize, usize) {
        for (i, &v) in chain.iter().enumerate() {
            let p = self.field.world_of_voxel(v);
            let nearest = (0..self.nodes.len())
                .min_by(|&a, &b| {
                    let da = self.nodes[a].point_mm.distance(p);
                    da.total_cmp(&self.nodes[b].point_mm.distance(p))
                })
                .unwrap_or(junction);
            if p.distance(self.nodes[nearest].point_mm)
                >= COVER_SCALE * self.nodes[nearest].distance_mm
            {
                return (junction, i);
            }
            junction = nearest;
        }
        (junction, chain.len())
    }

    /// `chain` less its tail inside the inscribed ball of an earlier voxel. The farthest voxel of
    /// a branch lies on the wall of its end (or on the rim where the scan cuts it), so the path
    /// to it leaves the axis over its last radius; the branch ends at the first voxel whose
    /// inscribed ball holds that tip: the centre of a rounded end, the middle of a cut.
    fn trimmed<'c>(&self, chain: &'c [[usize; 3]]) -> &'c [[usize; 3]] {
        let Some(&tip) = chain.last() else {
            return chain;
        };
        let tip_mm = self.field.world_of_voxel(tip);
        let end = chain
            .iter()
            .position(|&v| {
                self.field.world_of_voxel(v).distance(tip_mm) <= self.field.distance_at_voxel(v)
            })
            .unwrap_or(chain.len() - 1);
        &chain[..=end]
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

/// The centred path from voxel `top` down to `root` (whose centred `paths` they are), `top`
/// first; `[root]` when `top` is not reached.
fn entry(paths: &CentredPaths, top: [usize; 3], root: [usize; 3]) -> Vec<[usize; 3]> {
    let chain: Vec<[usize; 3]> = std::iter::successors(Some(top), |&v| paths.parent(v)).collect();
    if chain.last() == Some(&root) {
        chain
    } else {
        vec![root]
    }
}

/// The widest voxel of `lumen` within [`ROOT_REACH_MM`] of `seed`: the tree's root.
pub(super) fn root_near(lumen: &Lumen, field: &DistanceField, seed: [usize; 3]) -> [usize; 3] {
    let seed_mm = field.world_of_voxel(seed);
    lumen
        .voxels()
        .filter(|&v| field.world_of_voxel(v).distance(seed_mm) <= ROOT_REACH_MM)
        .max_by(|&a, &b| {
            field
                .distance_at_voxel(a)
                .total_cmp(&field.distance_at_voxel(b))
        })
        .unwrap_or(seed)
}

/// The lumen voxel nearest the middle of the lumen's section through its seed across the
/// body's long axis (within [`ROOT_REACH_MM`] of the seed). The seed lies on the scan's top
/// face, where the scan cuts the trachea, and on the rim of that cut as often as not; this
/// voxel is on the trachea's axis there.
fn top_middle(volume: &Volume, lumen: &Lumen, field: &DistanceField) -> [usize; 3] {
    let seed = lumen.seed();
    let axis = long_axis(volume);
    let seed_mm = field.world_of_voxel(seed);
    let section: Vec<([usize; 3], DVec3)> = lumen
        .voxels()
        .filter(|v| v[axis] == seed[axis])
        .map(|v| (v, field.world_of_voxel(v)))
        .filter(|(_, p)| p.distance(seed_mm) <= ROOT_REACH_MM)
        .collect();
    let middle = section.iter().map(|(_, p)| *p).sum::<DVec3>() / section.len().max(1) as f64;
    section
        .into_iter()
        .min_by(|a, b| a.1.distance(middle).total_cmp(&b.1.distance(middle)))
        .map_or(seed, |(v, _)| v)
}
