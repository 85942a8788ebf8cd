//! Image-based lighting: the paper's alternative to Phong ("Illumination is performed using
//! standard Phong lighting or image-based lighting, using 2D textures", Krüger et al. §4.4,
//! after Winnemöller & Bangay 2002). The diffuse light of a surface point is looked up in a
//! *lit sphere* — a square image of a ball lit as the tissue should be — at the point where the
//! ball's normal is the surface's, seen from the endoscope's tip: the image's centre faces the
//! tip, its rim is the silhouette, its right and up are the camera's.
//!
//! The view frame is taken per pixel (its `z` from the surface point to the tip, `x` the
//! camera's right made perpendicular to it), so a wall facing the tip reads the centre of the
//! image anywhere in a wide field, as the light at the tip lights it. Only the diffuse term
//! comes from the map; the wet highlights stay the specular model's (see [`super::Shading`]).

use super::lanes::{map, map3, Lanes};
use super::texture::{Texture, TextureError};
use crate::camera::Camera;
use glam::Vec3;
use std::sync::Arc;
use thiserror::Error;

/// Edge of the built-in lit sphere, texels.
const BUILT_IN_TEXELS: usize = 128;
/// The built-in lit sphere's light where nothing faces the tip (as Phong's ambient).
const BUILT_IN_AMBIENT: f32 = 0.12;
/// How far the built-in's diffuse light wraps past the terminator (light scattered under the
/// wet mucosa softens it), in cosines.
const BUILT_IN_WRAP: f32 = 0.25;
/// The built-in's soft rim: light the narrow cavity scatters back onto surfaces seen edge-on.
const BUILT_IN_RIM: f32 = 0.15;

/// A lit sphere that cannot be used.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum LitSphereError {
    /// The image is not square.
    #[error("a lit sphere is a square image of a lit ball, not {0}×{1} pixels")]
    NotSquare(usize, usize),
    /// The image's values cannot be a texture.
    #[error(transparent)]
    Texture(#[from] TextureError),
}

/// How the deferred stage lights the tissue.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Lighting {
    /// Phong: ambient plus diffuse by the cosine with the light at the tip. The default.
    #[default]
    Phong,
    /// Image-based: the diffuse light from a [`LitSphere`].
    LitSphere(Arc<LitSphere>),
}

impl Lighting {
    /// Image-based lighting with the built-in lit sphere ([`LitSphere::built_in`]).
    pub fn built_in_ibl() -> Self {
        Self::LitSphere(Arc::new(LitSphere::built_in()))
    }

    /// The name: `phong` or `ibl`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Phong => "phong",
            Self::LitSphere(_) => "ibl",
        }
    }
}

/// A lit sphere: a square greyscale image of a lit ball (its inscribed disc; the corners are
/// not read), 0 dark – 1 the full light.
#[derive(Debug, Clone, PartialEq)]
pub struct LitSphere {
    map: Texture,
}

impl LitSphere {
    /// The lit sphere in `map`, which must be square.
    pub fn new(map: Texture) -> Result<Self, LitSphereError> {
        let [w, h] = map.size();
        if w != h {
            return Err(LitSphereError::NotSquare(w, h));
        }
        Ok(Self { map })
    }

    /// The lit sphere of `n × n` texels of one `value` (a light that ignores the normal).
    pub fn uniform(n: usize, value: f32) -> Result<Self, LitSphereError> {
        Self::new(Texture::from_luma(n, n, vec![value; n * n])?)
    }

    /// An endoscope's lit sphere: the light at the tip, full where the surface faces it and
    /// wrapping softly past the terminator (`0.12 + 0.88 · (cos + 0.25) / 1.25`), plus a soft
    /// rim toward the silhouette (`0.15 · sin⁴`). Brightest at the centre, falling monotonically
    /// to about 0.45 at the rim.
    pub fn built_in() -> Self {
        let n = BUILT_IN_TEXELS;
        let texels = (0..n * n)
            .map(|i| {
                let at = |c: usize| (2.0 * c as f32 + 1.0) / n as f32 - 1.0;
                let sin2 = (at(i % n).powi(2) + at(i / n).powi(2)).min(1.0);
                let cos = (1.0 - sin2).sqrt();
                let wrapped = (cos + BUILT_IN_WRAP) / (1.0 + BUILT_IN_WRAP);
                let light = BUILT_IN_AMBIENT + (1.0 - BUILT_IN_AMBIENT) * wrapped;
                (light + BUILT_IN_RIM * sin2 * sin2).min(1.0)
            })
            .collect();
        let map = Texture::from_luma(n, n, texels).expect("the built-in lit sphere's texels");
        Self { map }
    }

