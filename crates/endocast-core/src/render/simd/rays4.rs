//! Ray set-up for four pixels of a row at once (AVX2, `f64`): the camera ray, its voxel-space
//! direction, its part inside the volume past the near plane and the start of its brick walk.
//! A pinhole camera with an ideal lens (the common case) has its rays made here too; any other
//! camera's come from [`Camera::ray`] one by one and only their clipping and walks run four at
//! a time. Every lane repeats the one-ray set-up ([`Camera::ray`], [`VoxelRay::new`],
//! [`VoxelRay::clip`], [`BrickDda::new`]) operation for operation, in the same order and with
//! the same comparisons, so it gives the same bits; only the per-ray bookkeeping is shared.

use crate::camera::{Camera, PinholeRays, Ray};
use crate::render::traverse::{BrickDda, VoxelRay};
use crate::render::BRICK_VOX;
use glam::{DAffine3, DVec3};
use std::arch::x86_64::{
    __m256d, _mm256_add_pd, _mm256_and_pd, _mm256_andnot_pd, _mm256_blendv_pd, _mm256_cmp_pd,
    _mm256_cvtps_pd, _mm256_cvttpd_epi32, _mm256_div_pd, _mm256_max_pd, _mm256_min_pd,
    _mm256_movemask_pd, _mm256_mul_pd, _mm256_or_pd, _mm256_set1_pd, _mm256_setr_pd,
    _mm256_sqrt_pd, _mm256_storeu_pd, _mm256_sub_pd, _mm_loadu_ps, _mm_storeu_si128, _CMP_EQ_OQ,
    _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _CMP_NEQ_OQ,
};

/// What a frame's rays share: the camera, and the volume's frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RaySetup {
    camera: Camera,
    /// The pinhole fast path's numbers, where the camera is a pinhole with an ideal lens.
    pinhole: Option<PinholeRays>,
    size: (f64, f64),
    near_mm: f64,
    voxel_from_world: DAffine3,
    /// The world-to-voxel matrix's columns.
    axes: [DVec3; 3],
    /// The pinhole's eye in voxel space (every ray's origin).
    origin: DVec3,
    /// The voxel positions' box, `[0, extent]`.
    extent: DVec3,
    bricks: [i32; 3],
}

/// One lane's ray: its voxel-space form, its part inside the volume and the start of its walk.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LaneRay {
    pub ray: VoxelRay,
    /// Unit world direction.
    pub dir_world: DVec3,
    pub range: (f64, f64),
    pub dda: BrickDda,
    /// Whether the walk starts at a late start (see [`LateStarts`]) rather than at `range.0`.
    pub late: bool,
}

/// Late starts of four lanes' brick walks (a stereo pair's second eye, see `render::stereo`):
/// per lane the start (mm; NaN for none) and the distance up to which samples must lie in the
/// eye's clear ball for the start to hold without a check. Lanes whose check reaches beyond the
/// ball keep their walk from `range.0` (the caller checks them one by one).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LateStarts {
    pub check: [f32; 4],
    pub start: [f32; 4],
    /// Radius of the ball around the eye in which every sample lies on the eye's side of the
    /// isovalue, voxels.
    pub clear: f32,
    /// Sample step, mm (the sample after `check` must lie in the ball too).
    pub step: f32,
}

/// Four lanes' rays before clipping: voxel-space origins and directions, unit world directions,
/// near distances, and which lanes have a ray at all.
struct Lanes4 {
    origin: [__m256d; 3],
    dir_world: [__m256d; 3],
    dir_vox: [__m256d; 3],
    t_min: __m256d,
    valid: [bool; 4],
}

