//! The trilinear field along a ray inside one cell is a cubic in the distance (Parker et al.
//! 1998; Marmitt et al. 2004): its four coefficients follow from the cell's eight corners and
//! the ray's entry point and direction. Its first crossing of an isovalue is found exactly: the
//! cubic's extrema split the segment into monotonic pieces, the first piece whose ends lie on
//! either side holds the crossing, and safeguarded Newton steps inside it reach it to well below
//! `f32` precision.

use glam::{Vec3, Vec4};

/// Newton steps at most per crossing (a monotonic cubic piece takes four or five).
const MAX_STEPS: usize = 40;
/// Newton stops once a step is shorter than this, mm: far below an `f32` distance's precision.
const TOLERANCE_MM: f64 = 1e-7;

/// The trilinear field along a ray segment inside one cell, `((a s + b) s + c) s + d` at `s` mm
/// past the segment's entry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CellCubic {
    a: f64,
    b: f64,
    c: f64,
    d: f64,
}

impl CellCubic {
    /// The cubic of the cell whose corners are `[low, high]` (as `VoxelGrid::corners` orders
    /// them: x = 0 and x = 1, each at (y, z) = (0, 0), (1, 0), (0, 1), (1, 1)), for a ray that
    /// enters it at `entry` (cell-local coordinates, 0–1) and moves `dir` cell units per mm.
    pub fn new([low, high]: [Vec4; 2], entry: Vec3, dir: Vec3) -> Self {
        let [c000, c010, c001, c011] = low.to_array().map(f64::from);
        let [c100, c110, c101, c111] = high.to_array().map(f64::from);
        // f = k + kx u + ky v + kz w + kxy u v + kyz v w + kxz u w + kxyz u v w.
        let k = c000;
        let (kx, ky, kz) = (c100 - c000, c010 - c000, c001 - c000);
        let kxy = c110 - c100 - c010 + c000;
        let kyz = c011 - c010 - c001 + c000;
        let kxz = c101 - c100 - c001 + c000;
        let kxyz = c111 - c110 - c101 - c011 + c100 + c010 + c001 - c000;
        let [u, v, w] = entry.to_array().map(f64::from);
        let [du, dv, dw] = dir.to_array().map(f64::from);
        Self {
            a: kxyz * du * dv * dw,
            b: kxy * du * dv
                + kyz * dv * dw
                + kxz * du * dw
                + kxyz * (u * dv * dw + du * v * dw + du * dv * w),
            c: kx * du
                + ky * dv
                + kz * dw
                + kxy * (u * dv + v * du)
                + kyz * (v * dw + w * dv)
                + kxz * (u * dw + w * du)
                + kxyz * (du * v * w + u * dv * w + u * v * dw),
            d: k + kx * u
                + ky * v
                + kz * w
                + kxy * u * v
                + kyz * v * w
                + kxz * u * w
                + kxyz * u * v * w,
        }
    }

    /// The field `s` mm past the entry.
    #[inline]
    pub fn at(&self, s: f64) -> f64 {
        ((self.a * s + self.b) * s + self.c) * s + self.d
    }

    /// The field's rate of change `s` mm past the entry, per mm.
    #[inline]
    fn slope(&self, s: f64) -> f64 {
        (3.0 * self.a * s + 2.0 * self.b) * s + self.c
    }

    /// Whether the field `s` mm past the entry lies past `iso` for a crossing in the direction
    /// `rising` (at or above it where rising, below it otherwise).
    #[inline]
    pub fn is_past(&self, iso: f64, rising: bool, s: f64) -> bool {
        (self.at(s) >= iso) == rising
    }

