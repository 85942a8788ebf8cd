//! A ray carried on from its first secretion hit to the tissue (Krüger et al., Figure 3): a
//! march at a small step to the tissue threshold, refined by bisection, with the secretion
//! measured on the way.

use super::settings::{RayPassSettings, SecretionMode};
use crate::render::traverse::VoxelRay;
use crate::render::{Lighting, Renderer, Sampler, Shader};
use glam::{DAffine3, DVec3, Vec3};

/// Bisection steps refining the tissue hit (then linear interpolation in the last bracket):
/// 1/16 of a small step (1/64 voxel at the default quarter voxel; the renderer's own surfaces
/// stop at 1/32 voxel), far below the 0.1 voxel the secretion must be measured to.
const REFINE_STEPS: u32 = 4;

/// A last stretch into the tissue up to this many times a bare edge's crossing of the band
/// between the thresholds is the tissue's own edge, not secretion (a Gaussian-blurred edge
/// takes about 0.9 of the linear estimate).
const EDGE_MAX: f32 = 1.2;

/// From this many times a bare edge's crossing on, the last stretch is all secretion (the
/// layered phantom's thinnest layer, 3 voxels between two 2-voxel ramps, takes 1.56).
const LAYER_MIN: f32 = 1.5;

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

    /// The tissue behind the secretion hits of up to eight rays at once (one per lane, each
    /// sample batch one AVX2 gather where the CPU has it): ray `k` starts at world `origin`
    /// along unit `dir` and met the secretion `t_secretion_mm` along it. A lane is `None`
    /// where its ray is missing, has no secretion hit (NaN), or leaves the volume before the
    /// tissue. Each lane takes the samples a one-ray march would: the same positions, values
    /// and bisection, so the result does not depend on its neighbours.
    pub fn tissue_after8(&self, rays: &[Option<(DVec3, DVec3, f32)>]) -> [Option<TissueHit>; 8] {
        debug_assert!(rays.len() <= 8);
        let mut lanes = Lanes8::default();
        for (k, ray) in rays.iter().enumerate() {
            lanes.start(k, self.lane(*ray));
        }
        lanes.v = self.values(&lanes, &lanes.t);
        self.march(&mut lanes);
        let t_hit = self.refine(&lanes);
        let points: [Vec3; 8] = std::array::from_fn(|k| lanes.o[k] + lanes.d[k] * t_hit[k]);
        let gradients = self.sampler.gradients8(&points);
        std::array::from_fn(|k| {
            let (origin, dir, t_secretion) = lanes.found[k].then_some(rays[k]?)?;
            let t_hit = t_hit[k];
            let measured = if self.accumulate {
                lanes.inside[k] + self.inside_secretion(lanes.before[k], (t_hit, self.tissue))
            } else {
                t_hit - t_secretion
            };
            let edge = t_hit - lanes.entered[k];
            let slope = gradients[k].dot(lanes.d[k]);
            let secretion_mm = (measured - self.own_edge(edge, slope)).max(0.0);
            let hit = origin + dir * f64::from(t_hit);
            Some(TissueHit {
                depth_mm: t_hit,
                hit_mm: hit.as_vec3().to_array(),
                normal: self.shader.normal(gradients[k]).to_array(),
                secretion_mm,
            })
        })
    }

    /// A lane's voxel ray (origin, direction), its start and the end of its march; `None`
    /// without a ray, a secretion hit, or a stretch inside the volume.
    fn lane(&self, ray: Option<(DVec3, DVec3, f32)>) -> Option<(Vec3, Vec3, f32, f64)> {
        let (origin, dir, t_secretion_mm) = ray?;
        if t_secretion_mm.is_nan() {
            return None;
        }
        let ray = VoxelRay::new(&self.voxel_from_world, origin, dir);
        let (_, t_end) = ray.clip(self.extent, 0.0)?;
        let (o, d) = (ray.origin.as_vec3(), ray.direction.as_vec3());
        Some((o, d, t_secretion_mm, t_end))
    }

    /// The values at distances `t` along the lanes' rays (idle lanes read the origin).
    fn values(&self, lanes: &Lanes8, t: &[f32; 8]) -> [f32; 8] {
        let mut xyz = [[0.0f32; 8]; 3];
        for k in 0..8 {
            let p = lanes.o[k] + lanes.d[k] * t[k];
            (xyz[0][k], xyz[1][k], xyz[2][k]) = (p.x, p.y, p.z);
        }
        self.sampler.points8(&xyz)
    }

    /// Steps every marching lane on at the small step until it passes the tissue threshold
    /// (found, bracketed by `before` and `after`) or leaves the volume.
    fn march(&self, lanes: &mut Lanes8) {
        while lanes.marching.iter().any(|m| *m) {
            let t_next: [f32; 8] = std::array::from_fn(|k| lanes.t[k] + self.step_mm);
            for (k, t) in t_next.iter().enumerate() {
                if lanes.marching[k] && f64::from(*t) > lanes.t_end[k] {
                    lanes.marching[k] = false;
                }
            }
            let v_next = self.values(lanes, &t_next);
            for k in 0..8 {
                if !lanes.marching[k] {
                    continue;
                }
                let (here, next) = ((lanes.t[k], lanes.v[k]), (t_next[k], v_next[k]));
                if self.past(next.1, self.tissue) {
                    (lanes.marching[k], lanes.found[k]) = (false, true);
                    (lanes.before[k], lanes.after[k]) = (here, next);
                } else {
                    if self.accumulate {
                        lanes.inside[k] += self.inside_secretion(here, next);
                    }
                    if !self.past(here.1, self.secretion) && self.past(next.1, self.secretion) {
                        lanes.entered[k] = crossing(here, next, self.secretion);
                    }
                    (lanes.t[k], lanes.v[k]) = next;
                }
            }
        }
    }

    /// The tissue crossing inside each found lane's bracket: bisection, then linear
    /// interpolation in the last bracket (other lanes: 0).
    fn refine(&self, lanes: &Lanes8) -> [f32; 8] {
        let (mut before, mut after) = (lanes.before, lanes.after);
        for _ in 0..REFINE_STEPS {
            let t: [f32; 8] = std::array::from_fn(|k| 0.5 * (before[k].0 + after[k].0));
            let v = self.values(lanes, &t);
            for k in 0..8 {
                if self.past(v[k], self.tissue) {
                    after[k] = (t[k], v[k]);
                } else {
                    before[k] = (t[k], v[k]);
                }
            }
        }
        std::array::from_fn(|k| crossing(before[k], after[k], self.tissue))
    }

    /// How much of the last stretch into the tissue, `edge_mm` long (from where the ray last
    /// crossed the secretion threshold to the tissue's), is the tissue's own edge rather than
    /// secretion, given the value's `slope` along the ray at the tissue (stored units per mm).
    ///
    /// A scan blurs every air–tissue boundary, so the value passes both thresholds on the way
    /// into bare tissue too: a film of "secretion" on every wall, thickest where the ray meets
    /// the wall obliquely or the voxels are coarse. A bare edge crosses the band between the
    /// thresholds at about the slope it has at the tissue, in `|tissue − secretion| / slope`;
    /// a real layer lingers between them (a plateau) and takes longer. The stretch counts as
    /// secretion once it takes over [`LAYER_MIN`] times a bare edge's crossing, not at all
    /// under [`EDGE_MAX`] times, smoothly between.
    fn own_edge(&self, edge_mm: f32, slope: f32) -> f32 {
        let bare = (self.tissue - self.secretion).abs() / slope.abs().max(f32::MIN_POSITIVE);
        let x = ((edge_mm / bare - EDGE_MAX) / (LAYER_MIN - EDGE_MAX)).clamp(0.0, 1.0);
        let layer = x * x * (3.0 - 2.0 * x);
        (1.0 - layer) * edge_mm.max(0.0)
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
}

