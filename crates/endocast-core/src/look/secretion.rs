//! A ray carried on from its first secretion hit to the tissue (Krüger et al., Figure 3): a
//! march at a small step to the tissue threshold, refined by bisection, with the secretion
//! measured on the way.

use super::lanes::{map, map3, normalize_or_zero, Lanes, LANES};
use super::settings::{RayPassSettings, SecretionMode};
use crate::render::{with_avx2, Filter, Renderer, Sampler};
use glam::{DAffine3, DVec3, Mat3};

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

/// The tissue behind the secretion hits of up to eight rays, one per lane (unspecified where
/// the lane found none).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct TissueHits {
    /// Whether the lane's ray found the tissue.
    pub found: [bool; LANES],
    /// Distance from the ray's start to the tissue, mm.
    pub depth_mm: Lanes,
    /// World position of the hit, mm.
    pub hit_mm: [[f32; 3]; LANES],
    /// Unit world normal, up the value gradient, by axis.
    pub normal: [Lanes; 3],
    /// Secretion in front of the tissue, mm.
    pub secretion_mm: Lanes,
    /// Unit world normal of the secretion's surface at the ray's secretion hit, up the value
    /// gradient, by axis.
    pub secretion_normal: [Lanes; 3],
}

impl TissueHits {
    /// Lane `k`'s normal, or its secretion surface's (`normals`: [`Self::normal`] or
    /// [`Self::secretion_normal`]).
    pub fn vector(normals: &[Lanes; 3], k: usize) -> [f32; 3] {
        [normals[0][k], normals[1][k], normals[2][k]]
    }
}

