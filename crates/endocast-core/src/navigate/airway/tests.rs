//! The tree, its labels and routes on an analytic airway tree: round tubes of air in soft
//! tissue along known segments, in a block with air around it.

use super::*;
use crate::navigate::{LumenSide, NavError};
use crate::{Geometry, Modality, ValueMap};

/// A segment of the phantom tree: name, start and end (world mm, LPS: +x left, −y anterior,
/// +z superior), radius (mm).
type Segment = (&'static str, [f64; 3], [f64; 3], f64);

/// The phantom's airways. The trachea runs out of the top; the right lower lobe bronchus out of
/// the bottom.
const SEGMENTS: [Segment; 9] = [
    ("trachea", [0.0, 0.0, 40.0], [0.0, 0.0, 4.0], 6.0),
    (
        "right main bronchus",
        [0.0, 0.0, 4.0],
        [-16.0, 0.0, -6.0],
        4.5,
    ),
    (
        "left main bronchus",
        [0.0, 0.0, 4.0],
        [18.0, 0.0, -10.0],
        4.0,
    ),
    (
        "right upper lobe bronchus",
        [-16.0, 0.0, -6.0],
        [-24.0, 0.0, 4.0],
        3.0,
    ),
    (
        "bronchus intermedius",
        [-16.0, 0.0, -6.0],
        [-20.0, 0.0, -22.0],
        3.5,
    ),
    (
        "right middle lobe bronchus",
        [-20.0, 0.0, -22.0],
        [-22.0, -12.0, -26.0],
        2.5,
    ),
    (
        "right lower lobe bronchus",
        [-20.0, 0.0, -22.0],
        [-22.0, 4.0, -40.0],
        2.5,
    ),
    (
        "left upper lobe bronchus",
        [18.0, 0.0, -10.0],
        [24.0, -4.0, 2.0],
        3.0,
    ),
    (
        "left lower lobe bronchus",
        [18.0, 0.0, -10.0],
        [24.0, 4.0, -26.0],
        3.0,
    ),
];
/// Half the width of the tissue block, mm: air beyond it.
const BODY_HALF_WIDTH_MM: f64 = 29.0;

/// Distance from `p` to segment `a`–`b`.
fn to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    p.distance(a + (b - a) * t)
}

/// The phantom: 64³ voxels of 1 mm, world (0, 0, 0) at its centre; −1000 HU in the tubes and
/// around the block, 40 HU elsewhere.
fn phantom() -> Volume {
    let n = 64;
    let origin = DVec3::splat(-31.5);
    let g = Geometry::axis_aligned([n; 3], DVec3::ONE, origin).unwrap();
    let mut voxels = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = origin + DVec3::new(i as f64, j as f64, k as f64);
                let air = p.x.abs().max(p.y.abs()) > BODY_HALF_WIDTH_MM
                    || SEGMENTS
                        .iter()
                        .any(|&(_, a, b, r)| to_segment(p, DVec3::from(a), DVec3::from(b)) <= r);
                voxels.push(if air { 24 } else { 1064 });
            }
        }
    }
    let map = ValueMap::new(1.0, -1024.0).unwrap();
    Volume::new(g, voxels, map, Modality::Ct).unwrap()
}

/// The phantom and its tree, grown from the trachea's top.
fn tree() -> (Volume, AirwayTree) {
    let volume = phantom();
    let lumen = Lumen::from_seed(&volume, [32, 32, 63], -900.0, LumenSide::Below).unwrap();
    let field = DistanceField::new(&lumen, volume.geometry());
    let tree = AirwayTree::new(&volume, &lumen, &field);
    (volume, tree)
}

#[test]
fn every_branch_of_the_phantom_is_found_and_named() {
    let (_, tree) = tree();
    for (name, a, b, r) in SEGMENTS {
        let branch = tree
            .find(name)
            .unwrap_or_else(|| panic!("no {name} in {tree:#?}"));
        let (a, b) = (DVec3::from(a), DVec3::from(b));
        // Its centreline follows the segment's axis (the first and last few mm bend into the
        // neighbouring branches at the branch points).
        let body = branch
            .points_mm
            .iter()
            .filter(|p| p.distance(a) > r + 2.0 && p.distance(b) > r + 2.0);
        let worst = body.map(|&p| to_segment(p, a, b)).fold(0.0, f64::max);
        assert!(worst <= 1.5, "{name}: {worst} mm off its axis");
        assert!(branch.length_mm() > 0.5 * a.distance(b).min(30.0), "{name}");
    }
    let generations = |name| tree.find(name).map(|b| b.generation);
    assert_eq!(generations("trachea"), Some(0));
    assert_eq!(generations("left main bronchus"), Some(1));
    assert_eq!(generations("right middle lobe bronchus"), Some(2));
    // Nothing else: the wall's voxel steps give no branches.
    assert_eq!(tree.branches().len(), SEGMENTS.len(), "{tree:#?}");
}

