//! The B-spline reconstruction against exact fields and the analytic sphere.

use super::bspline::BSplineCoefficients;
use super::Sampler;
use crate::phantom::profile::{ramp, AIR_HU, TISSUE_HU};
use crate::phantom::{rasterize, sphere_shell, PhantomOptions};
use crate::render::{Camera, Filter, Layers, Mode, RenderOptions, RenderSettings, Renderer};
use crate::{Geometry, Modality, ValueMap, Volume};
use glam::{DVec3, Vec3};
use std::sync::Arc;

/// A `dims` volume of `field(i, j, k)` (identity value map, 1 mm voxels).
fn volume_of(dims: [usize; 3], field: impl Fn(usize, usize, usize) -> u16) -> Volume {
    let voxels = (0..dims[2])
        .flat_map(|k| (0..dims[1]).flat_map(move |j| (0..dims[0]).map(move |i| (i, j, k))))
        .map(|(i, j, k)| field(i, j, k))
        .collect();
    let g = Geometry::axis_aligned(dims, DVec3::ONE, DVec3::ZERO).unwrap();
    Volume::new(g, voxels, ValueMap::IDENTITY, Modality::Unknown).unwrap()
}

/// Positions spread over `[lo, hi]³` (a fixed low-discrepancy walk).
fn positions(lo: f32, hi: f32) -> impl Iterator<Item = Vec3> {
    (1..300).map(move |n| {
        let f = |a: f32| (n as f32 * a).fract();
        Vec3::new(f(0.754_877_7), f(0.569_840_3), f(0.618_034)) * (hi - lo) + lo
    })
}

#[test]
fn spline_reproduces_voxels_and_linear_fields() {
    // Values: the interpolating spline passes through every voxel, even of a rough volume.
    let rough = volume_of([7, 6, 5], |i, j, k| {
        ((i * 7919 + j * 613 + k * 97) % 1013) as u16
    });
    let coefficients = BSplineCoefficients::new(&rough);
    let s = Sampler::with_spline(&rough, &coefficients);
    for (n, &v) in rough.voxels().iter().enumerate() {
        let p = Vec3::new((n % 7) as f32, (n / 7 % 6) as f32, (n / 42) as f32);
        assert!((s.value(p) - f32::from(v)).abs() < 0.05, "{p} {v}");
    }
    // A linear field: values at the voxels and (the approximating spline's) gradients wherever
    // their footprint lies inside the volume, exactly; values between the voxels away from the
    // border, where the mirrored field's kink no longer rings (0.27 a voxel).
    let linear = volume_of([20, 20, 20], |i, j, k| (3 * i + 7 * j + 11 * k + 5) as u16);
    let coefficients = BSplineCoefficients::new(&linear);
    let s = Sampler::with_spline(&linear, &coefficients);
    let exact = |p: Vec3| 3.0 * p.x + 7.0 * p.y + 11.0 * p.z + 5.0;
    for p in positions(0.0, 19.0) {
        let voxel = p.round();
        assert!((s.value(voxel) - exact(voxel)).abs() < 1e-2, "{voxel}");
    }
    for p in positions(7.0, 12.0) {
        assert!((s.value(p) - exact(p)).abs() < 1e-2, "{p}");
    }
    for p in positions(1.0, 17.0) {
        let g = s.gradient(p);
        assert!((g - Vec3::new(3.0, 7.0, 11.0)).length() < 1e-3, "{p} {g}");
    }
    let flat = volume_of([5, 5, 5], |_, _, _| 700);
    let coefficients = BSplineCoefficients::new(&flat);
    let s = Sampler::with_spline(&flat, &coefficients);
    for p in positions(-2.0, 7.0) {
        assert!((s.value(p) - 700.0).abs() < 1e-3);
        assert!(s.gradient(p).length() < 1e-3);
    }
}

#[test]
fn spline_is_bounded_at_the_border() {
    // A step at the border and a one-voxel-wide axis: the spline stays within the voxels' range
    // (up to the interpolating spline's ringing at the step), and positions outside the volume
    // read the border (no extrapolation), as trilinear samples do.
    let step = volume_of([6, 1, 4], |i, _, _| if i < 3 { 0 } else { 1000 });
    let coefficients = BSplineCoefficients::new(&step);
    let s = Sampler::with_spline(&step, &coefficients);
    for p in positions(-3.0, 8.0) {
        let (v, g) = (s.value(p), s.gradient(p));
        assert!((-150.0..=1150.0).contains(&v), "{p} {v}");
        assert!(g.is_finite() && g.y.abs() < 1e-3, "{p} {g}");
        let inside = p.clamp(Vec3::ZERO, Vec3::new(5.0, 0.0, 3.0));
        assert_eq!(v, s.value(inside));
    }
    assert_eq!(s.value(Vec3::new(5.0, 0.0, 0.0)), 1000.0);
    assert!(s.value(Vec3::NAN).is_finite() && s.gradient(Vec3::NAN).is_finite());
}

