use super::*;
use crate::camera::{Optics, Projection};
use crate::phantom::{self, PhantomOptions};
use crate::pose::{fly_through, Pose};
use crate::render::{Mode, Premultiplied, RenderSettings, Renderer};
use crate::Volume;
use std::sync::Arc;

/// Wall voxels by threshold: not lumen (below `iso_hu` is lumen) and 6-adjacent to lumen.
fn threshold_wall(volume: &Volume, iso_hu: f64) -> impl Fn([usize; 3]) -> bool + Sync + '_ {
    let lumen =
        move |i: usize, j: usize, k: usize| volume.physical(i, j, k).is_some_and(|v| v < iso_hu);
    move |[i, j, k]: [usize; 3]| {
        !lumen(i, j, k)
            && (lumen(i + 1, j, k)
                || lumen(i, j + 1, k)
                || lumen(i, j, k + 1)
                || (i > 0 && lumen(i - 1, j, k))
                || (j > 0 && lumen(i, j - 1, k))
                || (k > 0 && lumen(i, j, k - 1)))
    }
}

fn whole(volume: &Volume) -> [Range<usize>; 3] {
    volume.dims().map(|n| 0..n)
}

fn iso_settings() -> RenderSettings {
    let mut settings = RenderSettings::preset("colonoscopy").unwrap();
    settings.mode = Mode::Iso;
    settings
}

/// Records the frames of `poses` (90° cameras of `size²` pixels) into a fresh coverage.
fn fly(renderer: &Arc<Renderer>, wall: &Coverage, poses: &[Pose], size: usize) -> Coverage {
    fly_with(renderer, wall, poses, &Optics::default(), [size, size])
}

/// Records the frames of `poses` seen through `optics` at `size` pixels into a fresh coverage.
fn fly_with(
    renderer: &Arc<Renderer>,
    wall: &Coverage,
    poses: &[Pose],
    optics: &Optics,
    size: [usize; 2],
) -> Coverage {
    let prepared = renderer.prepare(&iso_settings()).unwrap();
    let mut coverage = wall.clone();
    for p in poses {
        let camera = optics.camera(p.eye_mm, p.look_at_mm, p.up, size).unwrap();
        coverage.record(&camera, &prepared.render(&camera)).unwrap();
    }
    coverage
}

/// The same poses flown the other way: eyes in reverse order, looking back.
fn backwards(poses: &[Pose]) -> Vec<Pose> {
    poses
        .iter()
        .rev()
        .map(|p| Pose {
            look_at_mm: p.eye_mm * 2.0 - p.look_at_mm,
            ..*p
        })
        .collect()
}

#[test]
fn a_straight_flight_sees_the_tube_ahead_of_its_first_frame() {
    let (volume, tube) = phantom::straight_tube(&PhantomOptions {
        size: 64,
        ..Default::default()
    });
    let wall = Coverage::new(
        volume.geometry(),
        threshold_wall(&volume, -500.0),
        &whole(&volume),
    )
    .unwrap();
    let g = *volume.geometry();
    let axis = tube.centreline.points()[0];
    let (first, last) = (4.0, 58.0);
    let forward: Vec<Pose> = (0..28)
        .map(|n| {
            let z = first + (last - first) * f64::from(n) / 27.0;
            Pose {
                eye_mm: g.world_of(axis + DVec3::Z * z),
                look_at_mm: g.world_of(axis + DVec3::Z * (z + 1.0)),
                up: DVec3::Y,
            }
        })
        .collect();
    let renderer = Arc::new(Renderer::new(volume));
    let ahead = fly(&renderer, &wall, &forward, 96);
    // The first frame shows the wall from z₀ + R·m(φ) on, where m(φ) = max(|cos φ|, |sin φ|)
    // is where a square 90° image's edge cuts the wall at azimuth φ (mean 0.9003); later frames
    // only see what lies ahead of it. The cell-corner rule reaches one slice further back.
    let slices = 64.0;
    let boundary = first + 0.9003 * tube.radius_vox - 1.0;
    let predicted = (slices - boundary) / slices;
    let f = ahead.seen_fraction();
    assert!(
        (f - predicted).abs() < 0.04,
        "forward {f}, predicted {predicted}"
    );
    // Every wall voxel well behind the boundary is unseen, nearly every one well ahead seen.
    let mask = ahead.mask();
    let [nx, ny, _] = g.dims();
    let (mut behind, mut beyond) = ([0usize; 2], [0usize; 2]);
    for (n, label) in mask.iter().enumerate().filter(|(_, l)| **l != MASK_NONE) {
        let k = (n / (nx * ny)) as f64;
        let seen = usize::from(*label == MASK_SEEN);
        if k < boundary - 4.0 {
            behind[seen] += 1;
        } else if k > boundary + 4.0 {
            beyond[seen] += 1;
        }
    }
    assert_eq!(behind[1], 0);
    assert!(
        beyond[1] as f64 > 0.99 * (beyond[0] + beyond[1]) as f64,
        "{beyond:?}"
    );
    assert_eq!(
        mask.iter().filter(|l| **l != MASK_NONE).count(),
        ahead.total()
    );

    let mut both = fly(&renderer, &wall, &backwards(&forward), 96);
    let back = both.seen_fraction();
    both.merge(&ahead).unwrap();
    assert!(
        (back - f).abs() < 0.03,
        "the tube is symmetric: {back} vs {f}"
    );
    assert!(both.seen_fraction() > 0.99, "{}", both.seen_fraction());
    assert!(both.seen_count() >= ahead.seen_count());
}