impl RaySetup {
    /// The set-up of `camera`'s rays through a volume of `dims` voxels in `bricks` bricks.
    pub fn new(
        camera: &Camera,
        voxel_from_world: &DAffine3,
        dims: [usize; 3],
        bricks: [usize; 3],
    ) -> Self {
        let [w, h] = camera.size();
        let m = voxel_from_world.matrix3;
        let pinhole = camera.fast_pinhole();
        let eye = pinhole.map_or(camera.eye_mm(), |p| p.origin);
        Self {
            camera: *camera,
            pinhole,
            size: (w as f64, h as f64),
            near_mm: camera.near_mm(),
            voxel_from_world: *voxel_from_world,
            axes: [m.x_axis, m.y_axis, m.z_axis],
            origin: voxel_from_world.transform_point3(eye),
            extent: DVec3::from(dims.map(|n| (n - 1) as f64)),
            bricks: bricks.map(|b| i32::try_from(b).unwrap_or(i32::MAX)),
        }
    }

    /// The rays of pixels `x0 .. x0 + 4` of row `y` (`None` where a ray misses the volume or
    /// the camera forms none; lanes past the image's right edge are computed all the same).
    #[target_feature(enable = "avx2")]
    pub(super) fn rays4(
        &self,
        x0: usize,
        y: usize,
        late: Option<&LateStarts>,
    ) -> [Option<LaneRay>; 4] {
        let lanes = match &self.pinhole {
            Some(pinhole) => self.pinhole4(pinhole, x0, y),
            None => self.camera4(x0, y),
        };
        self.finish(&lanes, late)
    }

    /// A pinhole's four rays, operation for operation as `Camera::ray` and `VoxelRay::new`.
    #[target_feature(enable = "avx2")]
    fn pinhole4(&self, p: &PinholeRays, x0: usize, y: usize) -> Lanes4 {
        let splat = _mm256_set1_pd;
        let (w, h) = self.size;
        let column = |k: usize| (x0 + k) as f64;
        let x = _mm256_add_pd(
            _mm256_add_pd(
                _mm256_setr_pd(column(0), column(1), column(2), column(3)),
                splat(0.5),
            ),
            splat(p.pixel_offset[0]),
        );
        let y = (y as f64 + 0.5) + p.pixel_offset[1];
        let sy = (1.0 - 2.0 * y / h) * p.tan_half_fov;
        let mut sx = _mm256_div_pd(
            _mm256_mul_pd(
                _mm256_mul_pd(
                    _mm256_sub_pd(
                        _mm256_div_pd(_mm256_mul_pd(splat(2.0), x), splat(w)),
                        splat(1.0),
                    ),
                    splat(p.tan_half_fov),
                ),
                splat(w),
            ),
            splat(h),
        );
        if let Some(shift) = p.shift {
            sx = _mm256_sub_pd(sx, splat(shift));
        }
        let v: [__m256d; 3] = std::array::from_fn(|c| {
            let along_right =
                _mm256_add_pd(splat(p.forward[c]), _mm256_mul_pd(splat(p.right[c]), sx));
            _mm256_add_pd(along_right, splat(p.up[c] * sy))
        });
        let length = _mm256_sqrt_pd(dot(v, v));
        let recip = _mm256_div_pd(splat(1.0), length);
        let dir = v.map(|vc| _mm256_mul_pd(vc, recip));
        // As `DAffine3::transform_vector3`.
        let dir_vox: [__m256d; 3] = std::array::from_fn(|c| {
            let [ax, ay, az] = self.axes;
            _mm256_add_pd(
                _mm256_add_pd(
                    _mm256_mul_pd(splat(ax[c]), dir[0]),
                    _mm256_mul_pd(splat(ay[c]), dir[1]),
                ),
                _mm256_mul_pd(splat(az[c]), dir[2]),
            )
        });
        Lanes4 {
            origin: self.origin.to_array().map(|c| _mm256_set1_pd(c)),
            t_min: self.near_distance(p.forward, dir),
            dir_world: dir,
            dir_vox,
            valid: [true; 4],
        }
    }