    /// The first distance in `[from, len]` mm at which the field crosses `iso` — from below to
    /// at or above it where `rising`, from at or above to below otherwise — or `None`. A field
    /// that only touches the isovalue from below counts as crossing it (the exact surface is
    /// there).
    pub fn first_crossing(&self, iso: f64, rising: bool, (from, len): (f64, f64)) -> Option<f64> {
        let after = |s: f64| self.is_past(iso, rising, s);
        let mut start = from;
        let extrema = self.extrema(len).into_iter().flatten();
        for end in extrema.filter(|&s| s > from).chain([len]) {
            if !after(start) && after(end) {
                return Some(self.root_in(iso, (start, end)));
            }
            start = end;
        }
        None
    }

    /// The cubic's extrema inside `(0, len)`, in order.
    fn extrema(&self, len: f64) -> [Option<f64>; 2] {
        // Roots of 3a s² + 2b s + c, in the stable form of the quadratic formula.
        let (qa, qb, qc) = (3.0 * self.a, 2.0 * self.b, self.c);
        let inside = |s: f64| (s > 0.0 && s < len).then_some(s);
        if qa == 0.0 {
            return [(qb != 0.0).then(|| -qc / qb).and_then(inside), None];
        }
        let discriminant = qb * qb - 4.0 * qa * qc;
        if discriminant < 0.0 {
            return [None, None];
        }
        let q = -0.5 * (qb + discriminant.sqrt().copysign(qb));
        let (r1, r2) = (q / qa, if q != 0.0 { qc / q } else { q / qa });
        let (first, second) = if r1 <= r2 { (r1, r2) } else { (r2, r1) };
        [inside(first), inside(second)]
    }

    /// The crossing of `iso` inside `(lo, hi)`, a piece on which the cubic is monotonic and
    /// whose ends lie on either side: Newton steps from the secant's guess, kept inside the
    /// shrinking bracket (bisection where a step leaves it).
    fn root_in(&self, iso: f64, (mut lo, mut hi): (f64, f64)) -> f64 {
        let (g_lo, g_hi) = (self.at(lo) - iso, self.at(hi) - iso);
        let below_at_lo = g_lo < 0.0;
        let span = g_hi - g_lo;
        let mut s = if span != 0.0 {
            lo + (hi - lo) * (-g_lo / span).clamp(0.0, 1.0)
        } else {
            0.5 * (lo + hi)
        };
        for _ in 0..MAX_STEPS {
            let g = self.at(s) - iso;
            if g == 0.0 {
                return s;
            }
            if (g < 0.0) == below_at_lo {
                lo = s;
            } else {
                hi = s;
            }
            let slope = self.slope(s);
            let newton = if slope != 0.0 {
                s - g / slope
            } else {
                f64::NAN
            };
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - s).abs() <= TOLERANCE_MM || hi - lo <= TOLERANCE_MM {
                return next;
            }
            s = next;
        }
        s
    }
}

