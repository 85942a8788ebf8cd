//! The endoscope's optics in the look (issue 35, item 4) on the sphere phantom: the realistic
//! look's default lens exact to the lens model, the field stop of a folding distortion, and
//! image-based lighting.

use super::*;
use crate::camera::{Lens, Optics, Projection};
use crate::phantom::{sphere_shell, PhantomOptions};
use crate::render::{Camera, Frame, Quality, RenderSettings, Renderer};
use crate::study::LensOptions;
use glam::DVec3;
use std::sync::Arc;

/// Image edge, pixels.
const SIZE: usize = 48;
/// Vertical field of view, degrees.
const FOV: f64 = 90.0;

/// The sphere shell phantom (outer radius 14.4 mm, inner 11.2 mm) and the look's ray pass at
/// its walls.
fn shell() -> (RayPass, DVec3) {
    let (volume, truth) = sphere_shell(&PhantomOptions {
        size: 32,
        ..Default::default()
    });
    let centre = volume.geometry().world_of(truth.centre_vox);
    let ray = RayPassSettings {
        tissue_hu: -480.0,
        ..RayPassSettings::default()
    };
    let renderer = Arc::new(Renderer::new(volume));
    let pass = RayPass::new(&renderer, &RenderSettings::default(), &ray).unwrap();
    (pass, centre)
}

/// A camera `distance_mm` from the shell's centre looking at it (0: from the centre, along
/// +z), through `lens`.
fn camera(centre: DVec3, distance_mm: f64, lens: Lens) -> Camera {
    let optics = Optics {
        projection: Projection::Pinhole,
        field: FOV,
        lens,
        near_mm: 0.0,
    };
    let eye = centre - DVec3::Z * distance_mm;
    optics
        .camera(eye, eye + DVec3::Z, DVec3::Y, [SIZE, SIZE])
        .unwrap()
}

/// Matte, untextured, no fall-off or smoothing: only the lighting and the lens shape the image.
fn matte(lighting: Lighting) -> Shading {
    Shading {
        attenuation_mm: None,
        smoothing_px: 0,
        lighting,
        ..Shading::default()
    }
}

/// The red channel of pixel `(x, y)`, `None` without a hit.
fn red(frame: &Frame, x: usize, y: usize) -> Option<f32> {
    let p = frame.color[x + frame.width * y];
    (p.transmittance < 1.0).then_some(p.rgb[0])
}

#[test]
fn the_realistic_look_sees_through_the_endoscope_exactly_as_its_lens_given() {
    let (pass, centre) = shell();
    let realistic = Look::of_kind(LookKind::Realistic, &PresetLook::CT).unwrap();
    let pinhole = Projection::Pinhole;
    let default = LensOptions::default()
        .resolve(Some(&realistic), pinhole)
        .unwrap();
    assert_eq!(default, Lens::RIGID_ENDOSCOPE);
    let given = LensOptions {
        distortion: Some(Lens::RIGID_ENDOSCOPE.distortion),
        vignetting: Some(Lens::RIGID_ENDOSCOPE.vignetting),
    };
    let explicit = given.resolve(None, pinhole).unwrap();
    let plain = LensOptions::default().resolve(None, pinhole).unwrap();
    assert!(plain.is_ideal() && plain.vignetting == 0.0);
    // 22 mm from the centre the ball spans 0.87 of the half height, where the lens shrinks it
    // by 11 %.
    let look_through = |lens| {
        let camera = camera(centre, 22.0, lens);
        shade(
            &pass.trace(&camera, Quality::Full),
            &camera,
            &realistic.shading,
        )
        .unwrap()
    };
    let (seen, again) = (look_through(default), look_through(explicit));
    let ideal = look_through(plain);
    assert_eq!(seen.color, again.color);
    assert_eq!(
        seen.depth_mm
            .iter()
            .map(|d| d.to_bits())
            .collect::<Vec<_>>(),
        again
            .depth_mm
            .iter()
            .map(|d| d.to_bits())
            .collect::<Vec<_>>()
    );
    // The ball's silhouette on the middle row where the lens model puts it: the ideal radius
    // (normalised to the half height) distorted, `r_u · (1 + k1 r_u² + k2 r_u⁴)`.
    let across = |frame: &Frame| {
        (0..SIZE)
            .filter(|&x| red(frame, x, SIZE / 2).is_some())
            .count()
    };
    let ideal_r = (14.4f64 / 22.0).asin().tan() / (FOV.to_radians() / 2.0).tan();
    let model_r = Lens::RIGID_ENDOSCOPE.distort((ideal_r, 0.0)).0;
    for (frame, r) in [(&ideal, ideal_r), (&seen, model_r)] {
        let expected = r * SIZE as f64;
        let got = across(frame) as f64;
        assert!(
            (got - expected).abs() <= 2.0,
            "{got} pixels across, the model {expected}"
        );
    }
    assert!(across(&seen) + 3 < across(&ideal));
}

