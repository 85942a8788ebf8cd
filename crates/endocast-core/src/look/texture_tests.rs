//! The detail texture in shaded frames (issue 35): its contrast on the sinus phantom, mip
//! mapping on a plane seen far and grazing, a colour texture's hue and a specular map's
//! highlights.

use super::texture::tests::{level_variance, without_mips, CONTRAST_BAND};
use super::*;
use crate::phantom::{sinus, PhantomOptions};
use crate::render::{Camera, Frame, Quality, RenderSettings, Renderer};
use glam::{DVec3, Vec3};
use std::sync::Arc;

/// The luminance of a shaded pixel.
fn luma(rgb: [f32; 3]) -> f32 {
    LUMA.iter().zip(rgb).map(|(w, c)| w * c).sum()
}

/// The sinus phantom (size 48) from inside its right cell, looking along +z: the G-buffer of
/// the realistic look without secretion, and its camera.
fn sinus_view(size: usize) -> (GBuffer, Camera) {
    let (volume, _) = sinus(&PhantomOptions {
        size: 48,
        ..Default::default()
    });
    let eye = volume.geometry().world_of(DVec3::new(14.4, 19.0, 21.6));
    let camera = Camera::look_at(eye, eye + DVec3::Z, DVec3::Y, 90.0, [size, size]).unwrap();
    let mut look = Look::of_kind(LookKind::Realistic, &PresetLook::CT).unwrap();
    look.ray.secretion = SecretionMode::Off;
    let renderer = Arc::new(Renderer::new(volume));
    let pass = RayPass::new(&renderer, &RenderSettings::default(), &look.ray).unwrap();
    (pass.trace(&camera, Quality::Full), camera)
}

/// The realistic look of the CT preset, dry (no highlights), no smoothing.
fn dry() -> Shading {
    let mut shading = Look::of_kind(LookKind::Realistic, &PresetLook::CT)
        .unwrap()
        .shading;
    shading.wetness = 0.0;
    shading.smoothing_px = 0;
    shading
}

/// Pixels with a hit none of whose channels is clamped, in both frames.
fn unclamped<'a>(a: &'a Frame, b: &'a Frame) -> impl Iterator<Item = usize> + 'a {
    let fine = |f: &Frame, i: usize| {
        f.color[i].transmittance == 0.0 && f.color[i].rgb.iter().all(|&c| c > 0.0 && c < 1.0)
    };
    (0..a.color.len()).filter(move |&i| fine(a, i) && fine(b, i))
}

#[test]
fn the_default_texture_s_contrast_on_the_sinus_phantom_is_in_its_band() {
    let (gbuffer, camera) = sinus_view(128);
    let textured = shade(&gbuffer, &camera, &dry()).unwrap();
    let bare = Shading {
        texture: None,
        ..dry()
    };
    let bare = shade(&gbuffer, &camera, &bare).unwrap();
    // The texture's share of each pixel's luminance: textured over untextured, the same light.
    let detail: Vec<f32> = unclamped(&textured, &bare)
        .map(|i| luma(textured.color[i].rgb) / luma(bare.color[i].rgb))
        .collect();
    assert!(detail.len() > 10_000, "{} pixels", detail.len());
    let n = detail.len() as f32;
    let mean = detail.iter().sum::<f32>() / n;
    let std = (detail.iter().map(|d| (d - mean).powi(2)).sum::<f32>() / n).sqrt();
    let contrast = std / mean;
    assert!(CONTRAST_BAND.contains(&contrast), "contrast {contrast}");
}

/// A G-buffer of the plane z = 0 seen by `camera`, out to `far` mm.
fn plane(camera: &Camera, far: f32) -> GBuffer {
    let [w, h] = camera.size();
    let mut g = GBuffer {
        width: w,
        height: h,
        ..GBuffer::default()
    };
    for i in 0..w * h {
        let ray = camera.pixel_ray(i % w, i / w).unwrap();
        let t = (-ray.origin.z / ray.dir.z) as f32;
        let hit = t > 0.0 && t < far;
        let point = ray.at(f64::from(t)).as_vec3().to_array();
        g.depth_mm.push(if hit { t } else { f32::NAN });
        g.hit_mm.push(if hit { point } else { [f32::NAN; 3] });
        g.normal
            .push(if hit { [0.0, 0.0, -1.0] } else { [f32::NAN; 3] });
        g.secretion_mm.push(0.0);
    }
    g
}