    /// The light at a normal whose components along the view's right and up are `(x, y)`
    /// (`x² + y² ≤ 1`; the disc's centre faces the tip).
    pub fn light(&self, x: f32, y: f32) -> f32 {
        let [n, _] = self.map.size();
        // The disc's rim on the outermost texels' centres: the lookup never wraps.
        let scale = 0.5 * (1.0 - 1.0 / n as f32);
        let r = x.hypot(y).max(1.0);
        // A grey map: its three channels are equal; level 0, the map itself.
        self.map.sample(0.5 + scale * x / r, 0.5 - scale * y / r, 0)[0]
    }

    /// The light of eight surface points with unit normals `normal` (either side) and unit
    /// directions `to_tip` toward the tip, in `view`'s per-pixel frame (see the module doc).
    #[inline(always)]
    pub(super) fn light8(&self, normal: &[Lanes; 3], to_tip: &[Lanes; 3], view: &TipView) -> Lanes {
        map(|k| {
            let z = Vec3::new(to_tip[0][k], to_tip[1][k], to_tip[2][k]);
            let n = Vec3::new(normal[0][k], normal[1][k], normal[2][k]);
            let n = if n.dot(z) < 0.0 { -n } else { n };
            // x: the camera's right made perpendicular to z (its up where right is along z).
            let x = (view.right - z * z.dot(view.right)).try_normalize();
            let x = x.unwrap_or_else(|| (view.up - z * z.dot(view.up)).normalize_or_zero());
            let y = z.cross(x);
            // No hit (NaN) gives any value: the lane is not shown.
            self.light(n.dot(x), n.dot(y))
        })
    }
}

/// The endoscope's tip as the deferred stage lights from it: where its light is and the
/// camera's right and up (the lit sphere's axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct TipView {
    /// The light's position, world mm.
    pub at: Vec3,
    /// The camera's right, world.
    pub right: Vec3,
    /// The camera's up, world.
    pub up: Vec3,
}

impl TipView {
    /// The tip of `camera`.
    pub fn of(camera: &Camera) -> Self {
        Self {
            at: camera.eye_mm().as_vec3(),
            right: camera.right().as_vec3(),
            up: camera.up().as_vec3(),
        }
    }
}

/// `normal` where it is a normal, else `fallback` (lane by lane; NaN: none).
#[inline(always)]
pub(super) fn or_normal(normal: &[Lanes; 3], fallback: &[Lanes; 3]) -> [Lanes; 3] {
    map3(|a, k| {
        if normal[0][k].is_nan() {
            fallback[a][k]
        } else {
            normal[a][k]
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_faces_the_tip_brightest_and_a_uniform_one_is_uniform() {
        let sphere = LitSphere::built_in();
        let centre = sphere.light(0.0, 0.0);
        assert!((centre - 1.0).abs() < 0.01, "{centre}");
        let mut last = centre;
        for r in [0.3, 0.6, 0.9, 1.0] {
            let l = sphere.light(r, 0.0);
            assert!(l < last, "{r}: {l}");
            assert!((sphere.light(0.0, -r) - l).abs() < 0.01);
            last = l;
        }
        assert!(last > 0.3 && last < 0.6, "{last}");
        let flat = LitSphere::uniform(8, 0.7).unwrap();
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (-0.6, 0.7), (5.0, 5.0)] {
            // Texels are stored in 8 bits: 0.7 is 179/255.
            assert!((flat.light(x, y) - 0.7).abs() < 0.5 / 255.0 + 1e-6);
        }
        let wide = Texture::from_luma(4, 2, vec![0.5; 8]).unwrap();
        assert_eq!(LitSphere::new(wide), Err(LitSphereError::NotSquare(4, 2)));
    }

    #[test]
    fn the_view_frame_follows_the_camera() {
        // A sphere whose top-right texels are bright: a normal up and right of the view lit.
        let n = 16;
        let texels = (0..n * n)
            .map(|i| {
                if i % n >= n / 2 && i / n < n / 2 {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        let sphere = LitSphere::new(Texture::from_luma(n, n, texels).unwrap()).unwrap();
        let view = TipView {
            at: Vec3::ZERO,
            right: Vec3::X,
            up: Vec3::Y,
        };
        let lanes = |v: Vec3| v.to_array().map(|c| [c; 8]);
        let to_tip = lanes(Vec3::new(0.0, 0.0, 1.0));
        let up_right = lanes(Vec3::new(0.5, 0.5, 0.7).normalize());
        let down_left = lanes(Vec3::new(-0.5, -0.5, -0.7).normalize());
        assert_eq!(sphere.light8(&up_right, &to_tip, &view)[0], 1.0);
        // The same normal given from its other side: turned toward the tip, up and right again.
        assert_eq!(sphere.light8(&down_left, &to_tip, &view)[0], 1.0);
        let left = lanes(Vec3::new(-0.5, 0.5, 0.7).normalize());
        assert_eq!(sphere.light8(&left, &to_tip, &view)[0], 0.0);
    }
}