    /// Any other camera's four rays: each from `Camera::ray` and `VoxelRay::new`.
    #[target_feature(enable = "avx2")]
    fn camera4(&self, x0: usize, y: usize) -> Lanes4 {
        let rays: [Option<Ray>; 4] = std::array::from_fn(|k| self.camera.pixel_ray(x0 + k, y));
        let voxel: [(VoxelRay, DVec3, f64); 4] = std::array::from_fn(|k| match rays[k] {
            Some(r) => (
                VoxelRay::new(&self.voxel_from_world, r.origin, r.dir),
                r.dir,
                self.camera.near_distance_along(r.dir),
            ),
            // A placeholder the mask drops.
            None => (
                VoxelRay {
                    origin: DVec3::ZERO,
                    direction: DVec3::ONE,
                },
                DVec3::ONE,
                0.0,
            ),
        });
        let lanes = |f: &dyn Fn(&(VoxelRay, DVec3, f64)) -> f64| {
            _mm256_setr_pd(f(&voxel[0]), f(&voxel[1]), f(&voxel[2]), f(&voxel[3]))
        };
        Lanes4 {
            origin: std::array::from_fn(|c| lanes(&|v| v.0.origin[c])),
            dir_world: std::array::from_fn(|c| lanes(&|v| v.1[c])),
            dir_vox: std::array::from_fn(|c| lanes(&|v| v.0.direction[c])),
            t_min: lanes(&|v| v.2),
            valid: rays.map(|r| r.is_some()),
        }
    }

    /// Clips the lanes' rays to the volume and starts their brick walks.
    #[target_feature(enable = "avx2")]
    fn finish(&self, lanes: &Lanes4, late: Option<&LateStarts>) -> [Option<LaneRay>; 4] {
        let (t0, t1, inside) = self.clip(lanes.origin, lanes.dir_vox, lanes.t_min);
        let (t_walk, started) = match late {
            Some(late) => late_walks(late, lanes.dir_vox, t0, t1),
            None => (t0, [false; 4]),
        };
        let walk = self.walk_start(lanes.origin, lanes.dir_vox, t_walk);
        let t_walk = doubles(t_walk);
        let (origin, dir, dir_vox, t0, t1, inside) = (
            lanes.origin.map(|v| doubles(v)),
            lanes.dir_world.map(|v| doubles(v)),
            lanes.dir_vox.map(|v| doubles(v)),
            doubles(t0),
            doubles(t1),
            doubles(inside),
        );
        std::array::from_fn(|k| {
            (lanes.valid[k] && inside[k] != 0.0).then(|| LaneRay {
                ray: VoxelRay {
                    origin: DVec3::new(origin[0][k], origin[1][k], origin[2][k]),
                    direction: DVec3::new(dir_vox[0][k], dir_vox[1][k], dir_vox[2][k]),
                },
                dir_world: DVec3::new(dir[0][k], dir[1][k], dir[2][k]),
                range: (t0[k], t1[k]),
                dda: walk.lane(k, (t_walk[k], t1[k]), self.bricks),
                late: started[k],
            })
        })
    }

    /// As `Camera::near_distance_along`.
    #[target_feature(enable = "avx2")]
    fn near_distance(&self, f: DVec3, dir: [__m256d; 3]) -> __m256d {
        if self.near_mm == 0.0 {
            return _mm256_set1_pd(0.0);
        }
        let forward = [
            _mm256_set1_pd(f.x),
            _mm256_set1_pd(f.y),
            _mm256_set1_pd(f.z),
        ];
        let cos = dot(dir, forward);
        // `cos.max(1e-9)`: a NaN gives 1e-9, as `f64::max` does.
        _mm256_div_pd(
            _mm256_set1_pd(self.near_mm),
            _mm256_max_pd(cos, _mm256_set1_pd(1e-9)),
        )
    }

