//! How wide a pixel is on a surface facing the eye: `mm + rad · depth` (the width of its ray
//! bundle where it leaves the camera, and its angle), as [`Camera::ray`] defines the pixel's
//! ray in every projection (pinhole, fisheye, orthographic) with the lens's distortion. Both
//! depend only on the distance from the image's centre, so they are tabulated once per frame
//! over the squared radius; the deferred stage reads the texture's mip level from it.

use super::lanes::{map, Lanes, LANES};
use crate::camera::{Camera, Ray};

/// Entries of the table, over the squared radius from the centre to the farthest corner.
const ENTRIES: usize = 256;

/// A camera's pixel footprints by distance from the image centre.
pub(super) struct Footprints {
    /// The image centre, pixels.
    centre: [f32; 2],
    /// Entries per squared pixel of radius.
    per_r2: f32,
    /// Width of a pixel's rays at their start, mm (orthographic: the pixel's spacing).
    mm: Vec<f32>,
    /// Angle between neighbouring pixels' rays, radians (the larger of radial and tangential).
    rad: Vec<f32>,
}

impl Footprints {
    /// The table of `camera`: at radii along the image's horizontal centre line, the rays half
    /// a pixel either side, radially (along the line) and tangentially (across it). Where the
    /// lens forms no image (outside a fisheye's circle) the last entry with one is kept.
    pub fn of(camera: &Camera) -> Self {
        let [w, h] = camera.size().map(|e| e as f64);
        let (cx, cy) = (0.5 * w, 0.5 * h);
        let max_r2 = (cx * cx + cy * cy).max(1.0);
        let (mut mm, mut rad) = (vec![0.0f32; ENTRIES], vec![0.0f32; ENTRIES]);
        for e in 0..ENTRIES {
            let r = (e as f64 / (ENTRIES - 1) as f64 * max_r2).sqrt();
            let offsets = [(-0.5, 0.0), (0.5, 0.0), (0.0, -0.5), (0.0, 0.5)];
            let rays = offsets.map(|(dx, dy)| camera.ray(cx + r + dx, cy + dy));
            match rays {
                [Some(left), Some(right), Some(up), Some(down)] => {
                    let apart =
                        |a: Ray, b: Ray| (a.origin.distance(b.origin), a.dir.angle_between(b.dir));
                    let ((m0, a0), (m1, a1)) = (apart(left, right), apart(up, down));
                    (mm[e], rad[e]) = (m0.max(m1) as f32, a0.max(a1) as f32);
                }
                _ if e > 0 => (mm[e], rad[e]) = (mm[e - 1], rad[e - 1]),
                _ => {}
            }
        }
        Self {
            centre: [cx as f32, cy as f32],
            per_r2: ((ENTRIES - 1) as f64 / max_r2) as f32,
            mm,
            rad,
        }
    }

    /// The footprints, mm, of pixels `x0 ..` of row `y` at `depth` mm along their rays.
    #[inline(always)]
    pub fn row8(&self, x0: usize, y: usize, depth: &Lanes) -> Lanes {
        let dy = y as f32 + 0.5 - self.centre[1];
        let entry = map(|k| {
            let dx = (x0 + k) as f32 + 0.5 - self.centre[0];
            ((dx * dx + dy * dy) * self.per_r2 + 0.5).min((ENTRIES - 1) as f32)
        });
        let mut out = [0.0; LANES];
        for (k, o) in out.iter_mut().enumerate() {
            let e = (entry[k] as usize).min(ENTRIES - 1);
            *o = self.mm[e] + self.rad[e] * depth[k];
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{Lens, Projection};
    use glam::DVec3;

    /// The footprint of pixel `(x, y)` at `depth` mm measured directly: the larger distance
    /// between the points at that depth half a pixel either side, toward the centre and across.
    fn measured(camera: &Camera, x: usize, y: usize, depth: f64) -> f64 {
        let at = |x: f64, y: f64| camera.ray(x, y).map(|r| r.at(depth));
        let (xc, yc) = (x as f64 + 0.5, y as f64 + 0.5);
        let [w, h] = camera.size().map(|e| e as f64);
        let (dx, dy) = (xc - 0.5 * w, yc - 0.5 * h);
        let r = dx.hypot(dy).max(1e-9);
        [(dx / r, dy / r), (-dy / r, dx / r)]
            .into_iter()
            .filter_map(|(dx, dy)| {
                let q = at(xc + 0.5 * dx, yc + 0.5 * dy)?;
                Some(at(xc - 0.5 * dx, yc - 0.5 * dy)?.distance(q))
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn footprints_match_neighbouring_rays_in_every_projection() {
        let base = Camera::look_at(DVec3::ZERO, DVec3::Z, DVec3::Y, 90.0, [96, 64]).unwrap();
        let cameras = [
            base,
            base.with_projection(Projection::Equidistant, 160.0)
                .unwrap(),
            base.with_projection(Projection::Equisolid, 120.0).unwrap(),
            base.with_projection(Projection::Orthographic, 30.0)
                .unwrap(),
            base.with_lens(Lens {
                distortion: [-0.2, 0.0],
                vignetting: 0.0,
            })
            .unwrap(),
        ];
        for camera in &cameras {
            let table = Footprints::of(camera);
            for (x, y) in [(48, 32), (60, 40), (20, 10), (90, 33), (47, 5)] {
                let depth = 25.0;
                if camera.pixel_ray(x, y).is_none() {
                    continue;
                }
                let got = table.row8(x, y, &[depth as f32; LANES])[0];
                let want = measured(camera, x, y, depth);
                let projection = camera.projection();
                assert!(
                    (f64::from(got) / want - 1.0).abs() < 0.08,
                    "{projection:?} ({x}, {y}): {got} mm, measured {want}"
                );
            }
        }
    }
}
