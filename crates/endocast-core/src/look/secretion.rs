//! A ray carried on from its first secretion hit to the tissue (Krüger et al., Figure 3): a
//! march at a small step to the tissue threshold, refined by bisection, with the secretion
//! measured on the way.

use super::settings::{RayPassSettings, SecretionMode};
use crate::render::traverse::VoxelRay;
use crate::render::{Lighting, Renderer, Sampler, Shader};
use glam::{DAffine3, DVec3};

/// Bisection steps refining the tissue hit (then linear interpolation in the last bracket):
/// 1/64 of a small step, far below the 0.1 voxel the secretion must be measured to.
const REFINE_STEPS: u32 = 6;

/// The tissue behind a secretion hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TissueHit {
    /// Distance from the ray's start to the tissue, mm.
    pub depth_mm: f32,
    /// World position of the hit, mm.
    pub hit_mm: [f32; 3],
    /// Unit world normal, up the value gradient.
    pub normal: [f32; 3],
    /// Secretion in front of the tissue, mm.
    pub secretion_mm: f32,
}

/// Everything a continuation needs, shared by the rays of a frame.
pub(crate) struct Continuation<'a> {
    sampler: Sampler<'a>,
    voxel_from_world: DAffine3,
    extent: DVec3,
    shader: Shader,
    /// The thresholds in stored units.
    tissue: f32,
    secretion: f32,
    /// Whether the value rises from the secretion into the tissue.
    rising: bool,
    step_mm: f32,
    accumulate: bool,
}

impl<'a> Continuation<'a> {
    /// The continuation of rays traced to the secretion threshold over `renderer`'s volume
    /// with `settings`.
    pub fn new(renderer: &'a Renderer, settings: &RayPassSettings) -> Self {
        let volume = renderer.volume();
        let geometry = volume.geometry();
        let map = volume.value_map();
        let stored = |hu: f64| map.stored_from_physical(hu) as f32;
        let (tissue, secretion) = (stored(settings.tissue_hu), stored(settings.secretion_hu));
        let dims = volume.dims();
        let step_vox = settings.secretion_step_vox;
        Self {
            sampler: renderer.sampler(),
            voxel_from_world: geometry.voxel_from_world(),
            extent: DVec3::from(dims.map(|n| (n - 1) as f64)),
            shader: Shader::new(geometry.world_from_voxel().matrix3, Lighting::default()),
            tissue,
            secretion,
            rising: tissue > secretion,
            step_mm: (step_vox * geometry.spacing_mm().min_element()) as f32,
            accumulate: settings.secretion == SecretionMode::Accumulate,
        }
    }

    /// The tissue behind the secretion hit `t_secretion_mm` along the world ray from `origin`
    /// along unit `dir`; `None` where there is no secretion hit (NaN) or the ray leaves the
    /// volume before the tissue.
    pub fn tissue_after(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_secretion_mm: f32,
    ) -> Option<TissueHit> {
        if t_secretion_mm.is_nan() {
            return None;
        }
        let ray = VoxelRay::new(&self.voxel_from_world, origin, dir);
        let (_, t_end) = ray.clip(self.extent, 0.0)?;
        let (o, d) = (ray.origin.as_vec3(), ray.direction.as_vec3());
        let value = |t: f32| self.sampler.value(o + d * t);
        let (mut t, mut v) = (t_secretion_mm, value(t_secretion_mm));
        let mut inside = 0.0;
        loop {
            let t_next = t + self.step_mm;
            if f64::from(t_next) > t_end {
                return None;
            }
            let v_next = value(t_next);
            if self.past(v_next, self.tissue) {
                let t_hit = self.refine(&value, (t, v), (t_next, v_next));
                inside += self.inside_secretion((t, v), (t_hit, self.tissue));
                let secretion_mm = if self.accumulate {
                    inside
                } else {
                    t_hit - t_secretion_mm
                };
                let p = o + d * t_hit;
                let normal = self.shader.normal(self.sampler.gradient(p));
                let hit = origin + dir * f64::from(t_hit);
                return Some(TissueHit {
                    depth_mm: t_hit,
                    hit_mm: hit.as_vec3().to_array(),
                    normal: normal.to_array(),
                    secretion_mm,
                });
            }
            if self.accumulate {
                inside += self.inside_secretion((t, v), (t_next, v_next));
            }
            (t, v) = (t_next, v_next);
        }
    }

    /// Whether stored value `v` lies past threshold `iso` on the tissue's side.
    #[inline]
    fn past(&self, v: f32, iso: f32) -> bool {
        (v >= iso) == self.rising
    }

    /// The length of the stretch from `(t0, v0)` to `(t1, v1)` past the secretion threshold,
    /// the value taken as linear between them.
    fn inside_secretion(&self, (t0, v0): (f32, f32), (t1, v1): (f32, f32)) -> f32 {
        let s = self.secretion;
        match (self.past(v0, s), self.past(v1, s)) {
            (true, true) => t1 - t0,
            (false, false) => 0.0,
            (in0, _) => {
                let f = ((s - v0) / (v1 - v0)).clamp(0.0, 1.0);
                if in0 {
                    f * (t1 - t0)
                } else {
                    (1.0 - f) * (t1 - t0)
                }
            }
        }
    }

    /// The tissue crossing inside the bracket `before`–`after`: bisection, then linear
    /// interpolation in the last bracket.
    fn refine(
        &self,
        value: &impl Fn(f32) -> f32,
        mut before: (f32, f32),
        mut after: (f32, f32),
    ) -> f32 {
        for _ in 0..REFINE_STEPS {
            let t = 0.5 * (before.0 + after.0);
            let v = value(t);
            if self.past(v, self.tissue) {
                after = (t, v);
            } else {
                before = (t, v);
            }
        }
        let (dv, iso) = (after.1 - before.1, self.tissue);
        let f = if dv == 0.0 {
            1.0
        } else {
            ((iso - before.1) / dv).clamp(0.0, 1.0)
        };
        before.0 + f * (after.0 - before.0)
    }
}
