//! The minimal centred path through a lumen: Dijkstra's algorithm over the lumen's voxels
//! (26-neighbourhood), each step costing its length in mm times a cost that grows steeply
//! towards the wall.
//!
//! The cost of a voxel is `(d_max / d)^3`, `d` its distance to the wall ([`DistanceField`]) and
//! `d_max` the lumen's largest. A path displaced by `δ` from the axis of a tube of radius `R`
//! pays about `1 + 3δ/R` per mm, while a bend of radius `ρ` saves only `δ/ρ` per mm by cutting
//! the corner, so the centre wins whenever `ρ > R/3`: any bend a tube can make without folding
//! onto itself. An exponent of 2 would do as well in theory, but at 3 the metrication error of
//! the 26-neighbour lattice (up to 8 % longer diagonal detours) is outweighed too; higher
//! exponents add nothing but dynamic range. Dividing by `d_max` keeps costs near 1 in the
//! middle of any lumen, whatever its size. Lumen voxels have `d` of at least a voxel, so the
//! cost is finite.
//!
//! Work arrays hold one entry per lumen voxel (not per voxel of its box): 9 bytes each (13 when
//! looking for the farthest point), plus the costs (4 bytes) and the heap.

use super::distance::DistanceField;
use super::error::NavError;
use super::lumen::{Lumen, LumenNumbering};
use crate::Volume;
use glam::DVec3;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Exponent of the centring cost (see the module doc).
const COST_EXPONENT: i32 = 3;
/// How far a start or end point in the wall, or right against it, is moved to reach a lumen
/// voxel clear of the wall, mm, at least: on coarse voxels it is [`SNAP_RADIUS_VOXELS`] of the
/// largest spacing (see [`snap_radius_mm`]).
pub const SNAP_RADIUS_MM: f64 = 5.0;
/// The snap radius in voxels (of the largest spacing) where that is more than
/// [`SNAP_RADIUS_MM`]: a point one voxel off a narrow lumen of 3 mm voxels still snaps.
pub const SNAP_RADIUS_VOXELS: f64 = 3.0;

/// The snap radius for voxels of `spacing_mm`: [`SNAP_RADIUS_MM`], or
/// [`SNAP_RADIUS_VOXELS`] of the largest spacing where that is more.
pub fn snap_radius_mm(spacing_mm: DVec3) -> f64 {
    SNAP_RADIUS_MM.max(SNAP_RADIUS_VOXELS * spacing_mm.max_element())
}
/// No predecessor (the start).
const NONE: u8 = u8::MAX;

/// Where a path ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathEnd {
    /// At this world point (mm, LPS), snapped to the lumen like the start.
    Point(DVec3),
    /// At the lumen voxel farthest from the start along the centred paths (by their length).
    Farthest,
}

/// A raw (unsmoothed) centreline: voxel centres from start to end, in world mm.
#[derive(Debug, Clone, PartialEq)]
pub struct CentrelinePath {
    /// Voxel centres along the path, world mm (LPS), start first; consecutive points are
    /// 26-neighbours.
    pub points_mm: Vec<DVec3>,
    /// Length of the polyline, mm.
    pub length_mm: f64,
    /// Smallest distance to the wall along the path (at its voxels), mm.
    pub min_distance_mm: f64,
    /// Mean distance to the wall along the path (per voxel), mm.
    pub mean_distance_mm: f64,
}