#[test]
fn unseen_wall_is_tinted_in_an_overview() {
    let (volume, tube) = phantom::straight_tube(&PhantomOptions {
        size: 48,
        ..Default::default()
    });
    let g = *volume.geometry();
    let wall = Coverage::new(&g, threshold_wall(&volume, -500.0), &whole(&volume)).unwrap();
    let axis = tube.centreline.points()[0];
    let renderer = Arc::new(Renderer::new(volume));
    let mut coverage = wall.clone();
    // Mark by hand everything at k ≥ 24: the wall surface points of that half.
    for k in 24..48 {
        for a in 0..720 {
            let phi = f64::from(a).to_radians() / 2.0;
            let p = axis + DVec3::new(phi.cos(), phi.sin(), 0.0) * tube.radius_vox;
            coverage.mark_point(g.world_of(p + DVec3::Z * f64::from(k)));
        }
    }
    // From the patient's left, outside the volume, looking at the tube's side.
    let centre = g.world_of(axis + DVec3::Z * 24.0);
    let view = Camera::look_at(centre + DVec3::X * 80.0, centre, DVec3::Z, 50.0, [64, 64]).unwrap();
    let frame = renderer.prepare(&iso_settings()).unwrap().render(&view);
    let mut image = Image::from_frame(&frame, iso_settings().background).unwrap();
    let red = [255, 0, 0];
    let tinted = coverage
        .tint_unseen(&mut image, &view, &frame.depth_mm, red, 1.0)
        .unwrap();
    assert!(tinted > 100);
    for (n, depth) in frame
        .depth_mm
        .iter()
        .enumerate()
        .filter(|(_, d)| d.is_finite())
    {
        let (x, y) = (n % 64, n / 64);
        let hit = view.point_at(x, y, f64::from(*depth)).unwrap();
        let k = g.voxel_from_world().transform_point3(hit).z;
        let is_red = image.pixel(x, y) == Some(red);
        if k < 21.0 {
            assert!(is_red, "unseen half at k = {k} not tinted");
        } else if k > 25.0 {
            assert!(!is_red, "seen half at k = {k} tinted");
        }
    }
    let short = vec![0.0; 3];
    assert!(coverage
        .tint_unseen(&mut image, &view, &short, red, 1.0)
        .is_err());
}