    /// As `VoxelRay::clip(extent, t_min)`: the lanes' `t0`, `t1` and a mask of the lanes whose
    /// interval is not empty.
    #[target_feature(enable = "avx2")]
    fn clip(
        &self,
        origin: [__m256d; 3],
        dir: [__m256d; 3],
        t_min: __m256d,
    ) -> (__m256d, __m256d, __m256d) {
        let (mut t0, mut t1) = (t_min, _mm256_set1_pd(f64::INFINITY));
        let mut missed = _mm256_set1_pd(0.0);
        for (axis, &d) in dir.iter().enumerate() {
            let (o, hi) = (origin[axis], _mm256_set1_pd(self.extent[axis]));
            let parallel = _mm256_cmp_pd::<_CMP_EQ_OQ>(d, _mm256_set1_pd(0.0));
            // `o < 0.0 || o > hi` per lane.
            let outside = _mm256_or_pd(
                _mm256_cmp_pd::<_CMP_LT_OQ>(o, _mm256_set1_pd(0.0)),
                _mm256_cmp_pd::<_CMP_GT_OQ>(o, hi),
            );
            missed = _mm256_or_pd(missed, _mm256_and_pd(parallel, outside));
            let a = _mm256_div_pd(_mm256_sub_pd(_mm256_set1_pd(0.0), o), d);
            let b = _mm256_div_pd(_mm256_sub_pd(hi, o), d);
            // `t0.max(a.min(b))` and `t1.min(a.max(b))`; a NaN operand yields the other, as
            // `f64::max` and `f64::min` do.
            let entered = _mm256_max_pd(_mm256_min_pd(a, b), t0);
            let left = _mm256_min_pd(_mm256_max_pd(a, b), t1);
            t0 = _mm256_blendv_pd(entered, t0, parallel);
            t1 = _mm256_blendv_pd(left, t1, parallel);
        }
        let ordered = _mm256_cmp_pd::<_CMP_LE_OQ>(t0, t1);
        let finite = _mm256_cmp_pd::<_CMP_NEQ_OQ>(
            _mm256_and_pd(t1, _mm256_set1_pd(f64::INFINITY)),
            _mm256_set1_pd(f64::INFINITY),
        );
        let inside = _mm256_andnot_pd(missed, _mm256_and_pd(ordered, finite));
        (t0, t1, inside)
    }

    /// As `BrickDda::new`: each lane's first brick, step directions and face distances.
    #[target_feature(enable = "avx2")]
    fn walk_start(&self, origin: [__m256d; 3], dir: [__m256d; 3], t_start: __m256d) -> WalkStart {
        let brick = BRICK_VOX as f64;
        let splat = _mm256_set1_pd;
        let mut start = WalkStart {
            cell: [[0; 4]; 3],
            t_next: [[f32::INFINITY; 4]; 3],
            t_delta: [[f32::INFINITY; 4]; 3],
            step: [[0; 4]; 3],
        };
        for (axis, &d) in dir.iter().enumerate() {
            let o = origin[axis];
            let at = _mm256_div_pd(_mm256_add_pd(o, _mm256_mul_pd(d, t_start)), splat(brick));
            let cell = truncate(at).map(|c| c.clamp(0, self.bricks[axis] - 1));
            // The face ahead: `cell + 1` going up, `cell` going down.
            let up = doubles(_mm256_cmp_pd::<_CMP_GE_OQ>(d, splat(0.0)));
            let face = _mm256_setr_pd(
                face_of(cell[0], up[0]),
                face_of(cell[1], up[1]),
                face_of(cell[2], up[2]),
                face_of(cell[3], up[3]),
            );
            let t_next = doubles(_mm256_div_pd(
                _mm256_sub_pd(_mm256_mul_pd(face, splat(brick)), o),
                d,
            ));
            let forward = doubles(_mm256_div_pd(splat(brick), d));
            let backward = doubles(_mm256_div_pd(splat(-brick), d));
            let d = doubles(d);
            for k in 0..4 {
                start.cell[axis][k] = cell[k];
                if d[k] > 0.0 {
                    start.step[axis][k] = 1;
                    start.t_next[axis][k] = t_next[k] as f32;
                    start.t_delta[axis][k] = forward[k] as f32;
                } else if d[k] < 0.0 {
                    start.step[axis][k] = -1;
                    start.t_next[axis][k] = t_next[k] as f32;
                    start.t_delta[axis][k] = backward[k] as f32;
                }
            }
        }
        start
    }
}