/// Everything a continuation needs, shared by the rays of a frame.
pub(crate) struct Continuation<'a> {
    sampler: Sampler<'a>,
    voxel_from_world: DAffine3,
    extent: DVec3,
    /// Turns voxel-space gradients into world space (as `Shader::normal` does).
    world_from_gradient: Mat3,
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
    /// with `settings`, reconstructing it as `filter` says.
    pub fn new(renderer: &'a Renderer, settings: &RayPassSettings, filter: Filter) -> Self {
        let volume = renderer.volume();
        let geometry = volume.geometry();
        let map = volume.value_map();
        let stored = |hu: f64| map.stored_from_physical(hu) as f32;
        let (tissue, secretion) = (stored(settings.tissue_hu), stored(settings.secretion_hu));
        let dims = volume.dims();
        let step_vox = settings.secretion_step_vox;
        Self {
            sampler: renderer.sampler_for(filter),
            voxel_from_world: geometry.voxel_from_world(),
            extent: DVec3::from(dims.map(|n| (n - 1) as f64)),
            // The inverse transpose of the linear part, as `Shader::new` makes it.
            world_from_gradient: geometry
                .world_from_voxel()
                .matrix3
                .inverse()
                .transpose()
                .as_mat3(),
            tissue,
            secretion,
            rising: tissue > secretion,
            step_mm: (step_vox * geometry.spacing_mm().min_element()) as f32,
            accumulate: settings.secretion == SecretionMode::Accumulate,
        }
    }

    /// The tissue behind the secretion hits of up to eight rays at once, one per lane: the
    /// set-up, the march, the bisection and the measures branch-free over fixed lanes, compiled
    /// for AVX2 where the CPU has it (each sample batch one AVX2 gather). Ray `k` starts at
    /// world `origin` along unit `dir` and met the secretion `t_secretion_mm` along it. A lane
    /// finds nothing where its ray is missing, has no secretion hit (NaN), or leaves the volume
    /// before the tissue; where no lane finds the tissue, nothing is refined or measured. Each
    /// lane takes the samples a one-ray march would: the same positions, values and bisection,
    /// so the result does not depend on its neighbours. The normals are [`Shader::normal`]'s
    /// operation for operation, lane by lane (the same bits).
    ///
    /// [`Shader::normal`]: crate::render::Shader::normal
    pub fn tissue_after8(&self, rays: &[Option<(DVec3, DVec3, f32)>]) -> TissueHits {
        debug_assert!(rays.len() <= 8);
        let world = WorldRays::new(rays);
        if !world.on.contains(&true) {
            return TissueHits::default();
        }
        with_avx2(
            #[inline(always)]
            || {
                let mut lanes = self.start(&world);
                lanes.v = self.values(&lanes, &lanes.t);
                self.march(&mut lanes);
                if !lanes.found.contains(&true) {
                    return TissueHits::default();
                }
                let t_hit = self.refine(&lanes);
                self.measure(&lanes, &world, t_hit)
            },
        )
    }

    /// The lanes' voxel rays and the ends of their marches, operation for operation as
    /// `VoxelRay::new` and `VoxelRay::clip` make them (`render::traverse`); lanes without a ray
    /// or whose ray misses the volume stay idle.
    #[inline(always)]
    fn start(&self, world: &WorldRays) -> Lanes8 {
        let m = self.voxel_from_world.matrix3;
        let columns = [m.x_axis, m.y_axis, m.z_axis];
        let turn = |v: &[F64s; 3], a: usize, k: usize| {
            columns[0][a] * v[0][k] + columns[1][a] * v[1][k] + columns[2][a] * v[2][k]
        };
        let shift = self.voxel_from_world.translation;
        let o = map64x3(|a, k| turn(&world.origin, a, k) + shift[a]);
        let d = map64x3(|a, k| turn(&world.dir, a, k));
        let (mut t0, mut t1, mut on) = ([0.0f64; LANES], [f64::INFINITY; LANES], world.on);
        for a in 0..3 {
            for k in 0..LANES {
                let (o, d, hi) = (o[a][k], d[a][k], self.extent[a]);
                let (p, q) = ((0.0 - o) / d, (hi - o) / d);
                let flat = d == 0.0;
                on[k] &= !(flat & ((o < 0.0) | (o > hi)));
                t0[k] = pick(flat, t0[k], t0[k].max(p.min(q)));
                t1[k] = pick(flat, t1[k], t1[k].min(p.max(q)));
            }
        }
        let mut lanes = Lanes8 {
            o: map3(|a, k| o[a][k] as f32),
            d: map3(|a, k| d[a][k] as f32),
            t: world.t_secretion,
            t_end: map(|k| f32_not_past(t1[k])),
            entered: world.t_secretion,
            ..Lanes8::default()
        };
        for k in 0..LANES {
            lanes.marching[k] = on[k] & (t0[k] <= t1[k]) & t1[k].is_finite();
        }
        lanes
    }

    /// What the lanes found at `t_hit`: the world hit, the normal and the secretion, and the
    /// normal at the secretion hit (the secretion surface's).
    #[inline(always)]
    fn measure(&self, lanes: &Lanes8, world: &WorldRays, t_hit: Lanes) -> TissueHits {
        let points = map3(|a, k| lanes.o[a][k] + lanes.d[a][k] * t_hit[k]);
        let gradient = self.sampler.gradients8_lanes(&points);
        let [gx, gy, gz] = gradient;
        let at_secretion = map3(|a, k| lanes.o[a][k] + lanes.d[a][k] * world.t_secretion[k]);
        let surface = self.sampler.gradients8_lanes(&at_secretion);
        let secretion_mm = map(|k| {
            let measured = if self.accumulate {
                let last = self.inside_secretion((lanes.t[k], lanes.v[k]), (t_hit[k], self.tissue));
                lanes.inside[k] + last
            } else {
                t_hit[k] - world.t_secretion[k]
            };
            let edge = t_hit[k] - lanes.entered[k];
            let [dx, dy, dz] = [lanes.d[0][k], lanes.d[1][k], lanes.d[2][k]];
            let slope = gx[k] * dx + gy[k] * dy + gz[k] * dz;
            (measured - self.own_edge(edge, slope)).max(0.0)
        });
        let hit = map64x3(|a, k| world.origin[a][k] + world.dir[a][k] * f64::from(t_hit[k]));
        TissueHits {
            found: lanes.found,
            depth_mm: t_hit,
            hit_mm: per_lane(|k| [hit[0][k] as f32, hit[1][k] as f32, hit[2][k] as f32]),
            normal: self.normals(&gradient),
            secretion_mm,
            secretion_normal: self.normals(&surface),
        }
    }

    /// World-space unit normals of voxel-space `gradient` lanes (zero where a gradient is
    /// zero): `Shader::normal` lane by lane, operation for operation.
    #[inline(always)]
    fn normals(&self, gradient: &[Lanes; 3]) -> [Lanes; 3] {
        let m = self.world_from_gradient;
        let [gx, gy, gz] = gradient;
        // `Mat3 * Vec3`: x column times x, plus y's, plus z's.
        normalize_or_zero(map3(|a, k| {
            m.x_axis[a] * gx[k] + m.y_axis[a] * gy[k] + m.z_axis[a] * gz[k]
        }))
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
                lanes.after_t[k] = pick(found, next.0, lanes.after_t[k]);
                lanes.after_v[k] = pick(found, next.1, lanes.after_v[k]);
                if self.accumulate {
                    let inside = lanes.inside[k] + self.inside_secretion(here, next);
                    lanes.inside[k] = pick(go, inside, lanes.inside[k]);
                }
                let enters =
                    !self.past(here.1, self.secretion) && self.past(next.1, self.secretion);
                let entered = crossing(here, next, self.secretion);
                lanes.entered[k] = pick(go && enters, entered, lanes.entered[k]);
                lanes.t[k] = pick(go, next.0, here.0);
                lanes.v[k] = pick(go, next.1, here.1);
                lanes.marching[k] = go;
            }
        }
    }

    /// The tissue crossing inside each found lane's bracket: bisection, then linear
    /// interpolation in the last bracket (other lanes: unspecified).
    #[inline(always)]
    fn refine(&self, lanes: &Lanes8) -> Lanes {
        // Each end of the brackets as distance and value lanes.
        let (mut before_t, mut before_v) = (lanes.t, lanes.v);
        let (mut after_t, mut after_v) = (lanes.after_t, lanes.after_v);
        for _ in 0..REFINE_STEPS {
            let t = map(|k| 0.5 * (before_t[k] + after_t[k]));
            let v = self.values(lanes, &t);
            for k in 0..LANES {
                let past = self.past(v[k], self.tissue);
                (after_t[k], after_v[k]) =
                    (pick(past, t[k], after_t[k]), pick(past, v[k], after_v[k]));
                (before_t[k], before_v[k]) =
                    (pick(past, before_t[k], t[k]), pick(past, before_v[k], v[k]));
            }
        }
        map(|k| {
            crossing(
                (before_t[k], before_v[k]),
                (after_t[k], after_v[k]),
                self.tissue,
            )
        })
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
    #[inline(always)]
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

/// `f(axis, lane)` for three axes of lanes, in `f64` (a loop inlined where it is called, unlike
/// `std::array::from_fn`'s closures, so that it compiles for AVX2 there).
#[inline(always)]
fn map64x3(f: impl Fn(usize, usize) -> f64) -> [F64s; 3] {
    let mut out = [[0.0; LANES]; 3];
    for (axis, o) in out.iter_mut().enumerate() {
        for (k, o) in o.iter_mut().enumerate() {
            *o = f(axis, k);
        }
    }
    out
}

/// `f(lane)` for each lane, as [`map64x3`] does.
#[inline(always)]
fn per_lane<T: Copy + Default>(f: impl Fn(usize) -> T) -> [T; LANES] {
    let mut out = [T::default(); LANES];
    for (k, o) in out.iter_mut().enumerate() {
        *o = f(k);
    }
    out
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
    /// The end of the found crossing's bracket: distance and value.
    after_t: Lanes,
    after_v: Lanes,
    /// Length inside the secretion so far ([`SecretionMode::Accumulate`]).
    inside: Lanes,
    /// Where the ray last crossed into the secretion: its first secretion hit, or later
    /// where it came back into it after a stretch of air.
    entered: Lanes,
}

/// Eight `f64` values, one per lane.
type F64s = [f64; LANES];

/// Eight lanes' world rays (zero in idle lanes) and secretion hits.
struct WorldRays {
    origin: [F64s; 3],
    dir: [F64s; 3],
    t_secretion: Lanes,
    /// Whether the lane has a ray with a secretion hit.
    on: [bool; LANES],
}

impl WorldRays {
    /// The lanes of up to eight `(origin, direction, secretion hit)` rays.
    fn new(rays: &[Option<(DVec3, DVec3, f32)>]) -> Self {
        let mut world = Self {
            origin: [[0.0; LANES]; 3],
            dir: [[0.0; LANES]; 3],
            t_secretion: [0.0; LANES],
            on: [false; LANES],
        };
        for (k, ray) in rays.iter().enumerate() {
            let Some((origin, dir, t)) = ray.filter(|r| !r.2.is_nan()) else {
                continue;
            };
            for a in 0..3 {
                (world.origin[a][k], world.dir[a][k]) = (origin[a], dir[a]);
            }
            (world.t_secretion[k], world.on[k]) = (t, true);
        }
        world
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
    use super::*;
    use crate::phantom::{layered, PhantomOptions};
    use crate::render::traverse::VoxelRay;
    use crate::render::{Lighting, Shader};
    use crate::test_rng::Rng;
    use glam::Vec3;

    #[test]
    fn the_lanes_start_as_the_voxel_rays_do() {
        let options = PhantomOptions {
            size: 24,
            ..Default::default()
        };
        let volume = layered(&options).0;
        let (geometry, dims) = (*volume.geometry(), volume.dims());
        let renderer = Renderer::new(volume);
        let on = Continuation::new(&renderer, &RayPassSettings::default(), Filter::Trilinear);
        let mut s = Rng::new(7);
        let (mut inside, mut outside) = (0, 0);
        for round in 0..40 {
            let rays: Vec<_> = (0..LANES)
                .map(|k| {
                    // From around the volume, a third of its size beyond each face.
                    let span = DVec3::from(dims.map(|n| n as f64));
                    let origin = geometry.world_of((s.vec() * 5.0 / 6.0 + 0.5) * span);
                    // Some directions along an axis (a zero component: the flat case).
                    let dir = match (round + k) % 4 {
                        0 => DVec3::Z,
                        1 => DVec3::new(0.0, -1.0, 0.0),
                        _ => s.vec().normalize(),
                    };
                    (k != 5).then_some((origin, dir, 0.5))
                })
                .collect();
            let lanes = on.start(&WorldRays::new(&rays));
            for (k, ray) in rays.iter().enumerate() {
                let Some((origin, dir, _)) = *ray else {
                    assert!(!lanes.marching[k]);
                    continue;
                };
                let voxel = VoxelRay::new(&on.voxel_from_world, origin, dir);
                let clipped = voxel.clip(on.extent, 0.0);
                assert_eq!(lanes.marching[k], clipped.is_some(), "lane {k} of {ray:?}");
                let Some((_, t_end)) = clipped else {
                    outside += 1;
                    continue;
                };
                inside += 1;
                let (o, d) = (voxel.origin.as_vec3(), voxel.direction.as_vec3());
                for a in 0..3 {
                    assert_eq!(lanes.o[a][k].to_bits(), o[a].to_bits());
                    assert_eq!(lanes.d[a][k].to_bits(), d[a].to_bits());
                }
                assert_eq!(lanes.t_end[k], f32_not_past(t_end));
            }
        }
        assert!(
            inside > 50 && outside > 20,
            "{inside} inside, {outside} outside"
        );
    }

    #[test]
    fn the_lane_normals_are_the_shaders_bit_for_bit() {
        let volume = layered(&PhantomOptions {
            size: 16,
            ..Default::default()
        })
        .0;
        let renderer = Renderer::new(volume);
        let mut on = Continuation::new(&renderer, &RayPassSettings::default(), Filter::Trilinear);
        // A sheared, anisotropic grid, as `Continuation::new` turns it.
        let linear = glam::DMat3::from_cols_array(&[0.7, 0.1, 0.0, 0.05, 1.3, 0.2, 0.0, -0.3, 2.1]);
        on.world_from_gradient = linear.inverse().transpose().as_mat3();
        let shader = Shader::new(linear, Lighting::default());
        let mut s = Rng::new(11);
        for round in 0..20 {
            let mut lanes = [[0.0f32; LANES]; 3];
            #[allow(clippy::needless_range_loop)] // k picks the case as well as the lane
            for k in 0..LANES {
                let g = match (round + k) % 5 {
                    0 => Vec3::ZERO,
                    1 => s.vec().as_vec3() * 1e-30,
                    _ => s.vec().as_vec3() * 300.0 - 150.0,
                };
                (lanes[0][k], lanes[1][k], lanes[2][k]) = (g.x, g.y, g.z);
            }
            let normals = on.normals(&lanes);
            #[allow(clippy::needless_range_loop)] // k reads the lanes and the normals
            for k in 0..LANES {
                let g = Vec3::new(lanes[0][k], lanes[1][k], lanes[2][k]);
                let want = shader.normal(g).to_array().map(f32::to_bits);
                let got = TissueHits::vector(&normals, k).map(f32::to_bits);
                assert_eq!(got, want, "gradient {g}");
            }
        }
    }

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