#[test]
fn a_far_grazing_plane_reads_coarse_mip_levels_and_does_not_alias() {
    // 20 mm over the plane, looking 31° down at it: beyond 100 mm the rays meet it at 11° or
    // less, tens to hundreds of texels per pixel.
    let eye = DVec3::new(0.0, 0.0, 20.0);
    let camera = Camera::look_at(
        eye,
        eye + DVec3::new(0.0, 1.0, -0.6),
        DVec3::Z,
        60.0,
        [128, 128],
    )
    .unwrap();
    let gbuffer = plane(&camera, 400.0);
    let mucosa = Arc::new(Texture::built_in("mucosa").unwrap());
    let shading = |texture: Arc<Texture>| Shading {
        tissue_color: [0.5; 3],
        ambient: 1.0,
        diffuse: 0.0,
        attenuation_mm: None,
        smoothing_px: 0,
        texture: Some(texture),
        texture_mm: 100.0,
        ..Shading::default()
    };
    // Neighbouring pixels' luminance differences among hits farther than 100 mm: half their
    // mean square, the pixel-to-pixel variance.
    let variance = |frame: &Frame| {
        let w = camera.size()[0];
        let pairs: Vec<f32> = (0..frame.color.len() - 1)
            .filter(|&i| i % w != w - 1)
            .filter(|&i| gbuffer.depth_mm[i] > 100.0 && gbuffer.depth_mm[i + 1] > 100.0)
            .map(|i| luma(frame.color[i].rgb) - luma(frame.color[i + 1].rgb))
            .collect();
        assert!(pairs.len() > 500, "{} pairs", pairs.len());
        pairs.iter().map(|d| d * d).sum::<f32>() / (2 * pairs.len()) as f32
    };
    let mipped = variance(&shade(&gbuffer, &camera, &shading(mucosa.clone())).unwrap());
    let single = shading(Arc::new(without_mips(&mucosa)));
    let single = variance(&shade(&gbuffer, &camera, &single).unwrap());
    // The footprint there: at 100 mm a pixel of this camera is 0.8 mm across, 5 times that
    // where the ray meets the plane at 11°: 4 mm, 21 texels of a 100 mm tile of 512, level 4.4
    // (farther, coarser). Level 4's variance, times the detail's gain (0.5 · 0.6 · 2)², bounds
    // what the pixels may show.
    let gain = (0.5f32 * 0.6 * 2.0).powi(2);
    let band_limited = gain * level_variance(&mucosa, 4);
    assert!(
        mipped <= 2.0 * band_limited,
        "{mipped} against {band_limited}"
    );
    assert!(
        single >= 10.0 * mipped,
        "without mips {single}, with {mipped}"
    );
}

#[test]
fn a_colour_texture_changes_the_hue_and_a_grey_one_does_not() {
    let (gbuffer, camera) = sinus_view(64);
    let hash = |i: usize, salt: usize| ((i * 7919 + salt * 104_729) % 1000) as f32 / 1000.0;
    let rgb: Vec<[f32; 3]> = (0..256)
        .map(|i| [hash(i, 1), hash(i, 2), hash(i, 3)])
        .collect();
    let grey = rgb.iter().map(|&c| luma(c)).collect();
    let textures = [
        Texture::from_rgb(16, 16, rgb).unwrap(),
        Texture::from_luma(16, 16, grey).unwrap(),
    ];
    let frames = textures.map(|t| {
        let shading = Shading {
            texture: Some(Arc::new(t)),
            texture_mm: 8.0,
            ..dry()
        };
        shade(&gbuffer, &camera, &shading).unwrap()
    });
    // The hue as red over green: the tissue colour's ratio times the texture's.
    let spread = |frame: &Frame| {
        let hues: Vec<f32> = unclamped(frame, frame)
            .map(|i| frame.color[i].rgb[0] / frame.color[i].rgb[1])
            .collect();
        let (lo, hi) = hues
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
        hi / lo - 1.0
    };
    let (colour, grey) = (spread(&frames[0]), spread(&frames[1]));
    assert!(colour > 0.5, "colour: hue varies by {colour}");
    assert!(grey < 0.02, "grey: hue varies by {grey}");
}

#[test]
fn a_specular_map_s_bright_half_glistens_and_its_dark_half_does_not() {
    let (gbuffer, camera) = sinus_view(96);
    // Black on the left half of the tile, white on the right.
    let map = Texture::from_luma(64, 64, (0..64 * 64).map(|i| (i % 64 / 32) as f32).collect());
    let map = Arc::new(map.unwrap());
    let shading = Shading {
        wetness: 1.0,
        specular_map: Some(map.clone()),
        texture: None,
        texture_mm: 16.0,
        ..dry()
    };
    let frame = shade(&gbuffer, &camera, &shading).unwrap();
    // Each pixel's side by the map there, at the finest level and at level 4 (a footprint of
    // 16 texels, coarser than the frame reads): both clear of the edge.
    let side = |i: usize| {
        let (p, n) = (Vec3::from(gbuffer.hit_mm[i]), Vec3::from(gbuffer.normal[i]));
        let at = |footprint: f32| map.triplanar(p / 16.0, n, footprint)[0];
        let values = [at(0.0), at(16.0 / 64.0)];
        if values.iter().all(|&v| v > 0.98) {
            Some(true)
        } else if values.iter().all(|&v| v < 0.02) {
            Some(false)
        } else {
            None
        }
    };
    let (mut counts, mut whites) = ([0usize; 2], [0usize; 2]);
    for i in (0..frame.color.len()).filter(|&i| frame.color[i].transmittance == 0.0) {
        let Some(bright) = side(i) else { continue };
        counts[usize::from(bright)] += 1;
        whites[usize::from(bright)] += usize::from(frame.color[i].rgb.iter().all(|&c| c >= 0.85));
    }
    assert!(
        counts.iter().all(|&c| c > 1000),
        "pixels per side {counts:?}"
    );
    assert_eq!(whites[0], 0, "highlights on the dark side");
    assert!(
        whites[1] * 100 >= counts[1],
        "{} highlights of {}",
        whites[1],
        counts[1]
    );
}