/// The least and greatest value of the trilinear field of the cell with corners `[low, high]`
/// (ordered as [`CellCubic::new`] takes them) over the axis-aligned box with opposite corners
/// `a` and `b` (cell-local): the field is linear along each axis, so they are among the box's
/// eight corners. A ray segment from `a` to `b` lies in that box.
pub(crate) fn range_over_box([low, high]: [Vec4; 2], a: Vec3, b: Vec3) -> (f32, f32) {
    let along_x = |x: f32| low + (high - low) * x;
    let (mut least, mut greatest) = (f32::INFINITY, f32::NEG_INFINITY);
    for e in [along_x(a.x), along_x(b.x)] {
        // The edges along y at z = 0 and z = 1, at y = a.y and y = b.y.
        let (y0, y1) = (Vec4::new(e.x, e.z, e.x, e.z), Vec4::new(e.y, e.w, e.y, e.w));
        let r = y0 + (y1 - y0) * Vec4::new(a.y, a.y, b.y, b.y);
        // Along z at z = a.z and z = b.z.
        let (z0, z1) = (Vec4::new(r.x, r.x, r.z, r.z), Vec4::new(r.y, r.y, r.w, r.w));
        let v = z0 + (z1 - z0) * Vec4::new(a.z, b.z, a.z, b.z);
        least = least.min(v.min_element());
        greatest = greatest.max(v.max_element());
    }
    (least, greatest)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The trilinear interpolation of `[low, high]` at cell-local `p`, as the sampler forms it.
    fn trilinear([low, high]: [Vec4; 2], p: [f64; 3]) -> f64 {
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let (l, h) = (low.as_dvec4(), high.as_dvec4());
        let c = [0, 1, 2, 3].map(|n| lerp(l[n], h[n], p[0]));
        lerp(lerp(c[0], c[1], p[1]), lerp(c[2], c[3], p[1]), p[2])
    }

    fn corners(seed: u32) -> [Vec4; 2] {
        let mut state = seed;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 20) as f32
        };
        [
            Vec4::new(next(), next(), next(), next()),
            Vec4::new(next(), next(), next(), next()),
        ]
    }

    #[test]
    fn the_cubic_is_the_trilinear_field_along_the_ray() {
        for seed in 0..200 {
            let cell = corners(seed);
            let entry = Vec3::new(0.1, 0.7, 0.3 + seed as f32 * 1e-3);
            let dir = Vec3::new(0.3, -0.4, 0.5);
            let cubic = CellCubic::new(cell, entry, dir);
            for s in [0.0, 0.2, 0.5, 0.9, 1.3] {
                let p = (entry + dir * s as f32).as_dvec3().to_array();
                let expected = trilinear(cell, p);
                assert!((cubic.at(s) - expected).abs() < 1e-3, "{seed} {s}");
            }
        }
    }

    #[test]
    fn the_box_range_holds_the_field_inside_the_box_and_reaches_its_ends() {
        for seed in 0..100 {
            let cell = corners(seed);
            let a = Vec3::new(0.1, 0.8, 0.3);
            let b = Vec3::new(0.6, 0.2 + seed as f32 * 5e-3, 0.9);
            let (least, greatest) = range_over_box(cell, a, b);
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for n in 0..27 {
                let f = [n % 3, n / 3 % 3, n / 9].map(|i| f64::from(i as u8) / 2.0);
                let p: [f64; 3] = std::array::from_fn(|k| {
                    f64::from(a[k]) + (f64::from(b[k]) - f64::from(a[k])) * f[k]
                });
                let v = trilinear(cell, p);
                (lo, hi) = (lo.min(v), hi.max(v));
            }
            // Inside, and its corners are where the extremes lie.
            assert!((f64::from(least) - lo).abs() < 1e-2, "{seed}: {least} {lo}");
            assert!(
                (f64::from(greatest) - hi).abs() < 1e-2,
                "{seed}: {greatest} {hi}"
            );
        }
    }

    #[test]
    fn the_first_crossing_is_the_first_of_several() {
        // (s − 1)(s − 2)(s − 3) = s³ − 6 s² + 11 s − 6: rising at 1 and 3, falling at 2.
        let cubic = CellCubic {
            a: 1.0,
            b: -6.0,
            c: 11.0,
            d: -6.0,
        };
        let near = |found: Option<f64>, s: f64| found.is_some_and(|f| (f - s).abs() < 1e-9);
        assert!(near(cubic.first_crossing(0.0, true, (0.0, 4.0)), 1.0));
        assert!(near(cubic.first_crossing(0.0, false, (0.0, 4.0)), 2.0));
        assert!(near(cubic.first_crossing(0.0, true, (1.0, 4.0)), 3.0));
        assert_eq!(cubic.first_crossing(0.0, true, (0.0, 0.9)), None);
        // Touching the isovalue from below at a maximum is a hit.
        let touch = CellCubic {
            a: 0.0,
            b: -1.0,
            c: 2.0,
            d: -1.0,
        };
        assert!(near(touch.first_crossing(0.0, true, (0.0, 2.0)), 1.0));
    }
}
