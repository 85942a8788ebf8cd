//! The vectorised deferred stage against a plain scalar form of it (one pixel at a time, as the
//! look first shaded): the same bits, on a G-buffer with misses, silhouettes, secretion and an
//! odd size (lane sets and bands cut off at the edges).

use super::footprint::Footprints;
use super::lanes::LANES;
use super::shading::{
    smoothstep, FILM_GLOSS, FILM_MM, FILM_SHININESS, MIN_FOOTPRINT_COS, SPECULAR_MAP_BASE,
    SPECULAR_MAP_GAIN, SPECULAR_MAP_MAX, WET_DARKENING,
};
use super::smooth::DEPTH_EDGE;
use super::*;
use crate::render::{Camera, Premultiplied, RenderStats};
use glam::{DVec3, Vec3};
use std::sync::Arc;

/// A number in [0, 1) from `i` and `salt`.
fn hash(i: usize, salt: u64) -> f32 {
    let mut h = (i as u64 ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15)).wrapping_add(0xD1B5);
    for _ in 0..3 {
        h ^= h >> 31;
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    }
    (h >> 40) as f32 / (1u64 << 24) as f32
}

/// A G-buffer seen by `camera`: a near fold over the left third in front of a far wall, noisy
/// depths and normals, secretion in a band (its surface's normal given on most of it), no hit
/// in a corner.
fn gbuffer(camera: &Camera) -> GBuffer {
    let [w, h] = camera.size();
    let mut g = GBuffer {
        width: w,
        height: h,
        ..GBuffer::default()
    };
    for i in 0..w * h {
        let (x, y) = (i % w, i / w);
        let ray = camera.pixel_ray(x, y).unwrap();
        let miss = x + y < 5;
        let depth = if x < w / 3 { 20.0 } else { 60.0 } * (1.0 + 0.02 * hash(i, 1));
        let normal = Vec3::new(hash(i, 2) - 0.5, hash(i, 3) - 0.5, -1.0).normalize();
        let secretion = if (10..18).contains(&y) {
            3.0 * hash(i, 4)
        } else {
            0.0
        };
        let hit = (ray.origin + ray.dir * f64::from(depth)).as_vec3();
        let nan = [f32::NAN; 3];
        g.depth_mm.push(if miss { f32::NAN } else { depth });
        g.hit_mm.push(if miss { nan } else { hit.to_array() });
        g.normal.push(if miss { nan } else { normal.to_array() });
        g.secretion_mm.push(if miss { 0.0 } else { secretion });
        let surface = Vec3::new(hash(i, 5) - 0.5, -0.2, -1.0).normalize();
        let surface = if secretion > 0.0 && x % 7 != 0 {
            surface.to_array()
        } else {
            nan
        };
        g.secretion_normal.push(surface);
    }
    g.stats = RenderStats::default();
    g
}

/// The smoothing one pixel and one tap at a time.
fn smooth_by_pixel(g: &GBuffer, radius: usize) -> Vec<[f32; 8]> {
    let (w, h) = (g.width, g.height);
    let sigma = 0.5 * radius as f32 + 0.5;
    let kernel: Vec<f32> = (0..=radius)
        .map(|k| (-0.5 * (k as f32 / sigma).powi(2)).exp())
        .collect();
    let texels: Vec<[f32; 8]> = (0..w * h).map(|i| g.texel(i)).collect();
    let pass = |texels: &[[f32; 8]], step: [isize; 2]| -> Vec<[f32; 8]> {
        (0..w * h)
            .map(|i| {
                let c = texels[i];
                if c[0].is_nan() {
                    return c;
                }
                let inverse = 1.0 / (DEPTH_EDGE * c[0].abs()).max(1e-3);
                let (mut sum, mut total) = ([0.0f32; 8], 0.0f32);
                let r = radius as isize;
                for k in -r..=r {
                    let (x, y) = (
                        (i % w) as isize + k * step[0],
                        (i / w) as isize + k * step[1],
                    );
                    if x < 0 || y < 0 || x >= w as isize || y >= h as isize {
                        continue;
                    }
                    let t = texels[x as usize + w * y as usize];
                    if t[0].is_nan() {
                        continue;
                    }
                    let d = (2.0 - 2.0 * (t[0] - c[0]).abs() * inverse).clamp(0.0, 1.0);
                    let weight = kernel[k.unsigned_abs()] * d;
                    if weight > 0.0 {
                        for (s, v) in sum.iter_mut().zip(t) {
                            *s += weight * v;
                        }
                        total += weight;
                    }
                }
                sum.map(|s| s / total)
            })
            .collect()
    };
    let mut out = pass(&pass(&texels, [1, 0]), [0, 1]);
    for t in &mut out {
        let n = Vec3::new(t[4], t[5], t[6]).normalize_or_zero();
        (t[4], t[5], t[6]) = (n.x, n.y, n.z);
    }
    out
}

