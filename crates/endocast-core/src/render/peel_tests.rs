//! Acceptance tests of depth peeling (issue 19) on the joint phantom: from inside the lower
//! bone looking across both joint spaces, each peel's depth is the analytic distance to its
//! articular surface, and the parts in front of the peel, behind it and of unpeeled rays
//! composite as specified.

use super::*;
use crate::phantom::{self, Joint, PhantomOptions};
use glam::DVec3;
use std::sync::Arc;

/// The bone–contrast mid-value the phantom's ramps put on every articular surface.
const PEEL_HU: f64 = 650.0;
const SIZE: usize = 24;

/// The joint phantom, its truth, and a camera in the lower bone 10 voxels below the first joint
/// space, looking up across both (the field narrow enough that every ray stays in the bones
/// up to the volume's top, so that the last crossings are the second joint space's).
fn scene() -> (Arc<Renderer>, Joint, Camera) {
    let (volume, joint) = phantom::joint(&PhantomOptions {
        size: 64,
        ..Default::default()
    });
    let eye_vox = joint.centre_vox - DVec3::new(1.5, -2.0, 10.0);
    let eye = volume.geometry().world_of(eye_vox);
    let camera = Camera::look_at(eye, eye + DVec3::Z, DVec3::Y, 30.0, [SIZE, SIZE]).unwrap();
    (Arc::new(Renderer::new(volume)), joint, camera)
}

