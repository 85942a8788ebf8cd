use super::*;
use crate::phantom::{colon, colon_prone, PhantomOptions};
use crate::presets::Preset;
use crate::study::StudyRequest;
use std::f64::consts::PI;

/// A winding test curve (mm): a stretched helix climbing along z, turning at varying rates.
fn winding(n: usize) -> Vec<DVec3> {
    (0..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let angle = 3.0 * PI * t * t;
            DVec3::new(60.0 * angle.cos(), 40.0 * angle.sin(), 150.0 * t)
        })
        .collect()
}

fn path(points: &[DVec3]) -> Path {
    Path::smooth(points, &SmoothOptions::default()).unwrap()
}

#[test]
fn a_path_matches_itself_reversed_and_turned_over() {
    let points = winding(400);
    let a = path(&points);
    let same = Correspondence::between(&a, &a).unwrap();
    assert!(same.turn_deg().abs() < 1.0 && !same.reversed());
    let length = a.len_mm();
    for s in [0.0, 0.3 * length, 0.7 * length, length] {
        assert!((same.arc_in_second(s) - s).abs() < 1.0, "{s}");
    }
    // The same path turned over (180° about z) and planned from its other end.
    let turned: Vec<DVec3> = points
        .iter()
        .rev()
        .map(|p| DVec3::new(-p.x, -p.y, p.z))
        .collect();
    let b = path(&turned);
    let over = Correspondence::between(&a, &b).unwrap();
    assert!(over.reversed());
    assert!(
        (over.turn_deg().abs() - 180.0).abs() < 1.0,
        "{}",
        over.turn_deg()
    );
    let x = a.point_at(0.4 * length) + DVec3::new(0.0, 0.0, 5.0);
    let found = over.counterpart(x).unwrap();
    assert!(
        (found.arc_mm - (b.len_mm() - 0.4 * length)).abs() < 2.0,
        "{found:?}"
    );
    let truth = DVec3::new(-x.x, -x.y, x.z);
    assert!(found.point_mm.distance(truth) < 1.5, "{found:?}");
    assert!(found.view.look_at_mm.distance(truth) < 1.5);
    assert!(
        found
            .view
            .up
            .dot(found.view.look_at_mm - found.view.eye_mm)
            .abs()
            < 1e-9
    );
}

#[test]
fn bad_input_is_refused() {
    let a = path(&winding(400));
    let short = path(&[DVec3::ZERO, DVec3::X * 4.0]);
    assert!(matches!(
        Correspondence::between(&a, &short),
        Err(MatchError::TooShort {
            which: "second",
            ..
        })
    ));
    let matched = Correspondence::between(&a, &a).unwrap();
    let error = matched.counterpart(DVec3::new(f64::NAN, 0.0, 0.0));
    assert!(matches!(error, Err(MatchError::BadPoint(_))));
    let pose = Pose {
        eye_mm: DVec3::ZERO,
        look_at_mm: DVec3::new(0.0, f64::INFINITY, 0.0),
        up: DVec3::Z,
    };
    assert!(matches!(
        matched.follow(&pose),
        Err(MatchError::BadPoint(_))
    ));
}

/// The acceptance test of issue 36: on the supine/prone phantom pair, points along the colon
/// (on its axis and on its wall, at the ends, between them and at the flexures) map to their
/// prone counterparts within 10 mm along the colon.
#[test]
fn supine_points_find_their_prone_counterparts_within_10_mm() {
    let options = PhantomOptions {
        size: 192,
        ..Default::default()
    };
    let (supine, _) = colon(&options);
    let (prone, pair) = colon_prone(&options);
    let request = StudyRequest::preset(Preset::find("colonoscopy").unwrap());
    let study_supine = Study::resolve(&supine, &request);
    let study_prone = Study::resolve(&prone, &request);
    let matched =
        Correspondence::of_studies((&supine, &study_supine), (&prone, &study_prone)).unwrap();
    assert!(
        (matched.turn_deg().abs() - 180.0).abs() < 10.0,
        "{}",
        matched.turn_deg()
    );
    let centre = |dims: [usize; 3]| DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64);
    let half = (centre(supine.dims()) - 1.0) / 2.0;
    let line = &pair.supine.centreline;
    let mut arcs: Vec<f64> = (1..10)
        .map(|n| 0.1 * f64::from(n) * line.length_vox())
        .collect();
    arcs.extend(flexures(line));
    let mut worst = 0.0f64;
    for (n, &s) in arcs.iter().enumerate() {
        // On the axis and halfway to the wall, at an angle that changes from point to point.
        let axis = line.point_at(s);
        let out = line.tangent_at(s).any_orthonormal_vector();
        let out = DQuat::from_axis_angle(line.tangent_at(s), n as f64) * out;
        for x_vox in [axis, axis + out * (0.5 * pair.supine.radius_vox_at(s))] {
            let found = matched.counterpart(x_vox - half).unwrap();
            let truth = pair.prone_arc_vox(pair.supine.centreline.closest(x_vox).0);
            let (at, _) = pair.prone.centreline.closest(found.point_mm + half);
            let (eye, _) = pair.prone.centreline.closest(found.view.eye_mm + half);
            worst = worst.max((at - truth).abs()).max((eye - truth).abs());
            let expected = pair.prone_point(x_vox) - half;
            assert!(
                found.point_mm.distance(expected) < 10.0,
                "s = {s}: {found:?}, expected {expected}"
            );
        }
        // The side-by-side views: a camera on the axis looking along the colon, carried to
        // the prone scan, stands at the counterpart and looks along the prone colon.
        let eye = axis - half;
        let along = line.tangent_at(s);
        let pose = Pose {
            eye_mm: eye,
            look_at_mm: eye + along * 10.0,
            up: along.any_orthonormal_vector(),
        };
        let followed = matched.follow(&pose).unwrap();
        let truth = pair.prone_arc_vox(s);
        let (at, _) = pair.prone.centreline.closest(followed.eye_mm + half);
        worst = worst.max((at - truth).abs());
        let forward = (followed.look_at_mm - followed.eye_mm) / 10.0;
        let prone_along = pair.prone.centreline.tangent_at(truth);
        assert!(
            forward.dot(prone_along) > 0.9,
            "s = {s}: {forward} vs {prone_along}"
        );
        assert!(followed.up.dot(forward).abs() < 1e-9);
    }
    assert!(worst < 10.0, "worst error along the colon {worst} mm");
}

/// Arc lengths of the centreline's highest points between two lower ones (the splenic and
/// hepatic flexures, the top of the sigmoid loop), voxels.
fn flexures(line: &crate::phantom::Centreline) -> Vec<f64> {
    let (points, arcs) = (line.points(), line.arc_vox());
    let window = 20;
    (window..points.len() - window)
        .filter(|&n| (n - window..=n + window).all(|m| points[m].z <= points[n].z))
        .map(|n| arcs[n])
        .collect()
}
