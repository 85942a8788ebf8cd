//! Dissection checked against analytic tubes with rings at known arc positions: each ring must
//! lie on one column of the flat image (within 1 mm of arc), and every mapped wall point on the
//! tube's analytic surface (within 0.5 mm).

use super::*;
use crate::phantom::profile::{ramp, AIR_HU, TISSUE_HU};
use crate::phantom::{rasterize, PhantomOptions};
use glam::DVec3;
use std::f64::consts::PI;

/// The air–tissue isovalue of the phantoms' ramps.
const ISO: f64 = 0.5 * (AIR_HU + TISSUE_HU);
/// Radius of the test tubes away from the rings, mm.
const RADIUS_MM: f64 = 8.0;
/// How far a ring reaches into the lumen at its centre, mm, and its half-width along the axis.
const RING_MM: f64 = 2.5;
const RING_HALF_WIDTH_MM: f64 = 3.0;

/// The tube's radius at arc `s` (mm) with rings centred at `rings` (arc, mm): a smooth
/// (cos²) ridge around each.
fn radius_at(s: f64, rings: &[f64]) -> f64 {
    let ridge = |centre: f64| {
        let u = (s - centre) / RING_HALF_WIDTH_MM;
        if u.abs() < 1.0 {
            RING_MM * (0.5 * PI * u).cos().powi(2)
        } else {
            0.0
        }
    };
    RADIUS_MM - rings.iter().map(|&c| ridge(c)).sum::<f64>()
}

/// A tube described by where a world point lies: (arc along the axis, distance from it), mm.
trait Tube: Fn(DVec3) -> (f64, f64) + Sync {}
impl<T: Fn(DVec3) -> (f64, f64) + Sync> Tube for T {}

/// A `size³` phantom (1 mm voxels, centred on the world origin) of air inside `tube`.
fn phantom(size: usize, tube: &impl Tube, rings: &[f64]) -> Volume {
    let centre = DVec3::splat(size as f64 / 2.0 - 0.5);
    let options = PhantomOptions {
        size,
        ..Default::default()
    };
    rasterize([size; 3], &options, &|p: DVec3| {
        let (s, r) = tube(p - centre);
        ramp(r - radius_at(s, rings), AIR_HU, TISSUE_HU)
    })
}