/// The minimal centred path through `lumen` (found in `volume`, with its distance `field`) from
/// `start_mm` to `end`. A point in the wall, or within a voxel of it, is snapped to the nearest
/// lumen voxel clear of the wall within [`snap_radius_mm`]. Errors: a non-finite point, a point
/// outside the volume, a point in the wall with nothing to snap to, and a point in another lumen
/// component than `lumen` ([`NavError::Disconnected`], naming both points).
pub fn centreline(
    volume: &Volume,
    lumen: &Lumen,
    field: &DistanceField,
    start_mm: DVec3,
    end: PathEnd,
) -> Result<CentrelinePath, NavError> {
    let snapper = Snapper {
        volume,
        lumen,
        field,
    };
    let radius_mm = snap_radius_mm(volume.geometry().spacing_mm());
    let start = snapper.snap(start_mm);
    let end_voxel = match end {
        PathEnd::Point(p) => Some((p, snapper.snap(p))),
        PathEnd::Farthest => None,
    };
    let disconnected = |end_mm: DVec3| NavError::Disconnected {
        start_mm: start_mm.to_array(),
        end_mm: end_mm.to_array(),
    };
    let start = match (start, end_voxel.as_ref()) {
        (Err(Snap::OtherLumen), Some((end_mm, _))) => return Err(disconnected(*end_mm)),
        (start, _) => start.map_err(|s| s.into_error(start_mm, radius_mm))?,
    };
    let graph = Graph::new(volume, lumen, field);
    let path = match end_voxel {
        Some((end_mm, snapped)) => {
            let goal = snapped.map_err(|s| match s {
                Snap::OtherLumen => disconnected(end_mm),
                other => other.into_error(end_mm, radius_mm),
            })?;
            graph.search(start, Some(goal)).path_to(&graph, goal)
        }
        None => {
            let search = graph.search(start, None);
            let far = search.farthest(&graph);
            search.path_to(&graph, far)
        }
    };
    path.ok_or_else(|| disconnected(start_mm))
        .map(|voxels| summarise(field, &voxels))
}

/// The centred paths from one lumen voxel to every other (one Dijkstra search over the whole
/// lumen): the shortest-path tree the airway tree is skeletonised from.
pub(crate) struct CentredPaths<'a> {
    graph: Graph<'a>,
    search: Search,
}

impl<'a> CentredPaths<'a> {
    /// The centred paths through `lumen` (with its distance `field`) from voxel `start`.
    pub(crate) fn new(
        volume: &Volume,
        lumen: &'a Lumen,
        field: &'a DistanceField,
        start: [usize; 3],
    ) -> Self {
        let graph = Graph::new(volume, lumen, field);
        let search = graph.search(start, None);
        Self { graph, search }
    }

    /// The length (mm) of the centred path to voxel number `n` (in the lumen's numbering), or
    /// `None` when it was not reached.
    pub(crate) fn length_mm(&self, n: usize) -> Option<f64> {
        self.search.cost[n]
            .is_finite()
            .then(|| f64::from(self.search.length_mm[n]))
    }

    /// The voxel before `v` on its centred path, or `None` for the start and voxels not
    /// reached.
    pub(crate) fn parent(&self, v: [usize; 3]) -> Option<[usize; 3]> {
        let n = self.graph.numbering.number(v)?;
        let by = *self.search.came_by.get(n).filter(|&&b| b != NONE)?;
        let o = self.graph.steps[usize::from(by)].0;
        Some([0, 1, 2].map(|a| v[a].wrapping_add_signed(-o[a])))
    }

    /// The centred path from lumen voxel `from` to lumen voxel `to`, `from` first (a search of
    /// its own, over the same costs); `None` when `to` is not reached from `from`.
    pub(crate) fn between(&self, from: [usize; 3], to: [usize; 3]) -> Option<Vec<[usize; 3]>> {
        self.graph.search(from, Some(to)).path_to(&self.graph, to)
    }

    /// The lumen's numbering.
    pub(crate) fn numbering(&self) -> &LumenNumbering<'a> {
        &self.graph.numbering
    }
}

/// Why a point could not be placed in the lumen.
enum Snap {
    NotFinite(f64),
    Outside,
    Wall,
    /// On the lumen side of the threshold, but in another component.
    OtherLumen,
}

impl Snap {
    fn into_error(self, p_mm: DVec3, radius_mm: f64) -> NavError {
        match self {
            Self::NotFinite(value) => NavError::BadNumber {
                what: "point coordinate (mm)",
                extra: "",
                value,
            },
            Self::Outside => NavError::PointOutside {
                point_mm: p_mm.to_array(),
            },
            // A point in another lumen with no end point to name is in this lumen's wall.
            Self::Wall | Self::OtherLumen => NavError::PointInWall {
                point_mm: p_mm.to_array(),
                radius_mm,
            },
        }
    }
}

/// Places world points on lumen voxels clear of the wall.
struct Snapper<'a> {
    volume: &'a Volume,
    lumen: &'a Lumen,
    field: &'a DistanceField,
}

