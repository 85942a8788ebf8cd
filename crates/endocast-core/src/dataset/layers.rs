//! One frame's training layers from its camera and its depth along each ray: the depth along
//! the view axis, the wall's unit normals in the OpenCV camera frame (from the volume's
//! gradient at each hit, turned toward the camera) and the structure mask; and the 16-bit
//! quantisation of a depth image.

use crate::camera::Camera;
use crate::render::{Lighting, Sampler, Shader};
use crate::Volume;

/// Largest code of a 16-bit depth image; code 0 means "no wall".
pub const DEPTH_CODES: u16 = u16::MAX;

/// One frame's layers, row 0 at the top; NaN where the pixel sees no wall.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameLayers {
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Distance from the eye along each pixel's ray to the wall, mm.
    pub depth_ray_mm: Vec<f32>,
    /// The hit's coordinate along the view axis (OpenCV z), mm; NaN also where it is not in
    /// front of the eye (a fisheye's rays beyond 90°).
    pub depth_z_mm: Vec<f32>,
    /// Unit normal of the wall at the hit in the OpenCV camera frame (x right, y down,
    /// z forward), facing the camera.
    pub normal_camera: Vec<[f32; 3]>,
}

impl FrameLayers {
    /// The layers of a frame of `volume` seen by `camera`, whose depth along each ray is
    /// `depth_mm` (NaN where none; `width·height` values, as a rendered frame holds them).
    pub fn new(camera: &Camera, depth_mm: &[f32], volume: &Volume) -> Self {
        let [width, height] = camera.size();
        let sampler = Sampler::new(volume);
        let geometry = volume.geometry();
        let shader = Shader::new(geometry.world_from_voxel().matrix3, Lighting::default());
        let voxel_from_world = geometry.voxel_from_world();
        let axes = [camera.right(), -camera.up(), camera.forward()];
        let mut layers = Self {
            width,
            height,
            depth_ray_mm: depth_mm.to_vec(),
            depth_z_mm: vec![f32::NAN; depth_mm.len()],
            normal_camera: vec![[f32::NAN; 3]; depth_mm.len()],
        };
        for (i, &depth) in depth_mm.iter().enumerate() {
            let ray = camera.pixel_ray(i % width.max(1), i / width.max(1));
            let (Some(ray), true) = (ray, depth.is_finite()) else {
                continue;
            };
            let z = ray.dir.dot(camera.forward()) * f64::from(depth);
            if z > 0.0 {
                layers.depth_z_mm[i] = z as f32;
            }
            let hit_vox = voxel_from_world.transform_point3(ray.at(f64::from(depth)));
            let world = shader
                .normal(sampler.gradient(hit_vox.as_vec3()))
                .as_dvec3();
            let facing = if world.dot(ray.dir) > 0.0 {
                -world
            } else {
                world
            };
            layers.normal_camera[i] = axes.map(|axis| facing.dot(axis) as f32);
        }
        layers
    }

    /// The structure mask: 255 where the pixel sees the wall, 0 elsewhere.
    pub fn mask(&self) -> Vec<u8> {
        self.depth_ray_mm
            .iter()
            .map(|d| if d.is_finite() { 255 } else { 0 })
            .collect()
    }

    /// The normals as 8-bit RGB, `(n + 1) / 2 · 255` per component; black where no wall.
    pub fn normals_rgb8(&self) -> Vec<u8> {
        self.normal_camera
            .iter()
            .flat_map(|n| {
                n.map(|c| match c.is_finite() {
                    true => ((c + 1.0) * 0.5 * 255.0).round().clamp(0.0, 255.0) as u8,
                    false => 0,
                })
            })
            .collect()
    }
}

/// The scale of a 16-bit depth image that holds depths up to `range_mm`: the smallest of
/// 1, 2 or 5 × 10ⁿ mm per code with `range_mm / scale ≤` [`DEPTH_CODES`] − 1 (e.g. 0.01 mm for
/// up to 655 mm). `range_mm` must be positive and finite.
pub fn depth_scale_mm(range_mm: f64) -> f64 {
    let least = range_mm.max(f64::MIN_POSITIVE) / f64::from(DEPTH_CODES - 1);
    let decade = 10f64.powf(least.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|s| *s >= least)
        .unwrap_or(10.0 * decade)
}

/// `depth_mm` as 16-bit codes of `scale_mm` each (rounded): 0 where NaN, at least 1 for a
/// wall, saturated at [`DEPTH_CODES`] beyond the range.
pub fn depth_to_u16(depth_mm: &[f32], scale_mm: f64) -> Vec<u16> {
    depth_mm
        .iter()
        .map(|&d| match d.is_finite() {
            true => (f64::from(d) / scale_mm)
                .round()
                .clamp(1.0, f64::from(DEPTH_CODES)) as u16,
            false => 0,
        })
        .collect()
}