/// Checks the dissection of `volume` along `path` against `tube`: rings on single columns, the
/// map on the wall. `arc_offset` is the tube's arc at the path's start.
fn check(volume: &Volume, path: &Path, tube: &impl Tube, rings: &[f64], arc_offset: f64) {
    let wall = Wall {
        iso: ISO,
        color: [1.0, 0.7, 0.6],
    };
    let flat = dissect(volume, path, &wall, &DissectOptions::default()).unwrap();
    let plot = flat.plot;
    assert_eq!(flat.scale.along_mm_per_px, 0.5);
    assert!(flat.hit_fraction > 0.99, "{}", flat.hit_fraction);
    for y in 0..flat.map.height() {
        for x in 0..flat.map.width() {
            let Some(p) = flat.map.at(x, y) else { continue };
            let (s, r) = tube(p);
            let error = r - radius_at(s, rings);
            assert!(error.abs() < 0.5, "pixel ({x}, {y}) at {p}: {error} mm off");
        }
    }
    for &ring in rings {
        let column = |x: usize| plot.x + x;
        let near: Vec<usize> = (0..plot.columns)
            .filter(|&c| ((c as f64 * 0.5 + arc_offset) - ring).abs() <= 2.0 * RING_HALF_WIDTH_MM)
            .collect();
        for y in plot.y..plot.y + plot.rows {
            let narrowest = near
                .iter()
                .filter_map(|&c| flat.map.at(column(c), y).map(|p| (c, tube(p).1)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            let arc = narrowest.0 as f64 * 0.5 + arc_offset;
            assert!((arc - ring).abs() <= 1.0, "ring {ring} in row {y} at {arc}");
        }
    }
}

#[test]
fn rings_of_a_straight_tube_lie_on_columns_and_the_map_on_its_wall() {
    // Along z through the origin; the arc is z + 24 from the path's start at z = −24.
    let tube = |p: DVec3| (p.z + 24.0, p.truncate().length());
    let rings = [10.0, 24.0, 37.5];
    let volume = phantom(64, &tube, &rings);
    let axis: Vec<DVec3> = (0..=8)
        .map(|n| DVec3::new(0.0, 0.0, -24.0 + 6.0 * f64::from(n)))
        .collect();
    let path = Path::from_points_exact(&axis, 0.5).unwrap();
    check(&volume, &path, &tube, &rings, 0.0);
}

#[test]
fn rings_of_a_curved_tube_lie_on_columns_and_the_map_on_its_wall() {
    // A torus of axis radius 24 mm in the x–z plane; the arc is 24 · angle.
    const AXIS_MM: f64 = 24.0;
    let tube = |p: DVec3| {
        let angle = p.z.atan2(p.x).rem_euclid(2.0 * PI);
        let r = (p.x.hypot(p.z) - AXIS_MM).hypot(p.y);
        (AXIS_MM * angle, r)
    };
    let rings = [30.0, 60.0, 95.0];
    let volume = phantom(72, &tube, &rings);
    let (first, last) = (0.5, 4.5);
    let axis: Vec<DVec3> = (0..=80)
        .map(|n| first + (last - first) * f64::from(n) / 80.0)
        .map(|a: f64| AXIS_MM * DVec3::new(a.cos(), 0.0, a.sin()))
        .collect();
    let path = Path::from_points_exact(&axis, 0.5).unwrap();
    check(&volume, &path, &tube, &rings, AXIS_MM * first);
}

#[test]
fn rays_inside_a_tight_bend_stop_where_the_next_column_cuts_them() {
    // A circle of radius 5 mm: every cutting plane holds the circle's axis, 5 mm from the path.
    let points: Vec<DVec3> = (0..=40)
        .map(|n| 5.0 * DVec3::new((f64::from(n) * 0.1).cos(), 0.0, (f64::from(n) * 0.1).sin()))
        .collect();
    let path = Path::from_points_exact(&points, 0.5).unwrap();
    let columns = rays::columns(&path, 20, 0.5);
    // In open space every fan reaches everywhere: every plane crossed clamps.
    let walls = vec![vec![f64::INFINITY; 36]; columns.len()];
    let reaches = rays::reaches(&columns, 10, 20.0, &walls);
    let column = &columns[10];
    for (row, reach) in reaches.iter().enumerate() {
        let d = rays::direction(column, rays::angle(row, 36));
        let inward = d.dot(-column.origin.normalize());
        if inward > 0.2 {
            assert!(*reach <= 5.0 / inward + 0.05, "row {row}: {reach}");
        } else if inward < -0.01 {
            assert_eq!(*reach, 20.0, "row {row}");
        }
    }
}

/// A `size³` phantom of a straight tube without rings along z through the origin, the path
/// along its axis from `z = −half_mm` to `half_mm`, and its wall.
fn straight_tube(size: usize, half_mm: f64) -> (Volume, Path, Wall) {
    let tube = |p: DVec3| (p.z, p.truncate().length());
    let axis = [-half_mm, half_mm].map(|z| DVec3::new(0.0, 0.0, z));
    let wall = Wall {
        iso: ISO,
        color: [1.0; 3],
    };
    let path = Path::from_points_exact(&axis, 0.5).unwrap();
    (phantom(size, &tube, &[]), path, wall)
}

#[test]
fn bad_options_and_a_path_outside_the_lumen_are_refused_by_name() {
    let (volume, path, wall) = straight_tube(24, 5.0);
    let error = |wall: &Wall, options: DissectOptions| {
        dissect(&volume, &path, wall, &options)
            .unwrap_err()
            .to_string()
    };
    let nan_step = DissectOptions {
        step_mm: f64::NAN,
        ..Default::default()
    };
    assert!(error(&wall, nan_step).contains("step (mm) must be"));
    let no_reach = DissectOptions {
        reach_mm: -1.0,
        ..Default::default()
    };
    assert!(error(&wall, no_reach).contains("reach"));
    let rows = DissectOptions {
        rows: 0,
        ..Default::default()
    };
    assert!(error(&wall, rows).contains("rows"));
    let tiny = DissectOptions {
        step_mm: 1e-9,
        ..Default::default()
    };
    assert!(error(&wall, tiny).contains("larger step"));
    let nan_iso = Wall {
        iso: f64::NAN,
        ..wall
    };
    assert!(error(&nan_iso, DissectOptions::default()).contains("isovalue"));
    let far = [DVec3::new(500.0, 0.0, 0.0), DVec3::new(510.0, 0.0, 0.0)];
    let outside = Path::from_points_exact(&far, 0.5).unwrap();
    let message = dissect(&volume, &outside, &wall, &DissectOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("no ray from the path met the wall"),
        "{message}"
    );
}

#[test]
fn a_flat_pixel_gives_the_camera_on_its_column_looking_at_its_wall_point() {
    let (volume, path, wall) = straight_tube(32, 10.0);
    let flat = dissect(&volume, &path, &wall, &DissectOptions::default()).unwrap();
    let plot = flat.plot;
    let (x, y) = (plot.x + 12, plot.y + 200);
    let pose = flat.pose_of_pixel(&path, x, y).unwrap();
    // Column 12 is 6 mm along the axis from z = −10; the eye looks at the mapped wall point.
    assert!(
        pose.eye_mm.distance(DVec3::new(0.0, 0.0, -4.0)) < 1e-6,
        "{pose:?}"
    );
    assert_eq!(Some(pose.look_at_mm), flat.map.at(x, y));
    assert!((pose.look_at_mm.z + 4.0).abs() < 1e-3, "{pose:?}");
    assert!(pose.up.dot(pose.look_at_mm - pose.eye_mm).abs() < 1e-9);
    assert_eq!(flat.arc_mm_of_column(x, &path), Some(6.0));
    assert_eq!(flat.column_of_arc(6.0), Some(x));
    // The last column is clamped to the path's end; beyond it and in the margins, nothing.
    let last = plot.x + plot.columns - 1;
    let end = flat.arc_mm_of_column(last, &path).unwrap();
    assert!((end - path.len_mm()).abs() < 1e-9, "{end}");
    assert_eq!(flat.column_of_arc(path.len_mm() + 1.0), None);
    assert_eq!(flat.column_of_arc(f64::NAN), None);
    assert_eq!(
        flat.pose_of_pixel(&path, 2, 2),
        Err(PickError::OutsidePlot(2, 2))
    );
    assert_eq!(
        flat.pose_of_pixel(&path, x, plot.y + plot.rows),
        Err(PickError::OutsidePlot(x, plot.y + plot.rows))
    );
}

#[test]
fn a_flat_pixel_whose_ray_met_no_wall_gives_no_camera() {
    let (volume, path, wall) = straight_tube(24, 5.0);
    // A reach shorter than the 8 mm radius: no ray meets the wall…
    let short = DissectOptions {
        reach_mm: 2.0,
        ..Default::default()
    };
    assert!(dissect(&volume, &path, &wall, &short).is_err());
    // …and with the reach to the wall for some rows only, the others are NaN.
    let tilted: Vec<DVec3> = [-5.0, 5.0].map(|z| DVec3::new(3.0, 0.0, z)).to_vec();
    let off_axis = Path::from_points_exact(&tilted, 0.5).unwrap();
    let near = DissectOptions {
        reach_mm: 6.0,
        ..Default::default()
    };
    let flat = dissect(&volume, &off_axis, &wall, &near).unwrap();
    let plot = flat.plot;
    let x = plot.x + 4;
    let empty = (plot.y..plot.y + plot.rows)
        .find(|&y| flat.map.at(x, y).is_none())
        .unwrap();
    assert_eq!(
        flat.pose_of_pixel(&off_axis, x, empty),
        Err(PickError::NoWall(x, empty))
    );
}