/// Fractions of the fold faces seen: (faces looking back at the rectum, faces looking on to
/// the caecum). A face looks where the surface normal into the lumen points along the colon.
fn fold_faces(volume: &Volume, colon: &phantom::Colon, coverage: &Coverage) -> (f64, f64) {
    let mut counts = [[0usize; 2]; 2];
    let [nx, ny, nz] = volume.dims();
    let value = |i: usize, j: usize, k: usize| volume.physical(i, j, k).unwrap_or(0.0);
    for k in 1..nz - 1 {
        for j in 1..ny - 1 {
            for i in 1..nx - 1 {
                let Some(seen) = coverage.state([i, j, k]) else {
                    continue;
                };
                let p = DVec3::new(i as f64, j as f64, k as f64);
                // The values rise into tissue: the normal into the lumen is minus the gradient.
                let gradient = DVec3::new(
                    value(i + 1, j, k) - value(i - 1, j, k),
                    value(i, j + 1, k) - value(i, j - 1, k),
                    value(i, j, k + 1) - value(i, j, k - 1),
                );
                let into_lumen = -gradient.normalize_or_zero();
                for fold in &colon.folds {
                    let along = (p - fold.centre_vox).dot(fold.axis);
                    let radial = (p - fold.centre_vox - fold.axis * along).length();
                    let on_fold = along.abs() < fold.depth_vox + 1.5
                        && radial < fold.ring_radius_vox - 0.5
                        && radial > fold.ring_radius_vox - fold.depth_vox - 1.5;
                    let facing = into_lumen.dot(fold.axis);
                    if on_fold && facing.abs() > 0.5 {
                        counts[usize::from(facing > 0.0)][usize::from(seen)] += 1;
                    }
                }
            }
        }
    }
    let fraction = |c: [usize; 2]| c[1] as f64 / (c[0] + c[1]).max(1) as f64;
    eprintln!("fold faces [looking back, looking on] × [unseen, seen]: {counts:?}");
    assert!(counts.iter().all(|c| c[0] + c[1] > 50), "{counts:?}");
    (fraction(counts[0]), fraction(counts[1]))
}

/// The 192³ colon phantom's renderer, the phantom, its wall (nothing seen yet) and the 48
/// poses of a forward flight along its centreline.
fn colon_flight() -> (Arc<Renderer>, phantom::Colon, Coverage, Vec<Pose>) {
    let (volume, colon) = phantom::colon(&PhantomOptions {
        size: 192,
        ..Default::default()
    });
    let line = &colon.centreline;
    let g = *volume.geometry();
    let wall = Coverage::new(&g, threshold_wall(&volume, -500.0), &whole(&volume)).unwrap();
    let forward = fly_through(&g, |s| line.point_at(s), line.length_vox(), 48, 6.0).unwrap();
    (Arc::new(Renderer::new(volume)), colon, wall, forward)
}

#[test]
fn a_forward_flight_misses_the_far_sides_of_the_folds() {
    let (renderer, colon, wall, forward) = colon_flight();
    let ahead = fly(&renderer, &wall, &forward, 96);
    let back = fly(&renderer, &wall, &backwards(&forward), 96);
    let mut both = ahead.clone();
    both.merge(&back).unwrap();
    let (f, b, fb) = (
        ahead.seen_fraction(),
        back.seen_fraction(),
        both.seen_fraction(),
    );
    eprintln!("colon coverage: forward {f:.3}, backward {b:.3}, both {fb:.3}");
    assert!(f < fb - 0.03 && b < fb - 0.03, "{f} {b} {fb}");
    // One way misses several per cent (Vos et al. measured 94 % in patients); both ways nearly
    // nothing on this phantom, whose folds are gentle ridges.
    assert!(f < 0.97 && b < 0.97 && f > 0.5 && b > 0.5);
    // Flying forward (rectum → caecum), the faces of the folds looking on to the caecum turn
    // their back to the camera; flying back, the other faces do.
    let volume = renderer.volume();
    let (toward_start, toward_end) = fold_faces(volume, &colon, &ahead);
    eprintln!("forward: fold faces looking back {toward_start:.3}, looking on {toward_end:.3}");
    assert!(toward_end < toward_start - 0.2);
    let (toward_start, toward_end) = fold_faces(volume, &colon, &back);
    eprintln!("backward: fold faces looking back {toward_start:.3}, looking on {toward_end:.3}");
    assert!(toward_start < toward_end - 0.2);
}

