//! Where the view starts inside the tissue — the eye, or the near plane (`--near`), placed in the
//! wall — and the colour overlay that says so (Krüger et al. §4.4: "a final color overlay is
//! performed when the tissue is being clipped"). The rays of those pixels still show the surface
//! beyond, tinted: the surgeon sees both that the tissue is cut and what lies behind it.

use super::settings::RayPassSettings;
use crate::camera::Camera;
use crate::render::{Frame, Renderer};
use glam::DVec3;
use rayon::prelude::*;

/// The overlay's colour: a cool blue that no mucosa, mucus or light at the tip produces.
pub(super) const CLIPPED_COLOR: [f32; 3] = [0.25, 0.5, 0.95];

/// Share of the overlay's colour in a clipped pixel.
pub(super) const CLIPPED_SHARE: f32 = 0.5;

/// Per pixel of `camera` (row 0 at the top), whether its ray starts inside the tissue: the
/// value at the ray's first point (on the near plane or sphere, else the eye) lies on the
/// tissue's side of the tissue threshold, the side away from the secretion threshold (which
/// lies toward the lumen). Empty when no pixel's ray does, or none starts inside the volume.
pub(super) fn clipped_pixels(
    renderer: &Renderer,
    camera: &Camera,
    settings: &RayPassSettings,
) -> Vec<bool> {
    let volume = renderer.volume();
    let map = volume.value_map();
    let tissue = map.stored_from_physical(settings.tissue_hu) as f32;
    let rising = tissue > map.stored_from_physical(settings.secretion_hu) as f32;
    let voxel_from_world = volume.geometry().voxel_from_world();
    let extent = volume.dims().map(|n| (n - 1) as f64);
    let sampler = renderer.sampler();
    let in_tissue = |start: DVec3| {
        let p = voxel_from_world.transform_point3(start);
        let within = (0..3).all(|a| (0.0..=extent[a]).contains(&p[a]));
        within && {
            let value = sampler.value(p.as_vec3());
            (value >= tissue) == rising
        }
    };
    // Without a near plane every ray starts at the shared eye: one sample says for all.
    let shared_start = camera.shared_origin().filter(|_| camera.near_mm() == 0.0);
    if shared_start.is_some_and(|eye| !in_tissue(eye)) {
        return Vec::new();
    }
    let [w, h] = camera.size();
    let inside = |x: usize, y: usize| {
        let Some(ray) = camera.pixel_ray(x, y) else {
            return false;
        };
        in_tissue(ray.at(camera.near_distance_along(ray.dir)))
    };
    let clipped: Vec<bool> = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| inside(x, y))
        .collect();
    if clipped.contains(&true) {
        clipped
    } else {
        Vec::new()
    }
}

/// Lays the overlay over the pixels of `frame` that `clipped` marks (none when it is empty):
/// [`CLIPPED_SHARE`] of [`CLIPPED_COLOR`], opaque.
pub(super) fn overlay(frame: &mut Frame, clipped: &[bool]) {
    if clipped.is_empty() {
        return;
    }
    frame
        .color
        .par_iter_mut()
        .zip(clipped)
        .filter(|(_, clipped)| **clipped)
        .for_each(|(p, _)| {
            for (c, overlay) in p.rgb.iter_mut().zip(CLIPPED_COLOR) {
                *c += CLIPPED_SHARE * (overlay - *c);
            }
            p.transmittance = 0.0;
        });
}
