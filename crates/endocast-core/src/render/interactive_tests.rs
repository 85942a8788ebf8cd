//! Tests of what an interactive front end needs (issue 16): float layers, maximum distances,
//! an owned renderer, cancellation and progress, quality levels, stills and the progressive
//! driver.

use super::progressive::{progressive, ProgressiveOptions, Stage};
use super::Filter;
use super::*;
use crate::phantom::{self, PhantomOptions, SphereShell};
use glam::DVec3;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;

/// The sphere shell phantom (1 mm voxels) and its truth.
fn shell(size: usize) -> (Arc<Renderer>, SphereShell) {
    let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
        size,
        ..PhantomOptions::default()
    });
    (Arc::new(Renderer::new(volume)), shell)
}

fn iso() -> RenderSettings {
    RenderSettings {
        mode: Mode::Iso,
        iso_hu: -480.0,
        ..RenderSettings::default()
    }
}

/// A camera at the shell's centre (plus `offset_vox`) looking along +z.
fn camera_in(renderer: &Renderer, shell: &SphereShell, offset_vox: DVec3, size: usize) -> Camera {
    let eye = renderer
        .volume()
        .geometry()
        .world_of(shell.centre_vox + offset_vox);
    let forward = DVec3::new(0.2, -0.1, 1.0);
    Camera::look_at(eye, eye + forward, DVec3::Y, 90.0, [size, size]).unwrap()
}

/// The frames' colours, depths and values as bits (`f32` equality would let −0 = 0 pass).
fn bits(frame: &Frame) -> Vec<[u32; 6]> {
    (0..frame.len())
        .map(|i| {
            let c = frame.color[i];
            let [r, g, b] = c.rgb.map(f32::to_bits);
            let (t, d, v) = (c.transmittance, frame.depth_mm[i], frame.value[i]);
            [r, g, b, t.to_bits(), d.to_bits(), v.to_bits()]
        })
        .collect()
}

fn assert_same_frame(a: &Frame, b: &Frame, what: &str) {
    assert_eq!([a.width, a.height], [b.width, b.height], "{what}: sizes");
    let (a, b) = (bits(a), bits(b));
    if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
        panic!("{what}: pixel {i} differs: {:?} vs {:?}", a[i], b[i]);
    }
}

#[test]
fn prepared_is_owned_shareable_and_updates_in_place() {
    fn send_sync<T: Send + Sync + 'static>() {}
    send_sync::<Prepared>();
    send_sync::<Renderer>();
    let (renderer, truth) = shell(32);
    let camera = camera_in(&renderer, &truth, DVec3::ZERO, 16);
    let mut prepared = renderer.prepare(&RenderSettings::default()).unwrap();
    let dvr = prepared.render(&camera);
    // A worker thread owns it and updates it.
    let worker = std::thread::spawn(move || {
        prepared.update(&iso()).unwrap();
        let bad = RenderSettings {
            step_vox: -1.0,
            ..iso()
        };
        assert!(prepared.update(&bad).is_err());
        assert_eq!(
            prepared.settings(),
            &iso(),
            "a failed update keeps the settings"
        );
        prepared.render(&camera)
    });
    let updated = worker.join().unwrap();
    let fresh = renderer.prepare(&iso()).unwrap().render(&camera);
    assert_same_frame(&updated, &fresh, "updated vs prepared afresh");
    assert!(bits(&updated) != bits(&dvr));
}