#[test]
fn a_thinner_scope_reaches_nearer_to_a_target() {
    let (volume, tree) = tree();
    // Beside the left upper lobe bronchus's far end, in the tissue.
    let target = DVec3::new(25.0, -7.0, 5.0);
    let names = |route: &AirwayRoute| -> Vec<&str> {
        let b = tree.branches();
        route.branches.iter().map(|&i| b[i].name.as_str()).collect()
    };
    let thin = tree.route(&volume, target, 3.0).unwrap();
    assert_eq!(
        names(&thin),
        ["trachea", "left main bronchus", "left upper lobe bronchus"]
    );
    assert!(thin.remaining_mm < 6.0, "{}", thin.remaining_mm);
    assert!(thin.narrowest_mm >= 3.0);
    // A 6.5 mm scope fits the left main bronchus (8 mm less a voxel) but not the upper lobe's
    // (6 mm less a voxel): it stops at the branch point, its mouth at most.
    let thick = tree.route(&volume, target, 6.5).unwrap();
    assert_eq!(names(&thick)[..2], ["trachea", "left main bronchus"]);
    assert!(thick.remaining_mm > thin.remaining_mm + 5.0);
    let mouth = thick.end_mm().distance(DVec3::new(18.0, 0.0, -10.0));
    assert!(
        mouth < 6.0,
        "ends {mouth} mm from the left main bronchus's end"
    );
}

/// How far inside the phantom's airways a point lies: its clearance from the nearest tube's
/// wall, mm (negative outside every tube).
fn clearance_mm(p: DVec3) -> f64 {
    SEGMENTS
        .iter()
        .map(|&(_, a, b, r)| r - to_segment(p, DVec3::from(a), DVec3::from(b)))
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Issue 36 item 7: the route began at the skeleton's root, 5 mm below the scan's top (on the
/// rim of the trachea's section in the chest CT), and jumped up to 6 mm from a branch point to
/// where the branch leaves its parent's lumen, cutting the corner.
#[test]
fn a_route_runs_from_the_tracheas_top_without_gaps() {
    let (volume, tree) = tree();
    let thin = tree
        .route(&volume, DVec3::new(25.0, -7.0, 5.0), 3.0)
        .unwrap();
    // From the middle of the trachea's section in the top slice (z = 31.5), on its axis.
    let start = thin.points_mm[0];
    assert!(
        start.z > 31.0 && start.x.abs() <= 1.0 && start.y.abs() <= 1.0,
        "{start}"
    );
    // Voxel by voxel (26-neighbours of 1 mm voxels), through both branch points.
    let worst = thin
        .points_mm
        .windows(2)
        .map(|w| w[0].distance(w[1]))
        .fold(0.0, f64::max);
    assert!(worst < 1.8, "a step of {worst} mm");
    // Clear of the wall all the way: the left upper lobe bronchus is 3 mm in radius, and the
    // forks' ridges are wider.
    let tightest = thin
        .points_mm
        .iter()
        .map(|&p| (clearance_mm(p), p))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap();
    assert!(tightest.0 >= 1.9, "{tightest:?}");
}

#[test]
fn the_carina_is_the_top_of_the_spur_between_the_main_bronchi() {
    let (_, tree) = tree();
    // The highest point between the main bronchi outside every tube, scanning the phantom's
    // plane y = 0 every 0.01 mm: 5.9 mm below the point (0, 0, 4) where their axes meet.
    let spur = DVec3::new(1.05, 0.0, -1.91);
    let carina = tree.carina_mm().expect("the trachea forks");
    assert!(carina.distance(spur) <= 1.5, "carina {carina}, spur {spur}");
    // The centrelines fork above it, where the lumen's medial axis does.
    let trachea = tree.find("trachea").unwrap();
    assert!(trachea.points_mm[trachea.points_mm.len() - 1].z > carina.z + 2.0);
    // Every fork has its split; no tip has one.
    let branches = tree.branches();
    for (i, branch) in branches.iter().enumerate() {
        let forks = branches.iter().any(|b| b.parent == Some(i));
        assert_eq!(branch.split_mm.is_some(), forks, "{}", branch.name);
    }
}

#[test]
fn bad_targets_and_scopes_are_errors_naming_them() {
    let (volume, tree) = tree();
    let inside = DVec3::new(10.0, 0.0, 0.0);
    let nan = tree.route(&volume, DVec3::new(f64::NAN, 0.0, 0.0), 4.9);
    assert!(nan.unwrap_err().to_string().contains("target"));
    let scope = tree.route(&volume, inside, f64::NAN).unwrap_err();
    assert!(scope.to_string().contains("scope diameter"), "{scope}");
    assert!(tree.route(&volume, inside, -1.0).is_err());
    let far = tree.route(&volume, DVec3::splat(500.0), 4.9).unwrap_err();
    assert!(
        matches!(far, RouteError::Bad(NavError::PointOutside { .. })),
        "{far}"
    );
    let air = tree
        .route(&volume, DVec3::new(31.0, 0.0, 0.0), 4.9)
        .unwrap_err();
    assert!(matches!(air, RouteError::OutsideBody { .. }), "{air}");
    assert!(air.to_string().contains("outside the body"));
    let wide = tree.route(&volume, inside, 20.0).unwrap_err();
    assert!(matches!(wide, RouteError::TooWide { .. }), "{wide}");
}