fn peel(layer: PeelLayer, falling: bool) -> RenderSettings {
    RenderSettings {
        mode: Mode::Peel,
        peel: PeelSettings {
            threshold_hu: Some(PEEL_HU),
            layer,
            falling,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Distance along pixel `(x, y)`'s ray to articular surface `surface` (0–3, bottom to top), by
/// bisection on the analytic surface (the rays rise faster than the bowl).
fn analytic_depth(
    renderer: &Renderer,
    joint: &Joint,
    camera: &Camera,
    x: usize,
    y: usize,
    surface: usize,
) -> f64 {
    let ray = camera.pixel_ray(x, y).unwrap();
    let voxel_from_world = renderer.volume().geometry().voxel_from_world();
    let (origin, dir) = (
        voxel_from_world.transform_point3(ray.origin),
        voxel_from_world.transform_vector3(ray.dir),
    );
    let above = |t: f64| {
        let p = origin + dir * t;
        p.z > joint.surfaces_k(p.x, p.y)[surface]
    };
    let (mut lo, mut hi) = (0.0, 60.0);
    assert!(!above(lo) && above(hi));
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if above(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn every_peel_lies_on_its_analytic_surface() {
    let (renderer, joint, camera) = scene();
    // Falling: into the (darker) contrast, the near surface of each joint space; rising: back
    // into bone, the opposing articular surfaces.
    let cases = [
        (PeelLayer::Nth(1), true, 0),
        (PeelLayer::Nth(2), true, 2),
        (PeelLayer::Last, true, 2),
        (PeelLayer::Nth(1), false, 1),
        (PeelLayer::Nth(2), false, 3),
        (PeelLayer::Last, false, 3),
    ];
    for (layer, falling, surface) in cases {
        let settings = peel(layer, falling);
        let frame = renderer.prepare(&settings).unwrap().render(&camera);
        let mut worst: f64 = 0.0;
        for y in 0..SIZE {
            for x in 0..SIZE {
                let depth = f64::from(frame.depth_mm[x + SIZE * y]);
                let expected = analytic_depth(&renderer, &joint, &camera, x, y, surface);
                worst = worst.max((depth - expected).abs());
            }
        }
        assert!(
            worst < 0.1,
            "{layer:?} falling {falling}: worst {worst} voxel"
        );
        // The surface is opaque: every pixel is.
        assert!(frame.color.iter().all(|c| c.transmittance == 0.0));
        // Without brick skipping the image is the same.
        let all_bricks = RenderSettings {
            skip_empty: false,
            ..settings.clone()
        };
        let slow = renderer.prepare(&all_bricks).unwrap().render(&camera);
        assert_eq!(slow.color, frame.color, "{layer:?} {falling}");
        // Tracing a pixel takes the one-sample-at-a-time path to the same surface.
        let prepared = renderer.prepare(&settings).unwrap();
        let trace = prepared.trace_pixel(&camera, 5, 17);
        assert_eq!(trace.depth_mm, frame.depth_mm[5 + SIZE * 17]);
    }
    // There is no third joint space: nothing is shown and no depth given.
    let frame = renderer
        .prepare(&peel(PeelLayer::Nth(3), true))
        .unwrap()
        .render(&camera);
    assert!(frame.depth_mm.iter().all(|d| d.is_nan()));
    assert!(frame
        .color
        .iter()
        .all(|c| c.transmittance == 1.0 && c.rgb == [0.0; 3]));
}

/// A transfer function of one colour, `alpha_per_mm` opaque in bone (above [`PEEL_HU`]).
fn bone_tf(color: [f32; 3], alpha_per_mm: f32) -> TransferFunction {
    TransferFunction::from_points(
        &[(PEEL_HU - 1.0, 0.0), (PEEL_HU, alpha_per_mm)],
        &[(0.0, color)],
    )
    .unwrap()
}

/// Settings whose every part shows: a red front, a half-opaque green surface, a blue back.
fn layered(keep: f32, unpeeled: Unpeeled, layer: PeelLayer) -> RenderSettings {
    let mut s = peel(layer, true);
    s.tf = bone_tf([1.0, 0.0, 0.0], 0.03);
    s.peel.tf_after = Some(bone_tf([0.0, 0.0, 1.0], 0.05));
    (s.iso_opacity, s.iso_color) = (0.5, [0.0, 1.0, 0.0]);
    // No white highlight: red comes from the front alone.
    s.lighting.specular = 0.0;
    s.peel.keep = keep;
    s.peel.unpeeled = unpeeled;
    s
}

fn close(a: &Premultiplied, b: &Premultiplied, what: &str) {
    let d = (0..3)
        .map(|c| (a.rgb[c] - b.rgb[c]).abs())
        .fold((a.transmittance - b.transmittance).abs(), f32::max);
    assert!(d < 1e-5, "{what}: {a:?} vs {b:?}");
}

#[test]
fn front_is_discarded_kept_by_its_factor_and_unpeeled_rays_give_context() {
    let (renderer, _, camera) = scene();
    let render = |s: &RenderSettings| renderer.prepare(s).unwrap().render(&camera);
    for layer in [PeelLayer::Nth(2), PeelLayer::Last] {
        // Discarded, the front does not matter: an opaque green one gives the same image.
        let discarded = render(&layered(0.0, Unpeeled::Discard, layer));
        let mut green = layered(0.0, Unpeeled::Discard, layer);
        green.tf = bone_tf([0.0, 1.0, 0.0], 1.0);
        assert_eq!(render(&green).color, discarded.color);
        assert!(discarded
            .color
            .iter()
            .all(|c| c.rgb[0] == 0.0 && c.rgb[2] > 0.0));
        // Kept by 0.4: 0.4 × the front (DVR up to the peel), then the discarded image behind it.
        let keep = 0.4;
        let kept = render(&layered(keep, Unpeeled::Discard, layer));
        let mut front_only = layered(0.0, Unpeeled::Discard, layer);
        front_only.mode = Mode::Dvr;
        let prepared = renderer.prepare(&front_only).unwrap();
        let (mut front, mut full) = (Frame::default(), Frame::default());
        let limits = discarded.depth_mm.clone();
        let options = RenderOptions::new().max_distance_mm(&limits);
        prepared.render_with(&camera, &options, &mut front).unwrap();
        prepared
            .render_with(&camera, &RenderOptions::new(), &mut full)
            .unwrap();
        for i in 0..SIZE * SIZE {
            let (f, back) = (front.color[i], discarded.color[i]);
            assert!(f.alpha() > 0.1, "the front shows at pixel {i}");
            let t = 1.0 - keep * f.alpha();
            let expected = Premultiplied {
                rgb: [0, 1, 2].map(|c| keep * f.rgb[c] + t * back.rgb[c]),
                transmittance: t * back.transmittance,
            };
            close(&kept.color[i], &expected, "kept");
        }
        assert_eq!(kept.depth_mm, discarded.depth_mm);
        // Kept whole, the front is the DVR up to the peel.
        let whole = render(&layered(1.0, Unpeeled::Discard, layer));
        let t_front = |i: usize| front.color[i].transmittance;
        assert!(
            (0..SIZE * SIZE).all(|i| (whole.color[i].rgb[0] - front.color[i].rgb[0]).abs() < 1e-6)
        );
        assert!((0..SIZE * SIZE).all(|i| whole.color[i].transmittance <= t_front(i)));
        // Never peeled three times: nothing, or as context the whole ray's DVR.
        let none = render(&layered(0.4, Unpeeled::Discard, PeelLayer::Nth(3)));
        assert!(none.color.iter().all(|c| *c == Premultiplied::default()));
        for keep in [0.0, 1.0] {
            let context = render(&layered(keep, Unpeeled::Context, PeelLayer::Nth(3)));
            for i in 0..SIZE * SIZE {
                close(&context.color[i], &full.color[i], "context");
            }
            assert!(context.depth_mm.iter().all(|d| d.is_nan()));
        }
        // Brick skipping leaves every variant as it is.
        for s in [
            layered(keep, Unpeeled::Discard, layer),
            layered(0.0, Unpeeled::Context, PeelLayer::Nth(3)),
        ] {
            let slow = RenderSettings {
                skip_empty: false,
                ..s.clone()
            };
            assert_eq!(render(&slow).color, render(&s).color);
        }
    }
}