#[test]
fn a_one_way_cube_flight_sees_nearly_all_the_colon_wall() {
    let (renderer, colon, wall, forward) = colon_flight();
    // Faces of 64 pixels: the pinhole's rays are exactly the cube's front face's.
    let pinhole = fly(&renderer, &wall, &forward, 64);
    let optics = Optics {
        projection: Projection::Cube,
        ..Optics::default()
    };
    let cube = fly_with(&renderer, &wall, &forward, &optics, [256, 192]);
    let (p, c) = (pinhole.seen_fraction(), cube.seen_fraction());
    eprintln!("colon coverage one way: pinhole {p:.4}, unfolded cube {c:.4}");
    // Vos et al. measured 99.5 % with the cube; the issue asks for 98 %.
    assert!(c >= 0.98, "the cube saw {c}");
    assert!(c > p + 0.05, "cube {c}, pinhole {p}");
    let mut both = cube.clone();
    both.merge(&pinhole).unwrap();
    assert_eq!(
        both.seen_count(),
        cube.seen_count(),
        "the front face is the pinhole's view"
    );
    // The fold faces looking on to the caecum, turned away from a forward camera, are in the
    // cube's back face.
    let (toward_start, toward_end) = fold_faces(renderer.volume(), &colon, &cube);
    eprintln!("cube: fold faces looking back {toward_start:.3}, looking on {toward_end:.3}");
    assert!(toward_start > 0.95 && toward_end > 0.95);
}

#[test]
fn rejects_bad_input() {
    let (volume, _) = phantom::straight_tube(&PhantomOptions {
        size: 16,
        ..Default::default()
    });
    let g = volume.geometry();
    let wall = threshold_wall(&volume, -500.0);
    assert!(matches!(
        Coverage::new(g, &wall, &[0..16, 0..16, 0..17]),
        Err(CoverageError::BadBox { .. })
    ));
    assert!(Coverage::new(g, &wall, &[3..3, 0..16, 0..16]).is_err());
    assert_eq!(
        Coverage::new(g, |_| false, &whole(&volume)),
        Err(CoverageError::NoWall)
    );
    let mut full = Coverage::new(g, &wall, &whole(&volume)).unwrap();
    let part = Coverage::new(g, &wall, &[0..16, 0..16, 0..8]).unwrap();
    assert_eq!(full.merge(&part), Err(CoverageError::DifferentWall));
    assert_eq!(full.mark_point(DVec3::NAN), 0);
    assert_eq!(full.mark_point(DVec3::splat(1e300)), 0);
    let camera = Camera::look_at(DVec3::ZERO, DVec3::Z, DVec3::Y, 90.0, [4, 4]).unwrap();
    let frame = Frame {
        width: 4,
        height: 3,
        color: vec![Premultiplied::default(); 12],
        depth_mm: vec![1.0; 12],
        value: vec![0.0; 12],
        ..Frame::default()
    };
    assert!(full.record(&camera, &frame).is_err());
    assert_eq!(full.seen_count(), 0);
}

#[test]
fn the_mask_volume_labels_seen_and_unseen_wall_on_the_scan_grid() {
    let (volume, _) = phantom::straight_tube(&PhantomOptions {
        size: 16,
        ..Default::default()
    });
    let g = *volume.geometry();
    let mut coverage = Coverage::new(&g, threshold_wall(&volume, -500.0), &whole(&volume)).unwrap();
    let first_wall = (0..16 * 16 * 16)
        .map(|n| [n % 16, n / 16 % 16, n / 256])
        .find(|&v| coverage.state(v).is_some())
        .unwrap();
    let p = DVec3::new(
        first_wall[0] as f64,
        first_wall[1] as f64,
        first_wall[2] as f64,
    );
    assert!(coverage.mark_point(g.world_of(p)) > 0);
    let mask = coverage.mask_volume().unwrap();
    assert_eq!(mask.geometry(), &g);
    assert_eq!(mask.dims(), g.dims());
    let labels = coverage.mask();
    for (stored, label) in mask.voxels().iter().zip(&labels) {
        assert_eq!(*stored, u16::from(*label));
        assert_eq!(mask.value_map().physical(*stored), f64::from(*label));
    }
    let count = |label: u8| labels.iter().filter(|&&l| l == label).count();
    assert_eq!(count(MASK_SEEN), coverage.seen_count());
    let cleared = coverage.cleared();
    assert_eq!(
        (cleared.seen_count(), cleared.total()),
        (0, coverage.total())
    );
    assert!(cleared.mask().iter().all(|&l| l != MASK_SEEN));
    let mut again = cleared.clone();
    again.merge(&coverage).unwrap();
    assert_eq!(again, coverage);
    assert!(count(MASK_SEEN) > 0);
    assert_eq!(count(MASK_SEEN) + count(MASK_UNSEEN), coverage.total());
}