/// Radius errors (RMS, voxels) and normal errors (RMS, degrees) of `sampler`'s surface at
/// `iso` against the analytic sphere of `radius` voxels about `centre`, along 400 directions.
fn sphere_errors(sampler: &Sampler<'_>, iso: f32, centre: Vec3, radius: f32) -> (f32, f32) {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let (mut r2, mut a2, n) = (0.0f32, 0.0f32, 400);
    for k in 0..n {
        let z = 1.0 - 2.0 * (k as f32 + 0.5) / n as f32;
        let (s, a) = ((1.0 - z * z).sqrt(), golden * k as f32);
        let dir = Vec3::new(s * a.cos(), s * a.sin(), z);
        // Bisection of the crossing.
        let (mut lo, mut hi) = (radius - 1.5, radius + 1.5);
        let inside = sampler.value(centre + dir * lo) > iso;
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            if (sampler.value(centre + dir * mid) > iso) == inside {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let r = 0.5 * (lo + hi);
        let normal = sampler.gradient(centre + dir * r).normalize();
        let angle = normal.dot(dir).abs().min(1.0).acos().to_degrees();
        (r2, a2) = (r2 + (r - radius).powi(2), a2 + angle * angle);
    }
    ((r2 / n as f32).sqrt(), (a2 / n as f32).sqrt())
}

/// A solid ball of tissue of `radius` voxels in air, the phantoms' edge ramp, in a `size`³
/// grid, and its centre (voxel index).
fn ball(size: usize, radius: f64) -> (Volume, Vec3) {
    let options = PhantomOptions {
        size,
        ..Default::default()
    };
    let centre = DVec3::splat(size as f64 / 2.0 - 0.5) + DVec3::new(0.13, 0.21, -0.08);
    let field = |p: DVec3| ramp(p.distance(centre) - radius, TISSUE_HU, AIR_HU);
    (rasterize([size; 3], &options, &field), centre.as_vec3())
}

#[test]
fn spline_surfaces_are_true_and_their_normals_smooth_on_spheres() {
    let (shell, truth) = sphere_shell(&PhantomOptions {
        size: 32,
        ..Default::default()
    });
    let (small, small_centre) = ball(12, 2.5);
    let cases = [
        (
            &shell,
            truth.centre_vox.as_vec3(),
            truth.inner_radius_vox as f32,
        ),
        (&small, small_centre, 2.5),
    ];
    for (volume, centre, radius) in cases {
        let iso = volume.value_map().stored_from_physical(-480.0) as f32;
        let coefficients = BSplineCoefficients::new(volume);
        let spline = Sampler::with_spline(volume, &coefficients);
        let trilinear = Sampler::new(volume);
        let (r_spline, a_spline) = sphere_errors(&spline, iso, centre, radius);
        let (r_tri, a_tri) = sphere_errors(&trilinear, iso, centre, radius);
        // Measured: radius 11.2: 0.017 vs 0.016 voxel, 0.66° vs 2.2°; radius 2.5: 0.016 vs
        // 0.072 voxel, 0.6° vs 1.7°.
        assert!(
            r_spline < 0.03 && r_spline < r_tri + 0.005,
            "{r_spline} {r_tri}"
        );
        assert!(
            a_spline < 0.5 * a_tri && a_spline < 1.0,
            "{a_spline}° {a_tri}°"
        );
    }
}

#[test]
fn spline_stills_shade_a_coarse_ball_without_facets() {
    // A ball of 3.5 voxels' radius seen whole. Inside its disc (normals within 60° of the
    // view), the rendered normals' error against the analytic sphere's and the shading's
    // high-frequency energy (the squared Laplacian of the luminance, which the smooth diffuse
    // shading of a true sphere all but lacks) measure the trilinear facets.
    let (volume, centre) = ball(12, 3.5);
    let centre_mm = volume.geometry().world_of(centre.as_dvec3());
    let renderer = Arc::new(Renderer::new(volume));
    let mut settings = RenderSettings {
        mode: Mode::Iso,
        iso_hu: -480.0,
        ..Default::default()
    };
    settings.lighting.specular = 0.0;
    let prepared = renderer.prepare(&settings).unwrap();
    let eye = centre_mm + DVec3::new(0.3, -0.4, -14.0);
    let camera = Camera::look_at(eye, centre_mm, DVec3::Y, 40.0, [48, 48]).unwrap();
    let measure = |filter| {
        let mut frame = crate::render::Frame::default();
        let options = RenderOptions::new().filter(filter).layers(Layers::NORMAL);
        prepared.render_with(&camera, &options, &mut frame).unwrap();
        // The analytic sphere's normal where pixel `i`'s ray meets it.
        let truth = |x: usize, y: usize| {
            let ray = camera.pixel_ray(x, y)?;
            let to_centre = centre_mm - ray.origin;
            let along = to_centre.dot(ray.dir);
            let miss2 = to_centre.length_squared() - along * along;
            let t = along - (3.5f64.powi(2) - miss2).max(0.0).sqrt();
            let n = ((ray.origin + ray.dir * t - centre_mm) / 3.5).as_vec3();
            (n.dot(-ray.dir.as_vec3()) > 0.5).then_some(n)
        };
        let lum = |x: usize, y: usize| frame.color[x + 48 * y].rgb.iter().sum::<f32>();
        let (mut angle2, mut energy, mut count) = (0.0, 0.0, 0usize);
        for y in 1..47 {
            for x in 1..47 {
                let Some(n) = truth(x, y) else { continue };
                let normal = Vec3::from(frame.normal[x + 48 * y]);
                angle2 += normal.dot(n).abs().min(1.0).acos().to_degrees().powi(2);
                let near = lum(x - 1, y) + lum(x + 1, y) + lum(x, y - 1) + lum(x, y + 1);
                energy += (near - 4.0 * lum(x, y)).powi(2);
                count += 1;
            }
        }
        let n = count as f32;
        ((angle2 / n).sqrt(), energy / n, count)
    };
    let (a_tri, e_tri, count) = measure(Filter::Trilinear);
    let (a_spline, e_spline, _) = measure(Filter::BSpline);
    assert!(count > 300, "{count}");
    // Measured: 0.77° vs 2.7°, 0.56 of the energy (the rest is the true sphere's shading).
    assert!(a_spline < 0.5 * a_tri, "{a_spline}° {a_tri}°");
    assert!(e_spline < 0.7 * e_tri, "{e_spline} {e_tri}");
}