/// Each lane's walk start: its late start where that lies past `t0` and the samples up to the
/// check lie in the clear ball around the eye (every lane's origin), else `t0`.
#[target_feature(enable = "avx2")]
fn late_walks(
    late: &LateStarts,
    dir_vox: [__m256d; 3],
    t0: __m256d,
    t1: __m256d,
) -> (__m256d, [bool; 4]) {
    let splat = _mm256_set1_pd;
    // SAFETY: four f32 are read from an array of four (each widened exactly to f64).
    let wide = |v: &[f32; 4]| _mm256_cvtps_pd(unsafe { _mm_loadu_ps(v.as_ptr()) });
    let (check, start) = (wide(&late.check), wide(&late.start));
    let voxels_per_mm = _mm256_sqrt_pd(dot(dir_vox, dir_vox));
    let reach = _mm256_mul_pd(
        voxels_per_mm,
        _mm256_add_pd(check, splat(f64::from(late.step))),
    );
    // A hair inside the ball: the samples are taken in f32. (NaN starts compare false.)
    let inside = _mm256_cmp_pd::<_CMP_LT_OQ>(reach, splat(0.999 * f64::from(late.clear)));
    let started = _mm256_and_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(start, t0), inside);
    // `start.min(t1)`: the minimum's second operand where `t1` is NaN, as `f64::min`.
    let walk = _mm256_blendv_pd(t0, _mm256_min_pd(t1, start), started);
    let bits = _mm256_movemask_pd(started);
    (walk, std::array::from_fn(|k| bits >> k & 1 == 1))
}

/// The per-lane start of the brick walks.
struct WalkStart {
    cell: [[i32; 4]; 3],
    step: [[i32; 4]; 3],
    t_next: [[f32; 4]; 3],
    t_delta: [[f32; 4]; 3],
}

impl WalkStart {
    /// Lane `k`'s walk over `(t_start, t_end)`.
    #[inline]
    fn lane(&self, k: usize, (t_start, t_end): (f64, f64), bricks: [i32; 3]) -> BrickDda {
        BrickDda {
            cell: self.cell.map(|c| c[k]),
            step: self.step.map(|s| s[k]),
            t_next: self.t_next.map(|t| t[k]),
            t_delta: self.t_delta.map(|t| t[k]),
            t: t_start as f32,
            t_end: t_end as f32,
            bricks,
        }
    }
}

/// The brick face ahead of `cell` in `f64`: `cell + 1` where the ray goes up (`up` non-zero).
fn face_of(cell: i32, up: f64) -> f64 {
    if up != 0.0 {
        f64::from(cell + 1)
    } else {
        f64::from(cell)
    }
}

/// `a · b` per lane, as `DVec3::dot`.
#[target_feature(enable = "avx2")]
fn dot(a: [__m256d; 3], b: [__m256d; 3]) -> __m256d {
    _mm256_add_pd(
        _mm256_add_pd(_mm256_mul_pd(a[0], b[0]), _mm256_mul_pd(a[1], b[1])),
        _mm256_mul_pd(a[2], b[2]),
    )
}

/// `v as i32` per lane (truncation; out of range gives `i32::MIN`, which the callers clamp).
#[target_feature(enable = "avx2")]
fn truncate(v: __m256d) -> [i32; 4] {
    let mut out = [0i32; 4];
    // SAFETY: 16 bytes are written to an array of 16 bytes.
    unsafe { _mm_storeu_si128(out.as_mut_ptr().cast(), _mm256_cvttpd_epi32(v)) };
    out
}

/// The lanes of `v`.
#[target_feature(enable = "avx2")]
fn doubles(v: __m256d) -> [f64; 4] {
    let mut out = [0.0; 4];
    // SAFETY: four f64 are written to an array of four.
    unsafe { _mm256_storeu_pd(out.as_mut_ptr(), v) };
    out
}