impl Snapper<'_> {
    /// The voxel of `p_mm` when it is in the lumen and clear of the wall (farther than one
    /// voxel), else the nearest such voxel within [`snap_radius_mm`].
    fn snap(&self, p_mm: DVec3) -> Result<[usize; 3], Snap> {
        if let Some(&bad) = p_mm.to_array().iter().find(|c| !c.is_finite()) {
            return Err(Snap::NotFinite(bad));
        }
        let v = self.field.voxel_of_world(p_mm).round();
        let dims = self.volume.dims();
        let inside = (0..3).all(|a| v[a] >= 0.0 && v[a] < dims[a] as f64);
        if !inside {
            return Err(Snap::Outside);
        }
        let voxel = [v.x as usize, v.y as usize, v.z as usize];
        if self.clear(voxel) {
            return Ok(voxel);
        }
        if let Some(near) = self.nearest_clear(voxel, p_mm) {
            return Ok(near);
        }
        let value = self.volume.physical(voxel[0], voxel[1], voxel[2]);
        let lumen_valued =
            value.is_some_and(|x| self.lumen.side().holds(x, self.lumen.threshold()));
        Err(if lumen_valued && !self.lumen.contains(voxel) {
            Snap::OtherLumen
        } else {
            Snap::Wall
        })
    }

    /// In the lumen and farther than one voxel from the wall.
    fn clear(&self, v: [usize; 3]) -> bool {
        self.lumen.contains(v)
            && self.field.distance_at_voxel(v) > self.field.min_spacing_mm() * 1.001
    }

    /// The clear voxel nearest to `p_mm` within [`snap_radius_mm`] of it, around voxel `v`.
    fn nearest_clear(&self, v: [usize; 3], p_mm: DVec3) -> Option<[usize; 3]> {
        let spacing = self.volume.geometry().spacing_mm();
        let radius = snap_radius_mm(spacing);
        let reach = [spacing.x, spacing.y, spacing.z].map(|s| (radius / s).ceil() as usize);
        let dims = self.volume.dims();
        let range = |a: usize| v[a].saturating_sub(reach[a])..=(v[a] + reach[a]).min(dims[a] - 1);
        let mut best: Option<(f64, [usize; 3])> = None;
        for k in range(2) {
            for j in range(1) {
                for i in range(0) {
                    let d = self.field.world_of_voxel([i, j, k]).distance(p_mm);
                    let closer = best.is_none_or(|(b, _)| d < b);
                    if d <= radius && closer && self.clear([i, j, k]) {
                        best = Some((d, [i, j, k]));
                    }
                }
            }
        }
        best.map(|(_, voxel)| voxel)
    }
}

/// The lumen as a graph: its voxels numbered densely, the 26 neighbour steps with their lengths
/// in mm, and each voxel's centring cost.
struct Graph<'a> {
    numbering: LumenNumbering<'a>,
    dims: [usize; 3],
    /// Index offset and length (mm) of each of the 26 neighbour steps.
    steps: Vec<([isize; 3], f64)>,
    /// Cost per mm of each lumen voxel, by number (see the module doc).
    cost: Vec<f32>,
}

impl<'a> Graph<'a> {
    fn new(volume: &Volume, lumen: &'a Lumen, field: &'a DistanceField) -> Self {
        let linear = volume.geometry().world_from_voxel().matrix3;
        let offsets =
            (-1..=1).flat_map(|k| (-1..=1).flat_map(move |j| (-1..=1).map(move |i| [i, j, k])));
        let steps = offsets
            .filter(|o| *o != [0, 0, 0])
            .map(|o: [isize; 3]| {
                let mm = linear * DVec3::new(o[0] as f64, o[1] as f64, o[2] as f64);
                (o, mm.length())
            })
            .collect();
        let cost = lumen
            .voxels()
            .map(|v| {
                let d = field.distance_at_voxel(v).max(1e-6);
                (field.max_mm() / d).powi(COST_EXPONENT) as f32
            })
            .collect();
        Self {
            numbering: LumenNumbering::new(lumen),
            dims: volume.dims(),
            steps,
            cost,
        }
    }

    /// The neighbour of `v` by step `s`, when inside the volume.
    fn neighbour(&self, v: [usize; 3], s: usize) -> Option<[usize; 3]> {
        let o = self.steps[s].0;
        let w = [0, 1, 2].map(|a| v[a].wrapping_add_signed(o[a]));
        (0..3).all(|a| w[a] < self.dims[a]).then_some(w)
    }