/// The Phong highlight of strength `gloss` (times the shading's specular) on a surface at
/// cosine `cos` to the tip's light, exponent `shininess`.
fn highlight(s: &Shading, gloss: f32, cos: f32, shininess: f32) -> f32 {
    let mirror = (2.0 * cos * cos - 1.0).max(0.0);
    let strength = gloss * s.specular;
    if strength > 0.0 && mirror > 0.0 {
        strength * mirror.powf(shininess)
    } else {
        0.0
    }
}

/// The luminance of a colour.
fn luma(rgb: [f32; 3]) -> f32 {
    LUMA[0] * rgb[0] + LUMA[1] * rgb[1] + LUMA[2] * rgb[2]
}

/// The shading of one smoothed texel, one pixel at a time (`surface`: the secretion surface's
/// normal, NaN for none; `footprint`: the pixel's width at its depth, mm).
fn shade_pixel(
    s: &Shading,
    t: [f32; 8],
    surface: Vec3,
    tip: Vec3,
    footprint: f32,
) -> Premultiplied {
    if t[0].is_nan() {
        return Premultiplied::default();
    }
    let (p, n) = (Vec3::new(t[1], t[2], t[3]), Vec3::new(t[4], t[5], t[6]));
    let to_tip = (tip - p).normalize_or_zero();
    // At most 1, NaN kept (no secretion surface).
    let cosine = |n: Vec3| {
        let c = n.dot(to_tip).abs();
        if c > 1.0 {
            1.0
        } else {
            c
        }
    };
    let cos = cosine(n);
    let film_cos = cosine(surface);
    let film_cos = if film_cos.is_nan() { cos } else { film_cos };
    let tiles = footprint / (cos.max(MIN_FOOTPRINT_COS) * s.texture_mm);
    let lookup = |tex: &Arc<Texture>| tex.triplanar(p / s.texture_mm, n, tiles);
    let texel = s.texture.as_ref().map_or([0.5; 3], lookup);
    let fog = s.fog(t[7]);
    let film = if t[7] > 0.0 {
        smoothstep(t[7] / FILM_MM)
    } else {
        0.0
    };
    let falloff = |d: f32| {
        s.attenuation_mm.map_or(1.0, |half| {
            let r = d / half;
            1.0 / (1.0 + r * r)
        })
    };
    let near = falloff((t[0] - t[7]).max(0.0));
    let raised = (1.0 - s.wetness) * fog * near * s.wetness.min(0.5) * 2.0;
    let wet = (s.wetness + raised).clamp(0.0, 1.0);
    let darkening = |c: f32| 1.0 - wet * WET_DARKENING * (1.0 - c * c);
    let detail = texel.map(|c| 1.0 + s.texture_strength * (2.0 * c - 1.0));
    let lit = s.ambient + s.diffuse * cos;
    let tissue = Vec3::from(detail.map(|d| d * lit * darkening(cos)));
    let tissue = Vec3::from(s.tissue_color) * tissue;
    let lit = s.ambient + s.diffuse * film_cos;
    let mucus = Vec3::from(s.secretion_color) * lit;
    let map = match &s.specular_map {
        Some(m) => SPECULAR_MAP_MAX * luma(lookup(m)),
        None => SPECULAR_MAP_BASE + SPECULAR_MAP_GAIN * (1.0 - luma(texel)),
    };
    let glints = [
        highlight(s, wet * map * (1.0 - fog), cos, s.shininess),
        highlight(s, wet * FILM_GLOSS * film, film_cos, FILM_SHININESS),
    ];
    let c = (tissue * (1.0 - fog) + mucus * fog + Vec3::splat(glints[0]) + Vec3::splat(glints[1]))
        * falloff(t[0]);
    Premultiplied {
        rgb: c.min(Vec3::ONE).to_array(),
        transmittance: 0.0,
    }
}

