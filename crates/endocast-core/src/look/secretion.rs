//! A ray carried on from its first secretion hit to the tissue (Krüger et al., Figure 3): a
//! march at a small step to the tissue threshold, refined by bisection, with the secretion
//! measured on the way.

use super::lanes::{map, map3, Lanes, LANES};
use super::settings::{RayPassSettings, SecretionMode};
use crate::render::traverse::VoxelRay;
use crate::render::{with_avx2, Lighting, Renderer, Sampler, Shader};
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
    /// sample batch one AVX2 gather and the lanes' bookkeeping branch-free over fixed lanes,
    /// compiled for AVX2 where the CPU has it): ray `k` starts at world `origin` along unit
    /// `dir` and met the secretion `t_secretion_mm` along it. A lane is `None` where its ray is
    /// missing, has no secretion hit (NaN), or leaves the volume before the tissue. Each lane
    /// takes the samples a one-ray march would: the same positions, values and bisection, so
    /// the result does not depend on its neighbours.
    pub fn tissue_after8(&self, rays: &[Option<(DVec3, DVec3, f32)>]) -> [Option<TissueHit>; 8] {
        debug_assert!(rays.len() <= 8);
        let mut lanes = Lanes8::default();
        for (k, ray) in rays.iter().enumerate() {
            lanes.start(k, self.lane(*ray));
        }
        let (t_hit, gradients) = with_avx2(
            #[inline(always)]
            || {
                lanes.v = self.values(&lanes, &lanes.t);
                self.march(&mut lanes);
                let t_hit = self.refine(&lanes);
                let points = map3(|a, k| lanes.o[a][k] + lanes.d[a][k] * t_hit[k]);
                (t_hit, self.sampler.gradients8_lanes(&points))
            },
        );
        std::array::from_fn(|k| {
            let (origin, dir, t_secretion) = lanes.found[k].then_some(rays[k]?)?;
            let t_hit = t_hit[k];
            let measured = if self.accumulate {
                lanes.inside[k]
                    + self.inside_secretion((lanes.t[k], lanes.v[k]), (t_hit, self.tissue))
            } else {
                t_hit - t_secretion
            };
            let edge = t_hit - lanes.entered[k];
            let d = Vec3::new(lanes.d[0][k], lanes.d[1][k], lanes.d[2][k]);
            let slope = gradients[k].dot(d);
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
    #[inline(always)]
    fn values(&self, lanes: &Lanes8, t: &Lanes) -> Lanes {
        self.sampler
            .points8(&map3(|a, k| lanes.o[a][k] + lanes.d[a][k] * t[k]))
    }

    /// Steps every marching lane on at the small step until it passes the tissue threshold
    /// (found, bracketed by the last step's start, where the lane stays, and `after`) or leaves
    /// the volume.
    #[inline(always)]
    fn march(&self, lanes: &mut Lanes8) {
        while lanes.marching.iter().any(|m| *m) {
            let t_next = map(|k| lanes.t[k] + self.step_mm);
            let v_next = self.values(lanes, &t_next);
            for k in 0..LANES {
                // `t_end` is the largest f32 not past the f64 end: the same test in f32.
                let on = lanes.marching[k] & (t_next[k] <= lanes.t_end[k]);
                let (here, next) = ((lanes.t[k], lanes.v[k]), (t_next[k], v_next[k]));
                let found = on & self.past(next.1, self.tissue);
                let go = on & !found;
                lanes.found[k] |= found;
                lanes.after[k] = pick(found, next, lanes.after[k]);
                if self.accumulate {
                    let inside = lanes.inside[k] + self.inside_secretion(here, next);
                    lanes.inside[k] = pick(go, inside, lanes.inside[k]);
                }
                let enters =
                    !self.past(here.1, self.secretion) && self.past(next.1, self.secretion);
                let entered = crossing(here, next, self.secretion);
                lanes.entered[k] = pick(go && enters, entered, lanes.entered[k]);
                (lanes.t[k], lanes.v[k]) = pick(go, next, here);
                lanes.marching[k] = go;
            }
        }
    }

    /// The tissue crossing inside each found lane's bracket: bisection, then linear
    /// interpolation in the last bracket (other lanes: unspecified).
    #[inline(always)]
    fn refine(&self, lanes: &Lanes8) -> Lanes {
        let (mut before, mut after) = (lanes.before(), lanes.after);
        for _ in 0..REFINE_STEPS {
            let t = map(|k| 0.5 * (before[k].0 + after[k].0));
            let v = self.values(lanes, &t);
            for k in 0..LANES {
                let past = self.past(v[k], self.tissue);
                after[k] = pick(past, (t[k], v[k]), after[k]);
                before[k] = pick(past, before[k], (t[k], v[k]));
            }
        }
        map(|k| crossing(before[k], after[k], self.tissue))
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
    /// the value taken as linear between them (without branches, so that lanes vectorise).
    #[inline(always)]
    fn inside_secretion(&self, (t0, v0): (f32, f32), (t1, v1): (f32, f32)) -> f32 {
        let s = self.secretion;
        let (in0, in1) = (self.past(v0, s), self.past(v1, s));
        let f = ((s - v0) / (v1 - v0)).clamp(0.0, 1.0);
        let part = pick(in0, f, 1.0 - f) * (t1 - t0);
        pick(in0 == in1, pick(in0, t1 - t0, 0.0), part)
    }
}

/// Where the value, taken as linear from `before` to `after` (distance, value), reaches
/// `iso` (`after`'s distance when it does not change).
#[inline(always)]
fn crossing(before: (f32, f32), after: (f32, f32), iso: f32) -> f32 {
    let dv = after.1 - before.1;
    let f = if dv == 0.0 {
        1.0
    } else {
        ((iso - before.1) / dv).clamp(0.0, 1.0)
    };
    before.0 + f * (after.0 - before.0)
}

/// `a` where `on`, else `b` (a select, for lanes that vectorise).
#[inline(always)]
fn pick<T>(on: bool, a: T, b: T) -> T {
    if on {
        a
    } else {
        b
    }
}

/// Eight rays' continuations in lockstep, each quantity one value per lane.
#[derive(Default)]
struct Lanes8 {
    /// Voxel-space origin and direction (per mm), by axis.
    o: [Lanes; 3],
    d: [Lanes; 3],
    /// Where the march stands, and the value there (a found lane: the start of the step that
    /// crossed the tissue threshold).
    t: Lanes,
    v: Lanes,
    /// Where the march must end, mm: the largest `f32` not past the ray's (`f64`) end.
    t_end: Lanes,
    /// Still marching; found the tissue.
    marching: [bool; LANES],
    found: [bool; LANES],
    /// The end of the found crossing's bracket.
    after: [(f32, f32); LANES],
    /// Length inside the secretion so far ([`SecretionMode::Accumulate`]).
    inside: Lanes,
    /// Where the ray last crossed into the secretion: its first secretion hit, or later
    /// where it came back into it after a stretch of air.
    entered: Lanes,
}

impl Lanes8 {
    /// Starts lane `k` on `lane` (origin, direction, start, end); `None` leaves it idle.
    fn start(&mut self, k: usize, lane: Option<(Vec3, Vec3, f32, f64)>) {
        if let Some((o, d, t, t_end)) = lane {
            for (axis, (o, d)) in o.to_array().into_iter().zip(d.to_array()).enumerate() {
                (self.o[axis][k], self.d[axis][k]) = (o, d);
            }
            (self.t[k], self.t_end[k]) = (t, f32_not_past(t_end));
            self.entered[k] = t;
            self.marching[k] = true;
        }
    }

    /// The start of each lane's found bracket.
    #[inline(always)]
    fn before(&self) -> [(f32, f32); LANES] {
        std::array::from_fn(|k| (self.t[k], self.v[k]))
    }
}

/// The largest `f32` not greater than `x`, so that `f64::from(t) > x` for an `f32` `t` is
/// `t > f32_not_past(x)` (for finite `x`; `f32::MAX` where `x` lies beyond the `f32` range).
fn f32_not_past(x: f64) -> f32 {
    let nearest = x as f32;
    if f64::from(nearest) > x {
        nearest.next_down()
    } else {
        nearest
    }
}

#[cfg(test)]
mod tests {
    use super::f32_not_past;

    #[test]
    fn the_f32_end_test_is_the_f64_one() {
        const ENDS: [f64; 8] = [
            0.1,
            1.0,
            1.0 / 3.0,
            217.123_456_789,
            1e-40,
            3.5e38,
            1e300,
            -2.7,
        ];
        for x in ENDS {
            let (below, near) = (f32_not_past(x), x as f32);
            assert!(f64::from(below) <= x, "{x}");
            let around = [near.next_down(), near, near.next_up(), below.next_up()];
            for t in around {
                assert_eq!(f64::from(t) > x, t > below, "t {t} against {x}");
            }
        }
    }
}