    /// Dijkstra from `start`, stopping when `goal` (if any) is settled.
    fn search(&self, start: [usize; 3], goal: Option<[usize; 3]>) -> Search {
        let mut search = Search {
            cost: vec![f32::INFINITY; self.cost.len()],
            came_by: vec![NONE; self.cost.len()],
            length_mm: vec![0.0; if goal.is_none() { self.cost.len() } else { 0 }],
        };
        let Some(first) = self.numbering.number(start) else {
            return search;
        };
        search.cost[first] = 0.0;
        let mut heap = BinaryHeap::from([Reverse((0u32, start))]);
        while let Some(Reverse((bits, v))) = heap.pop() {
            let here = self.numbering.number(v).unwrap_or(first);
            // Costs are non-negative f32, whose bit patterns order like the values.
            if bits > search.cost[here].to_bits() {
                continue;
            }
            if Some(v) == goal {
                break;
            }
            let cost_v = self.cost[here];
            for s in 0..self.steps.len() {
                let Some(w) = self.neighbour(v, s) else {
                    continue;
                };
                let Some(there) = self.numbering.number(w) else {
                    continue;
                };
                let edge = self.steps[s].1 * 0.5 * f64::from(cost_v + self.cost[there]);
                let total = (f64::from(search.cost[here]) + edge) as f32;
                if total < search.cost[there] {
                    search.cost[there] = total;
                    search.came_by[there] = s as u8;
                    if let Some(len) = search.length_mm.get(here).copied() {
                        search.length_mm[there] = len + self.steps[s].1 as f32;
                    }
                    heap.push(Reverse((total.to_bits(), w)));
                }
            }
        }
        search
    }
}

/// Dijkstra's result: accumulated cost and the step that reached each lumen voxel, and (when
/// looking for the farthest voxel) the length in mm of the path that reached it.
struct Search {
    cost: Vec<f32>,
    came_by: Vec<u8>,
    length_mm: Vec<f32>,
}

impl Search {
    /// The reached voxel with the longest path (the first in linear order among ties).
    fn farthest(&self, graph: &Graph) -> [usize; 3] {
        let mut best = (f32::NEG_INFINITY, graph.numbering.lumen().seed());
        for (n, v) in graph.numbering.lumen().voxels().enumerate() {
            if self.cost[n].is_finite() && self.length_mm[n] > best.0 {
                best = (self.length_mm[n], v);
            }
        }
        best.1
    }

    /// The voxels from the start to `goal`, or `None` when `goal` was not reached.
    fn path_to(&self, graph: &Graph, goal: [usize; 3]) -> Option<Vec<[usize; 3]>> {
        let mut n = graph.numbering.number(goal)?;
        if !self.cost[n].is_finite() {
            return None;
        }
        let mut v = goal;
        let mut voxels = vec![v];
        while self.came_by[n] != NONE {
            let o = graph.steps[usize::from(self.came_by[n])].0;
            v = [0, 1, 2].map(|a| v[a].wrapping_add_signed(-o[a]));
            n = graph.numbering.number(v)?;
            voxels.push(v);
        }
        voxels.reverse();
        Some(voxels)
    }
}

/// World points, length and distances to the wall of a voxel path.
fn summarise(field: &DistanceField, voxels: &[[usize; 3]]) -> CentrelinePath {
    let points_mm: Vec<DVec3> = voxels.iter().map(|&v| field.world_of_voxel(v)).collect();
    CentrelinePath::through(field, points_mm)
}