#[test]
fn the_vectorised_deferred_stage_matches_its_scalar_form() {
    let camera = Camera::look_at(DVec3::ZERO, DVec3::Z, DVec3::Y, 70.0, [37, 45]).unwrap();
    let g = gbuffer(&camera);
    let tip = camera.eye_mm().as_vec3();
    let realistic = Shading {
        wetness: 0.6,
        texture: Texture::built_in("mucosa").map(Arc::new),
        ..Shading::default()
    };
    let plain = Shading {
        attenuation_mm: None,
        ..Shading::default()
    };
    // A colour texture and a specular map, a few mm a tile (several mip levels in use).
    let rgb = (0..48)
        .map(|i| [hash(i, 7), hash(i, 8), hash(i, 9)])
        .collect();
    let mapped = Shading {
        wetness: 0.9,
        texture: Texture::from_rgb(8, 6, rgb).ok().map(Arc::new),
        specular_map: Texture::from_luma(4, 4, (0..16).map(|i| hash(i, 10)).collect())
            .ok()
            .map(Arc::new),
        texture_mm: 3.0,
        ..Shading::default()
    };
    let cases = [(&realistic, 2), (&realistic, 0), (&plain, 3), (&mapped, 1)];
    for (shading, radius) in cases {
        let shading = Shading {
            smoothing_px: radius,
            ..shading.clone()
        };
        let frame = shade(&g, &camera, &shading).unwrap();
        let texels = smooth_by_pixel(&g, radius);
        let smoothed = smooth::smooth(&g, radius);
        let footprints = Footprints::of(&camera);
        for (i, t) in texels.iter().enumerate() {
            let surface = Vec3::from(g.secretion_normal[i]);
            let (x, y) = (i % camera.size()[0], i / camera.size()[0]);
            let footprint = footprints.row8(x, y, &[t[0]; LANES])[0];
            let expected = shade_pixel(&shading, *t, surface, tip, footprint);
            assert_eq!(frame.color[i], expected, "radius {radius}, pixel {i}");
            let same = |a: f32, b: f32| a == b || (a.is_nan() && b.is_nan());
            assert!(same(frame.depth_mm[i], t[0]), "pixel {i}");
            if radius > 0 && !t[0].is_nan() {
                assert_eq!(smoothed.texel(i), *t, "pixel {i}");
            }
        }
    }
}

#[test]
fn vectorised_texture_lookups_match_the_scalar_ones() {
    let texture = Texture::built_in("mucosa").unwrap();
    let odd = Texture::from_rgb(5, 3, (0..15).map(|i| [i as f32 / 14.0, 0.2, 0.9]).collect());
    for t in [&texture, &odd.unwrap()] {
        let [w, h] = t.size();
        for i in 0..2000 {
            let (u, v) = (40.0 * hash(i, 5) - 20.0, 40.0 * hash(i, 6) - 20.0);
            // Bilinear from the four texels around, wrapped with `rem_euclid`.
            let (x, y) = (
                u.rem_euclid(1.0) * w as f32 - 0.5,
                v.rem_euclid(1.0) * h as f32 - 0.5,
            );
            let (x0, y0) = (x.floor(), y.floor());
            let at = |i: f32, j: f32| {
                let i = (i as i64).rem_euclid(w as i64) as f32;
                let j = (j as i64).rem_euclid(h as i64) as f32;
                Vec3::from(t.sample((i + 0.5) / w as f32, (j + 0.5) / h as f32, 0))
            };
            let (fx, fy) = (x - x0, y - y0);
            let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1.0, y0) * fx;
            let bottom = at(x0, y0 + 1.0) * (1.0 - fx) + at(x0 + 1.0, y0 + 1.0) * fx;
            let expected = top * (1.0 - fy) + bottom * fy;
            let got = Vec3::from(t.sample(u, v, 0));
            assert!((got - expected).abs().max_element() < 1e-4, "({u}, {v})");
        }
    }
}