#[test]
fn a_maximum_distance_before_the_wall_ends_the_rays_and_one_behind_it_changes_nothing() {
    let (renderer, truth) = shell(32);
    let camera = camera_in(&renderer, &truth, DVec3::new(2.0, -1.0, 0.5), 20);
    for settings in [
        iso(),
        RenderSettings {
            jitter: true,
            ..iso()
        },
    ] {
        let prepared = renderer.prepare(&settings).unwrap();
        let plain = prepared.render(&camera);
        let n = plain.len();
        assert!(plain.depth_mm.iter().all(|d| d.is_finite()));
        let nearest = plain.depth_mm.iter().copied().fold(f32::INFINITY, f32::min);
        let farthest = plain.depth_mm.iter().copied().fold(0.0, f32::max);
        let mut frame = Frame::default();
        // Before the wall: nothing is hit and nothing composited.
        let short = vec![nearest - 1.0; n];
        let options = RenderOptions::new().max_distance_mm(&short);
        prepared.render_with(&camera, &options, &mut frame).unwrap();
        assert!(frame.depth_mm.iter().all(|d| d.is_nan()));
        assert!(frame.color.iter().all(|c| *c == Premultiplied::default()));
        // Past the wall by more than a step (the sample after the crossing is taken): the
        // same image, bit for bit; so are infinite and NaN limits.
        for limit in [farthest + 1.5, f32::INFINITY, f32::NAN] {
            let long = vec![limit; n];
            let options = RenderOptions::new().max_distance_mm(&long);
            prepared.render_with(&camera, &options, &mut frame).unwrap();
            assert_same_frame(&frame, &plain, &format!("limit {limit}"));
        }
        // Per pixel: the left half ends before the wall, the right half behind it.
        let split: Vec<f32> = (0..n)
            .map(|i| {
                if i % 20 < 10 {
                    nearest - 1.0
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let options = RenderOptions::new().max_distance_mm(&split);
        prepared.render_with(&camera, &options, &mut frame).unwrap();
        for (i, d) in frame.depth_mm.iter().enumerate() {
            if i % 20 < 10 {
                assert!(d.is_nan());
            } else {
                assert_eq!(d.to_bits(), plain.depth_mm[i].to_bits());
            }
        }
    }
}

#[test]
fn optional_layers_give_hit_points_normals_and_the_surfaces_behind() {
    let (renderer, truth) = shell(40);
    let camera = camera_in(&renderer, &truth, DVec3::ZERO, 12);
    let prepared = renderer.prepare(&iso()).unwrap();
    let plain = prepared.render(&camera);
    assert_eq!(plain.layers(), Layers::NONE);
    assert!(plain.hit_mm.is_empty() && plain.normal.is_empty());
    let mut frame = Frame::default();
    let options = RenderOptions::new().layers(Layers::ALL);
    prepared.render_with(&camera, &options, &mut frame).unwrap();
    assert_eq!(frame.layers(), Layers::ALL);
    assert_same_frame(&frame, &plain, "layers change nothing else");
    let centre = renderer.volume().geometry().world_of(truth.centre_vox);
    let (inner, outer) = (truth.inner_radius_vox, truth.outer_radius_vox);
    for y in 0..12 {
        for x in 0..12 {
            let i = x + 12 * y;
            let dir = camera.pixel_ray(x, y).unwrap().dir;
            let hit = DVec3::from(frame.hit_mm[i].map(f64::from));
            assert!((hit.distance(centre) - inner).abs() < 0.1, "{hit}");
            // Tissue is brighter than air: the gradient points out of the cavity.
            let normal = DVec3::from(frame.normal[i].map(f64::from));
            assert!(normal.dot(dir) > 0.95, "({x}, {y}): {normal}");
            // Into the shell, out of it into the air outside, then nothing.
            let [first, second, third, _] = frame.layer_depths_mm[i];
            assert_eq!(first.to_bits(), frame.depth_mm[i].to_bits());
            assert!(
                (f64::from(second) - outer).abs() < 0.1,
                "{second} vs {outer}"
            );
            assert!(third.is_nan());
        }
    }
}

#[test]
fn cancelling_stops_within_a_tile_per_thread() {
    let (renderer, truth) = shell(48);
    let camera = camera_in(&renderer, &truth, DVec3::ZERO, 160); // 100 tiles
    let prepared = renderer.prepare(&iso()).unwrap();
    let threads = 2;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let cancel = AtomicBool::new(false);
    let (done, total, k) = (AtomicUsize::new(0), AtomicUsize::new(0), 5);
    let progress = |p: Progress| {
        done.fetch_max(p.done, Ordering::Relaxed);
        total.store(p.total, Ordering::Relaxed);
        if p.done == k {
            cancel.store(true, Ordering::Relaxed);
        }
    };
    let options = RenderOptions::new().cancel(&cancel).progress(&progress);
    let mut frame = Frame::default();
    let result = pool.install(|| prepared.render_with(&camera, &options, &mut frame));
    assert_eq!(result, Err(Cancelled));
    let (done, total) = (done.into_inner(), total.into_inner());
    assert_eq!(total, 100);
    // The tiles in flight when the flag was set finish; no other starts.
    assert!((k..=k + threads).contains(&done), "{done} tiles done");
    // Without the flag the same options render the whole frame, reporting every tile.
    cancel.store(false, Ordering::Relaxed);
    let count = AtomicUsize::new(0);
    let counting = |_: Progress| {
        count.fetch_add(1, Ordering::Relaxed);
    };
    let options = RenderOptions::new().cancel(&cancel).progress(&counting);
    pool.install(|| prepared.render_with(&camera, &options, &mut frame))
        .unwrap();
    assert_eq!(count.into_inner(), 100);
    assert_same_frame(&frame, &prepared.render(&camera), "uncancelled");
}

#[test]
fn reduced_quality_casts_fewer_rays_and_keeps_the_geometry() {
    let (renderer, truth) = shell(40);
    let camera = camera_in(&renderer, &truth, DVec3::ZERO, 48);
    let prepared = renderer.prepare(&iso()).unwrap();
    let full = prepared.render(&camera);
    let mut frame = Frame::default();
    for quality in [Quality::Half, Quality::Quarter] {
        let options = RenderOptions::new().quality(quality);
        prepared.render_with(&camera, &options, &mut frame).unwrap();
        assert_eq!([frame.width, frame.height], [48, 48]);
        let f = quality.factor() as u64;
        assert_eq!(frame.stats.rays, 48 * 48 / (f * f));
        // From the centre every ray hits the inner wall at its radius.
        let radius = truth.inner_radius_vox as f32;
        assert!(frame.depth_mm.iter().all(|d| (d - radius).abs() < 0.1));
        // The shading varies slowly: the image is close to the full one.
        let worst = (0..full.len())
            .map(|i| {
                let (a, b) = (frame.color[i].rgb, full.color[i].rgb);
                (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max)
            })
            .fold(0.0, f32::max);
        assert!(worst < 0.05, "{quality:?}: {worst}");
    }
}

#[test]
fn reduced_quality_keeps_a_silhouette_sharp() {
    // From outside the shell, looking at its rim: a near surface against the air beyond.
    let (renderer, truth) = shell(40);
    let g = renderer.volume().geometry();
    let centre = g.world_of(truth.centre_vox);
    let eye = centre + DVec3::new(0.0, 0.0, -60.0);
    let at = centre + DVec3::new(truth.outer_radius_vox, 0.0, 0.0);
    let camera = Camera::look_at(eye, at, DVec3::Y, 40.0, [64, 64]).unwrap();
    let prepared = renderer.prepare(&iso()).unwrap();
    let full = prepared.render(&camera);
    let mut quarter = Frame::default();
    let options = RenderOptions::new().quality(Quality::Quarter);
    prepared
        .render_with(&camera, &options, &mut quarter)
        .unwrap();
    let (hits, misses) = (
        full.depth_mm.iter().filter(|d| d.is_finite()).count(),
        full.depth_mm.iter().filter(|d| d.is_nan()).count(),
    );
    assert!(hits > 500 && misses > 500, "{hits} hits, {misses} misses");
    // No pixel blends the surface with the air beyond: each is one or the other.
    for (i, c) in quarter.color.iter().enumerate() {
        let hit = quarter.depth_mm[i].is_finite();
        let alpha = c.alpha();
        assert!(
            if hit { alpha == 1.0 } else { alpha == 0.0 },
            "pixel {i}: {alpha}"
        );
    }
}

#[test]
fn a_still_of_one_frame_is_the_plain_render_and_more_frames_smooth_it() {
    let (renderer, truth) = shell(32);
    let camera = camera_in(&renderer, &truth, DVec3::new(1.0, 2.0, 0.0), 24);
    let settings = RenderSettings {
        mode: Mode::Hybrid,
        iso_opacity: 0.5,
        ..iso()
    };
    let prepared = renderer.prepare(&settings).unwrap();
    let plain = prepared.render(&camera);
    let mut still = Still::new();
    let one = still
        .render_next(&prepared, &camera, &RenderOptions::new())
        .unwrap();
    assert_same_frame(one, &plain, "one frame");
    for _ in 1..4 {
        still
            .render_next(&prepared, &camera, &RenderOptions::new())
            .unwrap();
    }
    assert_eq!(still.frames(), 4);
    let average = still.frame();
    // Depths stay frame 0's; colours move a little.
    let depth_bits = |f: &Frame| f.depth_mm.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
    assert_eq!(depth_bits(average), depth_bits(&plain));
    assert!(bits(average) != bits(&plain));
    let worst = (0..plain.len())
        .map(|i| (average.color[i].rgb[0] - plain.color[i].rgb[0]).abs())
        .fold(0.0, f32::max);
    assert!(worst < 0.2, "{worst}");
    still.reset();
    assert_eq!(still.frames(), 0);
}

#[test]
fn a_pixel_offset_moves_where_pixels_sample() {
    let camera = Camera::look_at(DVec3::ZERO, DVec3::Z, DVec3::Y, 70.0, [40, 30]).unwrap();
    assert_eq!(camera.with_pixel_offset(0.0, 0.0), camera);
    let moved = camera.with_pixel_offset(0.25, -0.375);
    for (x, y) in [(0, 0), (17, 9), (39, 29)] {
        let expected = camera.ray(x as f64 + 0.75, y as f64 + 0.125).unwrap().dir;
        assert!(moved.pixel_ray(x, y).unwrap().dir.distance(expected) < 1e-12);
    }
}

#[test]
fn the_progressive_sequence_ends_in_the_full_image_unless_the_view_changes() {
    let (renderer, truth) = shell(32);
    let camera = camera_in(&renderer, &truth, DVec3::ZERO, 40);
    let prepared = renderer.prepare(&iso()).unwrap();
    let plain = prepared.render(&camera);
    let generation = AtomicU64::new(7);
    let options = ProgressiveOptions {
        still_frames: 3,
        still_filter: Filter::Trilinear,
        ..ProgressiveOptions::default()
    };
    let delivered = Mutex::new(Vec::new());
    progressive(
        &prepared,
        &camera,
        &generation,
        7,
        &options,
        |stage, frame| {
            assert_eq!([frame.width, frame.height], [40, 40]);
            if stage == Stage::Full {
                assert_same_frame(frame, &plain, "the full stage");
            }
            delivered.lock().unwrap().push(stage);
        },
    )
    .unwrap();
    let expected = [
        Stage::Preview(Quality::Quarter),
        Stage::Preview(Quality::Half),
        Stage::Full,
        Stage::Still(2),
        Stage::Still(3),
    ];
    assert_eq!(delivered.into_inner().unwrap(), expected);
    // B-spline stills start again after the (trilinear) full frame.
    let spline = ProgressiveOptions {
        still_filter: Filter::BSpline,
        ..options.clone()
    };
    let mut stages = Vec::new();
    progressive(&prepared, &camera, &generation, 7, &spline, |stage, _| {
        stages.push(stage);
    })
    .unwrap();
    let stills = [Stage::Still(1), Stage::Still(2), Stage::Still(3)];
    assert_eq!(stages[..3], expected[..3]);
    assert_eq!(stages[3..], stills);
    // The view changes while the half preview is shown: nothing more comes.
    let mut stages = Vec::new();
    let result = progressive(&prepared, &camera, &generation, 7, &options, |stage, _| {
        stages.push(stage);
        if stage == Stage::Preview(Quality::Half) {
            generation.fetch_add(1, Ordering::AcqRel);
        }
    });
    assert_eq!(result, Err(Cancelled));
    assert_eq!(stages, expected[..2]);
    // A stale generation renders nothing.
    let result = progressive(&prepared, &camera, &generation, 7, &options, |_, _| {
        panic!("a stale view was delivered")
    });
    assert_eq!(result, Err(Cancelled));
}

#[test]
fn the_progressive_driver_drops_the_frame_in_flight() {
    // The generation changes a millisecond in, while a frame renders: the driver gives up.
    let (renderer, truth) = shell(32);
    let camera = camera_in(&renderer, &truth, DVec3::ZERO, 160);
    let prepared = renderer.prepare(&iso()).unwrap();
    let generation = AtomicU64::new(0);
    // Stills without end: only the change can stop the sequence, however late it comes.
    let options = ProgressiveOptions {
        previews: Vec::new(),
        still_frames: usize::MAX,
        ..ProgressiveOptions::default()
    };
    let result = std::thread::scope(|scope| {
        let bump = scope.spawn(|| {
            std::thread::sleep(std::time::Duration::from_millis(1));
            generation.fetch_add(1, Ordering::AcqRel);
        });
        let result = progressive(&prepared, &camera, &generation, 0, &options, |_, _| {});
        bump.join().unwrap();
        result
    });
    assert_eq!(result, Err(Cancelled));
}

#[test]
fn reduced_quality_takes_any_size_and_field_of_view() {
    let (renderer, truth) = shell(24);
    let prepared = renderer.prepare(&iso()).unwrap();
    let eye = renderer.volume().geometry().world_of(truth.centre_vox);
    assert_eq!(Quality::from_name(" Quarter"), Some(Quality::Quarter));
    assert_eq!(Quality::Quarter.reduced_size([37, 23]), [10, 6]);
    assert_eq!(Quality::Half.reduced_size([1, 3]), [1, 2]);
    let mut frame = Frame::default();
    for (fov, size) in [
        (FOV_RANGE_DEG.0, [37, 23]),
        (FOV_RANGE_DEG.1, [3, 1]),
        (90.0, [1, 1]),
    ] {
        let camera = Camera::look_at(eye, eye + DVec3::X, DVec3::Z, fov, size).unwrap();
        for quality in Quality::ALL {
            let options = RenderOptions::new().quality(quality);
            prepared.render_with(&camera, &options, &mut frame).unwrap();
            assert_eq!([frame.width, frame.height], size, "{fov}° {quality:?}");
            let radius = truth.inner_radius_vox as f32;
            assert!(frame.depth_mm.iter().all(|d| (d - radius).abs() < 0.1));
        }
    }
}

#[test]
fn the_preview_planner_starts_an_expensive_view_at_an_eighth() {
    use super::progressive::PreviewPlanner;
    use std::time::Duration;
    let budget = Duration::from_millis(25);
    let mut planner = PreviewPlanner::default();
    // Nothing measured yet: quarter first.
    assert_eq!(
        planner.previews([512, 512], budget),
        [Quality::Quarter, Quality::Half]
    );
    let frame = |time_ms: u64| Frame {
        width: 512,
        height: 512,
        stats: RenderStats {
            time: Duration::from_millis(time_ms),
            ..RenderStats::default()
        },
        ..Frame::default()
    };
    // A full frame of 800 ms: a quarter would take 50 ms, over the budget.
    planner.observe(Stage::Full, &frame(800));
    assert_eq!(
        planner.predict(Quality::Quarter, [512, 512]),
        Some(Duration::from_millis(50))
    );
    assert_eq!(
        planner.previews([512, 512], budget),
        [Quality::Eighth, Quality::Quarter, Quality::Half]
    );
    // The mode became cheap: a 3 ms eighth predicts a 12 ms quarter.
    planner.observe(Stage::Preview(Quality::Eighth), &frame(3));
    assert_eq!(planner.previews([512, 512], budget)[0], Quality::Quarter);
    // Stills and empty frames teach nothing.
    planner.observe(Stage::Still(4), &frame(10_000));
    planner.observe(Stage::Full, &frame(0));
    assert_eq!(planner.previews([512, 512], budget)[0], Quality::Quarter);
}

#[test]
fn an_unlit_iso_render_finds_the_same_surfaces_and_shades_none() {
    let (renderer, truth) = shell(32);
    let camera = camera_in(&renderer, &truth, DVec3::new(2.0, -1.0, 0.5), 20);
    let prepared = renderer.prepare(&iso()).unwrap();
    let layers = Layers::HIT_POSITION | Layers::NORMAL;
    let (mut lit, mut unlit) = (Frame::default(), Frame::default());
    let options = RenderOptions::new().layers(layers);
    prepared.render_with(&camera, &options, &mut lit).unwrap();
    prepared
        .render_with(&camera, &options.unlit(), &mut unlit)
        .unwrap();
    let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    assert!(same(&lit.depth_mm, &unlit.depth_mm));
    assert!(lit
        .hit_mm
        .iter()
        .flatten()
        .eq(unlit.hit_mm.iter().flatten()));
    assert!(lit
        .normal
        .iter()
        .flatten()
        .eq(unlit.normal.iter().flatten()));
    assert!(lit.color.iter().all(|c| c.transmittance < 0.5));
    assert!(unlit.color.iter().all(|c| c.transmittance == 1.0));
}
