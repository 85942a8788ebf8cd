//! One ray from the path to the wall: marched in small steps until the value crosses the
//! isovalue (from whichever side the path point is on), the crossing refined by bisection, and
//! the wall's normal taken from the volume's gradient there.

use crate::render::{Lighting, Shader};
use crate::Volume;
use glam::{DAffine3, DVec3, Vec3};

/// Steps along a ray, as a fraction of the smallest voxel spacing.
const STEP_VOX: f64 = 0.25;
/// Bisection steps refining a crossing (a 2⁻¹⁰ share of a step), then a linear interpolation.
const BISECTIONS: u32 = 10;

/// Where a ray met the wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Hit {
    /// The wall point, world mm.
    pub point: DVec3,
    /// The colour of the wall there, lit along the ray (0–1).
    pub color: Vec3,
}

/// Casts rays through one volume toward one isovalue.
#[derive(Debug, Clone, Copy)]
pub(super) struct Caster<'a> {
    volume: &'a Volume,
    voxel_from_world: DAffine3,
    step_mm: f64,
    iso: f64,
    color: Vec3,
    shader: Shader,
}

impl<'a> Caster<'a> {
    /// A caster finding `iso` (physical units) in `volume`, shading the wall `color` (0–1).
    pub fn new(volume: &'a Volume, iso: f64, color: [f32; 3]) -> Self {
        let geometry = volume.geometry();
        Self {
            volume,
            voxel_from_world: geometry.voxel_from_world(),
            step_mm: STEP_VOX * geometry.spacing_mm().min_element(),
            iso,
            color: Vec3::from(color),
            shader: Shader::new(geometry.world_from_voxel().matrix3, Lighting::default()),
        }
    }

    /// The value at world point `p`, or `None` outside the voxel centres' hull.
    fn value(&self, p: DVec3) -> Option<f64> {
        self.volume
            .sample_physical(self.voxel_from_world.transform_point3(p))
    }

    /// The first wall point on `origin + r · dir` for `r` in `(0, reach_mm]`, `dir` a unit
    /// vector: where the value first crosses the isovalue to the side the origin is not on.
    /// `None` when the ray leaves the scan or reaches no crossing.
    pub fn cast(&self, origin: DVec3, dir: DVec3, reach_mm: f64) -> Option<Hit> {
        let below = self.value(origin)? < self.iso;
        let steps = (reach_mm / self.step_mm).ceil() as usize;
        let mut near = 0.0;
        for n in 1..=steps {
            let far = (n as f64 * self.step_mm).min(reach_mm);
            if (self.value(origin + dir * far)? < self.iso) != below {
                let point = origin + dir * self.refine(origin, dir, near, far, below);
                return Some(Hit {
                    point,
                    color: self.shade(point, dir),
                });
            }
            near = far;
        }
        None
    }

    /// The crossing between `near` (on the origin's side) and `far` (past it), by bisection
    /// and a final linear interpolation.
    fn refine(&self, origin: DVec3, dir: DVec3, mut near: f64, mut far: f64, below: bool) -> f64 {
        let at = |r: f64| self.value(origin + dir * r).unwrap_or(self.iso);
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (near + far);
            if (at(mid) < self.iso) == below {
                near = mid;
            } else {
                far = mid;
            }
        }
        let (a, b) = (at(near) - self.iso, at(far) - self.iso);
        if a == b {
            return 0.5 * (near + far);
        }
        near + (far - near) * (a / (a - b)).clamp(0.0, 1.0)
    }

    /// The wall colour at `point` lit by a light along the ray `dir`, as the iso view shades
    /// its surface (Blinn-Phong with a headlight).
    fn shade(&self, point: DVec3, dir: DVec3) -> Vec3 {
        let voxel = self.voxel_from_world.transform_point3(point);
        let axis_difference = |axis: DVec3| {
            let ahead = self.volume.sample_physical(voxel + axis * 0.5);
            let behind = self.volume.sample_physical(voxel - axis * 0.5);
            ahead.zip(behind).map_or(0.0, |(a, b)| a - b)
        };
        let gradient = DVec3::new(
            axis_difference(DVec3::X),
            axis_difference(DVec3::Y),
            axis_difference(DVec3::Z),
        );
        let normal = self.shader.normal(gradient.as_vec3());
        self.shader.shade(self.color, normal, dir.as_vec3())
    }
}