/// Where the value, taken as linear from `before` to `after` (distance, value), reaches
/// `iso` (`after`'s distance when it does not change).
fn crossing(before: (f32, f32), after: (f32, f32), iso: f32) -> f32 {
    let dv = after.1 - before.1;
    let f = if dv == 0.0 {
        1.0
    } else {
        ((iso - before.1) / dv).clamp(0.0, 1.0)
    };
    before.0 + f * (after.0 - before.0)
}

/// Eight rays' continuations in lockstep.
#[derive(Default)]
struct Lanes8 {
    /// Voxel-space origin and direction (per mm).
    o: [Vec3; 8],
    d: [Vec3; 8],
    /// Where the march stands, and the value there.
    t: [f32; 8],
    v: [f32; 8],
    /// Where the march must end, mm.
    t_end: [f64; 8],
    /// Still marching; found the tissue.
    marching: [bool; 8],
    found: [bool; 8],
    /// The found crossing's bracket.
    before: [(f32, f32); 8],
    after: [(f32, f32); 8],
    /// Length inside the secretion so far ([`SecretionMode::Accumulate`]).
    inside: [f32; 8],
    /// Where the ray last crossed into the secretion: its first secretion hit, or later
    /// where it came back into it after a stretch of air.
    entered: [f32; 8],
}

impl Lanes8 {
    /// Starts lane `k` on `lane` (origin, direction, start, end); `None` leaves it idle.
    fn start(&mut self, k: usize, lane: Option<(Vec3, Vec3, f32, f64)>) {
        if let Some((o, d, t, t_end)) = lane {
            (self.o[k], self.d[k], self.t[k], self.t_end[k]) = (o, d, t, t_end);
            self.entered[k] = t;
            self.marching[k] = true;
        }
    }
}