#[test]
fn a_folding_distortion_ends_in_a_soft_round_field_stop() {
    let (pass, centre) = shell();
    // From the centre every wall point faces the tip at one distance: one colour, but for the
    // lens. r (1 − 0.5 r²) folds at r_d = 0.544 of the half height.
    let lens = Lens {
        distortion: [-0.5, 0.0],
        vignetting: 0.0,
    };
    let edge = lens.image_radius().unwrap() * SIZE as f64 / 2.0;
    let camera = camera(centre, 0.0, lens);
    let frame = shade(
        &pass.trace(&camera, Quality::Full),
        &camera,
        &matte(Lighting::Phong),
    )
    .unwrap();
    let middle = SIZE / 2;
    let inside = red(&frame, middle, middle).unwrap();
    for x in middle..SIZE {
        let r = x as f64 + 0.5 - middle as f64;
        let shown = red(&frame, x, middle);
        if r > edge {
            assert_eq!(shown, None, "beyond the fold at {x}: the background shows");
        } else if r < edge - 2.5 {
            let v = shown.unwrap();
            assert!(
                (v - inside).abs() < 0.03 * inside,
                "inside the field at {x}: {v}"
            );
        } else if r > edge - 1.5 {
            let v = shown.unwrap();
            assert!(v < 0.9 * inside, "the stop's soft edge at {x}: {v}");
        }
    }
}

#[test]
fn a_uniform_lit_sphere_lights_uniformly_and_the_built_in_one_faces_the_tip() {
    let (pass, centre) = shell();
    let camera = camera(centre, 25.0, Lens::default());
    let gbuffer = pass.trace(&camera, Quality::Full);
    let frame = |lighting| shade(&gbuffer, &camera, &matte(lighting)).unwrap();
    let hits = |f: &Frame| -> Vec<f32> {
        (0..SIZE * SIZE)
            .filter_map(|i| red(f, i % SIZE, i / SIZE))
            .collect()
    };
    let spread = |v: &[f32]| {
        let (lo, hi) = v
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), c| (lo.min(*c), hi.max(*c)));
        hi - lo
    };
    let uniform = Lighting::LitSphere(Arc::new(LitSphere::uniform(4, 0.7).unwrap()));
    let flat = hits(&frame(uniform));
    assert!(flat.len() > SIZE * SIZE / 4);
    let red_tissue = Shading::default().tissue_color[0];
    assert!(
        // Texels are stored in 8 bits: 0.7 is 179/255.
        flat.iter()
            .all(|c| (c - red_tissue * 0.7).abs() < red_tissue * 0.5 / 255.0 + 1e-5),
        "{:?}",
        &flat[..4]
    );
    assert!(
        spread(&hits(&frame(Lighting::Phong))) > 0.3,
        "Phong shades the ball"
    );
    // The built-in one: the ball's middle (facing the tip) brighter than its rim.
    let built_in = frame(Lighting::built_in_ibl());
    let middle = SIZE / 2;
    let row: Vec<f32> = (middle..SIZE)
        .map_while(|x| red(&built_in, x, middle))
        .collect();
    let (facing, rim) = (row[0], row[row.len() - 1]);
    assert!(facing > 1.4 * rim, "facing {facing}, rim {rim}");
    assert!(row.windows(2).all(|w| w[1] <= w[0] + 0.02), "{row:?}");
}