impl CentrelinePath {
    /// The raw path through `points_mm`, voxel centres of `field`'s lumen in order (each
    /// point's distance is its nearest voxel's).
    pub fn through(field: &DistanceField, points_mm: Vec<DVec3>) -> Self {
        let length_mm = points_mm.windows(2).map(|p| p[0].distance(p[1])).sum();
        let distances: Vec<f64> = points_mm
            .iter()
            .map(|&p| {
                let v = field.voxel_of_world(p).round().max(DVec3::ZERO);
                field.distance_at_voxel([v.x as usize, v.y as usize, v.z as usize])
            })
            .collect();
        CentrelinePath {
            points_mm,
            length_mm,
            min_distance_mm: distances.iter().copied().fold(f64::INFINITY, f64::min),
            mean_distance_mm: distances.iter().sum::<f64>() / distances.len().max(1) as f64,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::navigate::lumen::LumenSide;
    use crate::phantom::{self, PhantomOptions};
    use crate::{Geometry, Modality};

    fn options(size: usize) -> PhantomOptions {
        PhantomOptions {
            size,
            ..Default::default()
        }
    }

    fn field_of(volume: &Volume, seed: [usize; 3]) -> (Lumen, DistanceField) {
        let lumen = Lumen::from_seed(volume, seed, -480.0, LumenSide::Below).unwrap();
        let field = DistanceField::new(&lumen, volume.geometry());
        (lumen, field)
    }

    #[test]
    fn straight_tube_path_follows_the_axis() {
        let (volume, tube) = phantom::straight_tube(&options(48));
        let (lumen, field) = field_of(&volume, [24, 24, 24]);
        let g = volume.geometry();
        let to_vox = g.voxel_from_world();
        let axis_offset = |p: DVec3| {
            let v = to_vox.transform_point3(p);
            (v - tube.centreline.point_at(0.0)).truncate().length()
        };
        let start = DVec3::new(0.0, 0.0, -20.0);
        let path = centreline(&volume, &lumen, &field, start, PathEnd::Point(-start)).unwrap();
        assert!(path.points_mm.iter().all(|&p| axis_offset(p) <= 1.0));
        assert!(path.points_mm[0].distance(start) < 1.0);
        assert!((path.length_mm - 40.0).abs() < 2.0, "{}", path.length_mm);
        // To the farthest point: the far face, along the axis until the last radius or so
        // (the farthest voxel of the face lies on its rim).
        let far = centreline(&volume, &lumen, &field, start, PathEnd::Farthest).unwrap();
        let last = far.points_mm[far.points_mm.len() - 1];
        assert!(last.z > 23.0 - 1e-9, "ends at {last}");
        let body = far
            .points_mm
            .iter()
            .filter(|p| p.z < 23.5 - tube.radius_vox - 2.0);
        assert!(body.clone().count() > 25);
        assert!(body.map(|&p| axis_offset(p)).all(|d| d <= 1.0));
        assert!(far.min_distance_mm >= 1.0 && far.mean_distance_mm > 0.8 * tube.radius_vox);
    }

    #[test]
    fn curved_tube_path_follows_the_arc() {
        let (volume, tube) = phantom::curved_tube(&options(64));
        let g = volume.geometry();
        let seed = tube.axis_point(1.0).round();
        let (lumen, field) = field_of(&volume, [seed.x as usize, seed.y as usize, seed.z as usize]);
        let start = g.world_of(tube.axis_point(0.1));
        let end = g.world_of(tube.axis_point(tube.sweep_rad - 0.1));
        let path = centreline(&volume, &lumen, &field, start, PathEnd::Point(end)).unwrap();
        let to_vox = g.voxel_from_world();
        let ignore_mm = 3.0;
        let mut worst: f64 = 0.0;
        for &p in &path.points_mm {
            if p.distance(start) > ignore_mm && p.distance(end) > ignore_mm {
                worst = worst.max(tube.distance_to_axis_vox(to_vox.transform_point3(p)));
            }
        }
        assert!(worst <= 1.0, "{worst} voxel from the axis");
        let arc = (tube.sweep_rad - 0.2) * tube.arc_radius_vox;
        assert!(
            (path.length_mm - arc).abs() < 0.08 * arc,
            "{} vs {arc}",
            path.length_mm
        );
    }

    #[test]
    fn colon_path_runs_end_to_end_clear_of_the_wall() {
        let (volume, colon) = phantom::colon(&options(128));
        let line = &colon.centreline;
        let g = volume.geometry();
        let seed = line.point_at(0.0).round();
        let (lumen, field) = field_of(&volume, [seed.x as usize, seed.y as usize, seed.z as usize]);
        let start = g.world_of(line.point_at(0.0));
        let end = g.world_of(line.point_at(line.length_vox()));
        let path = centreline(&volume, &lumen, &field, start, PathEnd::Point(end)).unwrap();
        assert!(path.points_mm[0].distance(start) < 1.0);
        assert!(path.points_mm[path.points_mm.len() - 1].distance(end) < 1.0);
        // Every point at least a voxel (1 mm) from the nearest wall voxel, hence off the wall.
        assert!(path.min_distance_mm >= 1.0);
        // And in the middle: within half the local radius of the analytic axis.
        let to_vox = g.voxel_from_world();
        for &p in &path.points_mm {
            let (s, off) = line.closest(to_vox.transform_point3(p));
            assert!(
                off < 0.5 * colon.radius_vox_at(s),
                "{off} voxel off the axis at {s}"
            );
        }
        assert!(
            path.length_mm < 1.1 * line.length_vox(),
            "{}",
            path.length_mm
        );
    }

    #[test]
    fn bad_points_are_errors_and_near_misses_are_snapped() {
        let (volume, shell) = phantom::sphere_shell(&options(32));
        let c = shell.centre_vox.round();
        let (lumen, field) = field_of(&volume, [c.x as usize, c.y as usize, c.z as usize]);
        let g = volume.geometry();
        let centre = g.world_of(shell.centre_vox);
        let go =
            |from: DVec3, to: DVec3| centreline(&volume, &lumen, &field, from, PathEnd::Point(to));
        // Inside the shell to the air outside it.
        let outside = g.world_of(DVec3::new(1.0, 1.0, 1.0));
        let err = go(centre, outside).unwrap_err();
        assert!(matches!(err, NavError::Disconnected { .. }), "{err}");
        assert!(err.to_string().contains("disconnected"));
        assert!(matches!(
            go(outside, centre),
            Err(NavError::Disconnected { .. })
        ));
        assert!(matches!(
            go(centre, DVec3::splat(1e4)),
            Err(NavError::PointOutside { .. })
        ));
        assert!(matches!(
            go(DVec3::NAN, centre),
            Err(NavError::BadNumber { .. })
        ));
        // Just inside the wall: snapped to a voxel clear of it.
        let near_wall = g.world_of(shell.centre_vox + DVec3::X * (shell.inner_radius_vox + 0.7));
        let path = go(near_wall, centre).unwrap();
        assert!(path.points_mm[0].distance(near_wall) <= SNAP_RADIUS_MM);
        assert!(path.min_distance_mm > 1.0);
    }

    #[test]
    fn the_snap_radius_grows_with_coarse_voxels() {
        assert_eq!(snap_radius_mm(DVec3::ONE), SNAP_RADIUS_MM);
        assert_eq!(snap_radius_mm(DVec3::new(1.0, 1.0, 4.0)), 12.0);
        // The sphere shell on 4 mm voxels: a point 0.7 voxel into the wall is 2.8 mm from the
        // lumen, but the nearest voxel clear of the wall lies beyond a fixed 5 mm.
        let (fine, shell) = phantom::sphere_shell(&options(32));
        let g = Geometry::axis_aligned(fine.dims(), DVec3::splat(4.0), DVec3::ZERO).unwrap();
        let volume =
            Volume::new(g, fine.voxels().to_vec(), fine.value_map(), Modality::Ct).unwrap();
        let c = shell.centre_vox.round();
        let (lumen, field) = field_of(&volume, [c.x as usize, c.y as usize, c.z as usize]);
        let g = volume.geometry();
        let near_wall = g.world_of(shell.centre_vox + DVec3::X * (shell.inner_radius_vox + 0.7));
        let centre = g.world_of(shell.centre_vox);
        let path = centreline(&volume, &lumen, &field, near_wall, PathEnd::Point(centre)).unwrap();
        let moved = path.points_mm[0].distance(near_wall);
        assert!(moved > SNAP_RADIUS_MM && moved <= 12.0, "{moved}");
    }

    #[test]
    fn a_point_deep_in_the_wall_is_an_error() {
        let (volume, _) = phantom::straight_tube(&options(48));
        let (lumen, field) = field_of(&volume, [24, 24, 24]);
        // A corner of the tissue block, far more than the snap radius from the tube.
        let corner = DVec3::new(-20.0, -20.0, 0.0);
        let err = centreline(&volume, &lumen, &field, DVec3::ZERO, PathEnd::Point(corner));
        assert!(matches!(err, Err(NavError::PointInWall { .. })), "{err:?}");
        assert!(err.unwrap_err().to_string().contains("in the wall"));
    }
}
