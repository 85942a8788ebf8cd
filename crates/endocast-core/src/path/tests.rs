use super::*;
use glam::{DMat3, DQuat};

/// The tangential component (rad) of the rotation taking frame `a` to frame `b`: zero for a
/// rotation-minimising frame, up to rounding and discretisation.
fn twist(a: &PathSample, b: &PathSample) -> f64 {
    let frame = |s: &PathSample| DMat3::from_cols(s.tangent, s.up, s.tangent.cross(s.up));
    let rotation = DQuat::from_mat3(&(frame(b) * frame(a).transpose()));
    let (axis, angle) = rotation.to_axis_angle();
    angle * axis.dot((a.tangent + b.tangent).normalize())
}

/// Consecutive frames are orthonormal, turn by less than `max_deg`, the up vector no more than
/// the tangent (the least a frame must turn), and do not twist.
fn check_frames(path: &Path, max_deg: f64) -> f64 {
    let mut total_twist = 0.0;
    for pair in path.samples().windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        assert!((a.tangent.length() - 1.0).abs() < 1e-9);
        assert!((a.up.length() - 1.0).abs() < 1e-9);
        assert!(a.up.dot(a.tangent).abs() < 1e-9);
        let angle = |x: DVec3, y: DVec3| x.dot(y).clamp(-1.0, 1.0).acos().to_degrees();
        let (turn, bend) = (angle(a.up, b.up), angle(a.tangent, b.tangent));
        assert!(
            bend < max_deg,
            "tangent turned by {bend}° at {} mm",
            a.arc_mm
        );
        assert!(
            turn < bend + 0.05,
            "up turned by {turn}° at {} mm",
            a.arc_mm
        );
        let t = twist(a, b);
        assert!(t.abs() < 1e-3, "twist {t} rad at {} mm", a.arc_mm);
        total_twist += t;
    }
    total_twist
}

/// A tiny deterministic generator (no rand dependency): uniform in [0, 1).
fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// Voxel centres (1 mm voxels) along a curve: the staircase a centreline search returns.
fn staircase(curve: impl Fn(f64) -> DVec3, length: f64) -> Vec<DVec3> {
    let mut out: Vec<DVec3> = Vec::new();
    let mut s = 0.0;
    while s <= length {
        let p = curve(s).round();
        if out.last() != Some(&p) {
            out.push(p);
        }
        s += 0.05;
    }
    out
}

fn helix(s: f64) -> DVec3 {
    // Radius 8 mm, rising 10 mm per turn; s is roughly arc length.
    let t = s / (64.0 + (10.0 / std::f64::consts::TAU).powi(2)).sqrt();
    DVec3::new(
        8.0 * t.cos(),
        8.0 * t.sin(),
        10.0 * t / std::f64::consts::TAU,
    )
}

#[test]
fn a_path_too_long_for_f64_is_an_error() {
    let points = [DVec3::ZERO, DVec3::new(1e308, 0.0, 0.0), DVec3::X];
    assert_eq!(
        Path::from_points_exact(&points, 1.0).err(),
        Some(PathError::TooLong)
    );
}

#[test]
fn passes_through_its_control_points() {
    let raw = staircase(helix, 60.0);
    let path = Path::smooth(&raw, &SmoothOptions::default()).unwrap();
    assert!(path.control_points().len() > 5);
    for (i, c) in path.control_points().iter().enumerate() {
        let s = path.table.arc_at_point_mm(i);
        assert!(path.point_at(s).distance(*c) < 1e-6, "control point {i}");
    }
    assert_eq!(path.samples()[0].position_mm, raw[0]);
    let end = path.samples().last().unwrap().position_mm;
    assert!(end.distance(*raw.last().unwrap()) < 1e-6);
    // Exact paths pass through every given point.
    let points = [
        DVec3::ZERO,
        DVec3::new(3.0, 1.0, 0.0),
        DVec3::new(4.0, 5.0, 2.0),
    ];
    let exact = Path::from_points_exact(&points, 0.25).unwrap();
    for (i, p) in points.iter().enumerate() {
        assert!(exact.point_at(exact.table.arc_at_point_mm(i)).distance(*p) < 1e-6);
    }
}

