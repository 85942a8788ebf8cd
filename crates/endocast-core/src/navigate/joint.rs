//! A joint space with no seed (the knee's, between femur and tibia): the dark gap between the
//! two largest bones.
//!
//! On T1 the bones' fatty marrow is bright, and so is the fat around them: everything above
//! the threshold is one component, and the dark gap between the bones joins the dark muscle
//! and the air outside. The bones are told from the fat by their thickness: the cores of the
//! bright tissue (its voxels [`BONE_CORE_DEPTH_MM`] from anything dark, holes in the marrow's
//! texture filled) fall apart into the bones' marrow, the two largest being the femur and the
//! tibia. Where their cores come closest, the darkest point between them is the joint space;
//! the dark voxels joined to it within a lens around the two closest points
//! ([`JOINT_REACH_MM`]) are the space an arthroscope looks around in.

use super::bit_grid::BitGrid;
use super::distance::DistanceField;
use super::lumen::{largest_components, Lumen, LumenSide};
use super::plan::seed_voxel;
use crate::Volume;
use glam::DVec3;

/// How deep inside the bright tissue a bone's core lies, mm: deeper than the fat under the
/// skin and around the joint reaches, shallower than the femur's and tibia's marrow.
pub const BONE_CORE_DEPTH_MM: f64 = 8.0;
/// How far the joint space reaches beyond the segment between the bones' closest points, mm:
/// the lens of points whose distances to the two points add up to at most their distance
/// plus twice this.
pub const JOINT_REACH_MM: f64 = 10.0;
/// The widest dark gap between the two bones still taken for a joint space, mm: the joint
/// space without distension is a few millimetres, wider is soft tissue between bones apart.
pub const MAX_JOINT_GAP_MM: f64 = 10.0;

/// A joint space found between two bones.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// The dark space: the voxels below the threshold joined to `gap_mm` within the lens
    /// between the bones (see [`JOINT_REACH_MM`]).
    pub space: Lumen,
    /// The darkest point between the bones where they come closest, world mm.
    pub gap_mm: DVec3,
    /// The closest points of the two bones' cores, world mm (largest bone first).
    pub cores_mm: [DVec3; 2],
    /// The width of the gap there, mm: the run of the segment between the two points below
    /// the threshold around `gap_mm`.
    pub width_mm: f64,
}

/// The joint space below `threshold` (the marrow/tissue boundary of a T1 joint) between the
/// two largest bones of `volume` (see the module documentation). `None` without two bones,
/// or when no point between them is below the threshold.
pub fn find_joint(volume: &Volume, threshold: f64) -> Option<Joint> {
    let object = Lumen::object(volume, threshold, LumenSide::Below).ok()??;
    let field = DistanceField::new(&object, volume.geometry());
    let mut cores = BitGrid::new(volume.dims());
    for v in object.voxels() {
        if field.distance_at_voxel(v) >= BONE_CORE_DEPTH_MM {
            cores.set(v);
        }
    }
    let bones = largest_components(&cores, 2);
    let [first, second] = bones.as_slice() else {
        return None;
    };
    let (a, b) = closest_points(&surface(first, volume), &surface(second, volume))?;
    let (gap_mm, width_mm) = darkest_between(volume, a, b, threshold);
    let seed = seed_voxel(volume, gap_mm).ok()?;
    let lens = lens_between(volume, a, b);
    let space = Lumen::within(volume, seed, threshold, LumenSide::Below, &lens).ok()?;
    Some(Joint {
        space,
        gap_mm,
        cores_mm: [a, b],
        width_mm,
    })
}

/// The voxels of `volume` whose distances to world points `a` and `b` (mm) add up to at most
/// theirs plus twice [`JOINT_REACH_MM`]: an ellipsoid with `a` and `b` as its foci.
fn lens_between(volume: &Volume, a: DVec3, b: DVec3) -> BitGrid {
    let reach = a.distance(b) + 2.0 * JOINT_REACH_MM;
    let dims = volume.dims();
    let geometry = volume.geometry();
    let mut lens = BitGrid::new(dims);
    for n in 0..dims[0] * dims[1] * dims[2] {
        let v = [n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])];
        let p = geometry.world_of(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64));
        if p.distance(a) + p.distance(b) <= reach {
            lens.set(v);
        }
    }
    lens
}

/// World positions (mm) of the voxels of `grid` with a 6-neighbour outside it.
fn surface(grid: &BitGrid, volume: &Volume) -> Vec<DVec3> {
    let dims = volume.dims();
    let g = volume.geometry();
    let inside = |v: [usize; 3], a: usize, up: bool| {
        let mut w = v;
        w[a] = if up { v[a] + 1 } else { v[a].wrapping_sub(1) };
        w[a] < dims[a] && grid.get(w)
    };
    let mut points = Vec::new();
    for n in 0..dims[0] * dims[1] * dims[2] {
        let v = [n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])];
        if grid.get_linear(n) && (0..3).any(|a| !inside(v, a, false) || !inside(v, a, true)) {
            points.push(g.world_of(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)));
        }
    }
    points
}

/// The closest pair of points, one of `first`, one of `second` (brute force: the surfaces
/// of two cores hold a few thousand voxels each).
fn closest_points(first: &[DVec3], second: &[DVec3]) -> Option<(DVec3, DVec3)> {
    first
        .iter()
        .flat_map(|&a| second.iter().map(move |&b| (a, b)))
        .min_by(|x, y| {
            x.0.distance_squared(x.1)
                .total_cmp(&y.0.distance_squared(y.1))
        })
}

/// The point of the segment from `a` to `b` (world mm) with the lowest value, sampled every
/// half of the smallest voxel spacing, and the length (mm) of the run of samples below
/// `threshold` around it (0 where it is not below).
fn darkest_between(volume: &Volume, a: DVec3, b: DVec3, threshold: f64) -> (DVec3, f64) {
    let step = 0.5 * volume.geometry().spacing_mm().min_element();
    let samples = (a.distance(b) / step).ceil().max(1.0) as usize;
    let to_voxel = volume.geometry().voxel_from_world();
    let values: Vec<f64> = (0..=samples)
        .map(|s| {
            let p = a.lerp(b, s as f64 / samples as f64);
            volume
                .sample_physical(to_voxel.transform_point3(p))
                .unwrap_or(f64::INFINITY)
        })
        .collect();
    let darkest = (0..values.len())
        .min_by(|&x, &y| values[x].total_cmp(&values[y]))
        .unwrap_or(0);
    let dark = |s: &usize| values[*s] < threshold;
    let first = (0..=darkest).rev().take_while(dark).last();
    let last = (darkest..values.len()).take_while(dark).last();
    let run = match (first, last) {
        (Some(first), Some(last)) => (last - first + 1) as f64 * a.distance(b) / samples as f64,
        _ => 0.0,
    };
    (a.lerp(b, darkest as f64 / samples as f64), run)
}