#[test]
fn samples_are_a_constant_step_apart() {
    let mut seed = 7;
    let (a, b, c) = (
        lcg(&mut seed) * 6.0,
        lcg(&mut seed) * 6.0,
        lcg(&mut seed) * 3.0,
    );
    let wiggle = move |s: f64| {
        DVec3::new(
            s,
            a * (s / 6.0).sin(),
            b * (s / 9.0).cos() + c * (s / 4.0).sin(),
        )
    };
    for step in [0.3, 0.5, 1.0] {
        let options = SmoothOptions {
            step_mm: step,
            ..Default::default()
        };
        let path = Path::smooth(&staircase(wiggle, 80.0), &options).unwrap();
        let samples = path.samples();
        for pair in samples[..samples.len() - 1].windows(2) {
            assert!((pair[1].arc_mm - pair[0].arc_mm - step).abs() < 1e-9);
            let chord = pair[0].position_mm.distance(pair[1].position_mm);
            assert!(
                (chord / step - 1.0).abs() < 0.01,
                "step {chord} instead of {step}"
            );
        }
        let last = samples.len() - 1;
        assert!(samples[last].arc_mm - samples[last - 1].arc_mm <= step + 1e-9);
        // The tabulated length agrees with a much finer polyline through the spline.
        let n = 200_000;
        let segs = path.spline.segments() as f64;
        let fine: f64 = (0..n)
            .map(|k| {
                let u = |k: usize| k as f64 / n as f64 * segs;
                path.spline
                    .point(u(k))
                    .distance(path.spline.point(u(k + 1)))
            })
            .sum();
        assert!(
            (fine - path.len_mm()).abs() < 1e-3 * step,
            "{fine} vs {}",
            path.len_mm()
        );
    }
}

#[test]
fn frames_on_a_helix_turn_smoothly_without_twist() {
    let options = SmoothOptions {
        control_spacing_mm: 3.0,
        ..Default::default()
    };
    let path = Path::smooth(&staircase(helix, 150.0), &options).unwrap();
    // The helix itself turns by 3.4° per 0.5 mm step; the voxel staircase adds a little.
    let total = check_frames(&path, 8.0);
    // The Frenet frame would twist by the torsion (0.024 rad/mm) times the length: 3.6 rad.
    assert!(total.abs() < 0.05, "total twist {total} rad");
    // The smoothed path follows the helix within a voxel despite the staircase.
    for s in path.samples() {
        let r = s.position_mm.truncate().length();
        assert!((r - 8.0).abs() < 0.75, "radius {r} at {} mm", s.arc_mm);
    }
}

#[test]
fn frames_on_random_wiggly_curves_stay_orthonormal() {
    let mut seed = 42;
    for _ in 0..3 {
        let amp: Vec<f64> = (0..6).map(|_| lcg(&mut seed) * 6.0).collect();
        let phase: Vec<f64> = (0..6).map(|_| lcg(&mut seed) * 6.0).collect();
        let curve = |s: f64| {
            DVec3::new(
                s + amp[0] * (s / 9.0 + phase[0]).sin(),
                amp[1] * (s / 10.0 + phase[1]).sin() + amp[2] * (s / 17.0 + phase[2]).cos(),
                amp[3] * (s / 12.0 + phase[3]).sin() + amp[4] * (s / 15.0 + phase[4]).cos(),
            )
        };
        let path = Path::smooth(&staircase(curve, 100.0), &SmoothOptions::default()).unwrap();
        check_frames(&path, 8.0);
    }
}

#[test]
fn a_straight_line_keeps_its_up_vector() {
    let raw = staircase(|s| DVec3::new(s, 0.5 * s, 0.0), 40.0);
    let options = SmoothOptions {
        initial_up: Some(DVec3::Z),
        ..Default::default()
    };
    let path = Path::smooth(&raw, &options).unwrap();
    for s in path.samples() {
        assert!(s.up.distance(DVec3::Z) < 1e-6, "{:?}", s);
    }
    let pose = path.pose_at(10.0, 5.0).unwrap();
    assert!(pose.up.distance(DVec3::Z) < 1e-6);
}

#[test]
fn poses_look_ahead_and_stop_at_the_end() {
    let points = [
        DVec3::ZERO,
        DVec3::new(10.0, 0.0, 0.0),
        DVec3::new(10.0, 10.0, 0.0),
    ];
    let path = Path::from_points_exact(&points, 0.5).unwrap();
    let len = path.len_mm();
    let pose = path.pose_at(2.0, 3.0).unwrap();
    assert!(pose.look_at_mm.distance(path.point_at(5.0)) < 1e-9);
    // At the end the look-ahead collapses: the camera looks along the final tangent.
    let end = path.pose_at(len + 5.0, 3.0).unwrap();
    assert!(end.eye_mm.distance(points[2]) < 1e-6);
    let forward = (end.look_at_mm - end.eye_mm).normalize();
    assert!(forward.dot(path.samples().last().unwrap().tangent) > 0.999);
    let poses: Vec<Pose> = path.poses(1.0, 2.0).unwrap().collect();
    assert_eq!(poses.len(), len.ceil() as usize + 1);
    for p in &poses {
        let f = (p.look_at_mm - p.eye_mm).normalize();
        assert!(p.up.dot(f).abs() < 1e-9 && (p.up.length() - 1.0).abs() < 1e-9);
    }
    for pair in poses.windows(2) {
        assert!(pair[0].up.dot(pair[1].up) > 0.9);
    }
}

#[test]
fn degenerate_inputs_are_errors() {
    let o = SmoothOptions::default();
    let p = DVec3::new(1.0, 2.0, 3.0);
    assert_eq!(Path::smooth(&[], &o), Err(PathError::TooFewPoints(0)));
    assert_eq!(Path::smooth(&[p], &o), Err(PathError::TooFewPoints(1)));
    assert_eq!(
        Path::smooth(&[p, p, p], &o),
        Err(PathError::TooFewPoints(1))
    );
    let nan = DVec3::new(0.0, f64::NAN, 0.0);
    assert!(matches!(
        Path::smooth(&[p, nan], &o),
        Err(PathError::NotFinite { index: 1, .. })
    ));
    assert!(Path::from_points_exact(&[p, DVec3::INFINITY], 1.0).is_err());
    for step in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(Path::from_points_exact(&[p, DVec3::ZERO], step).is_err());
        let bad = SmoothOptions {
            control_spacing_mm: step,
            ..o
        };
        assert!(Path::smooth(&[p, DVec3::ZERO], &bad).is_err());
    }
    // A step in metres instead of millimetres is refused, not allocated.
    let far = DVec3::new(1e6, 0.0, 0.0);
    assert!(matches!(
        Path::from_points_exact(&[DVec3::ZERO, far], 1e-3),
        Err(PathError::TooManySamples { .. })
    ));
    // Duplicates between distinct points are harmless.
    let path = Path::smooth(&[p, p, DVec3::ZERO, DVec3::ZERO], &o).unwrap();
    assert!((path.len_mm() - p.length()).abs() < 1e-6);
    assert!(path.pose_at(f64::NAN, 1.0).is_err());
    assert!(path.pose_at(1.0, -1.0).is_err());
    assert!(path.poses(0.0, 1.0).is_err());
}

#[test]
fn smooth_until_tightens_the_control_spacing() {
    let raw = staircase(helix, 60.0);
    let o = SmoothOptions {
        control_spacing_mm: 8.0,
        ..Default::default()
    };
    let path = Path::smooth_until(&raw, &o, |p| p.options().control_spacing_mm <= 2.0).unwrap();
    assert_eq!(path.options().control_spacing_mm, 2.0);
    let finest = Path::smooth_until(&raw, &o, |p| p.control_points().len() == raw.len()).unwrap();
    assert_eq!(finest.control_points(), &raw[..]);
    assert_eq!(
        Path::smooth_until(&raw, &o, |_| false),
        Err(PathError::NotAccepted)
    );
    let finer = path.resmoothed(1.0).unwrap();
    assert!(finer.control_points().len() > path.control_points().len());
}

#[test]
fn points_every_step_end_at_the_last_point() {
    let raw: Vec<DVec3> = (0..=20)
        .map(|i| DVec3::new(f64::from(i), 0.0, 0.0))
        .collect();
    let path = Path::smooth(&raw, &SmoothOptions::default()).unwrap();
    let points = path.points_every(3.0).unwrap();
    assert_eq!(points.len(), 8, "0, 3, ..., 18 and the end at 20");
    for pair in points[..7].windows(2) {
        assert!((pair[0].distance(pair[1]) - 3.0).abs() < 1e-6);
    }
    assert!(points[7].distance(DVec3::new(20.0, 0.0, 0.0)) < 1e-9);
    assert!(path.points_every(0.0).is_err() && path.points_every(f64::NAN).is_err());
    assert!(path.points_every(1e-12).is_err());
}
