//! The procedural aids: a planar grid of lines, a marker sphere, and the instruments of an
//! endoscope (capsules fixed to the camera). Each answers where a ray meets it, analytically.

use super::SceneError;
use glam::DVec3;

/// A planar grid of lines for orientation (Scharsach et al. 2006, Figure 3): lines `spacing_mm`
/// apart along two perpendicular directions of the plane, `line_width_mm` wide, through
/// `origin_mm`; unbounded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridPlane {
    origin_mm: DVec3,
    normal: DVec3,
    spacing_mm: f64,
    line_width_mm: f64,
    /// The in-plane directions of the lines.
    axes: [DVec3; 2],
}

impl GridPlane {
    /// A grid through `origin_mm` with unit `normal` (normalised here) and lines `spacing_mm`
    /// apart, a twentieth of the spacing wide. The lines run along the world axes nearest to
    /// the plane (a plane normal to z has lines along x and y).
    pub fn new(origin_mm: DVec3, normal: DVec3, spacing_mm: f64) -> Result<Self, SceneError> {
        if !origin_mm.is_finite() || !normal.is_finite() || normal.length() < 1e-9 {
            return Err(SceneError::BadGrid(
                "the origin and the normal must be finite, the normal not zero".into(),
            ));
        }
        let normal = normal.normalize();
        let grid = Self {
            origin_mm,
            normal,
            spacing_mm: 1.0,
            line_width_mm: 0.05,
            axes: in_plane_axes(normal),
        };
        grid.with_spacing(spacing_mm, spacing_mm / 20.0)
    }

    /// The same grid with lines `spacing_mm` apart and `line_width_mm` wide (0 < width ≤ spacing;
    /// a width equal to the spacing fills the plane).
    pub fn with_spacing(self, spacing_mm: f64, line_width_mm: f64) -> Result<Self, SceneError> {
        let good = spacing_mm.is_finite() && spacing_mm > 0.0;
        if !(good && line_width_mm > 0.0 && line_width_mm <= spacing_mm) {
            return Err(SceneError::BadGrid(format!(
                "spacing {spacing_mm} mm must be positive and the line width {line_width_mm} mm \
                 between 0 and the spacing"
            )));
        }
        Ok(Self {
            spacing_mm,
            line_width_mm,
            ..self
        })
    }

    /// The grid moved by `distance_mm` along its normal.
    pub fn moved(self, distance_mm: f64) -> Self {
        Self {
            origin_mm: self.origin_mm + self.normal * distance_mm,
            ..self
        }
    }

    /// A point of the plane (where two lines cross), world mm.
    pub fn origin_mm(&self) -> DVec3 {
        self.origin_mm
    }

    /// The unit normal.
    pub fn normal(&self) -> DVec3 {
        self.normal
    }

    /// The unit directions of the two families of lines.
    pub fn axes(&self) -> [DVec3; 2] {
        self.axes
    }

    /// Distance between lines, mm.
    pub fn spacing_mm(&self) -> f64 {
        self.spacing_mm
    }

    /// Width of a line, mm.
    pub fn line_width_mm(&self) -> f64 {
        self.line_width_mm
    }

    /// Whether plane point `p` lies on a line.
    pub fn on_line(&self, p: DVec3) -> bool {
        let d = p - self.origin_mm;
        let half = 0.5 * self.line_width_mm;
        self.axes.iter().any(|axis| {
            // Distance to the nearest line across this family (lines run along the other axis).
            let x = d.dot(*axis) / self.spacing_mm;
            (x - x.round()).abs() * self.spacing_mm <= half
        })
    }

    /// Where the ray meets a line of the grid within `(t_min, t_max)`.
    pub fn hit(&self, origin: DVec3, dir: DVec3, t_min: f64, t_max: f64) -> Option<f64> {
        let denom = dir.dot(self.normal);
        if denom == 0.0 {
            return None;
        }
        let t = (self.origin_mm - origin).dot(self.normal) / denom;
        (t > t_min && t < t_max && self.on_line(origin + dir * t)).then_some(t)
    }
}

/// The two in-plane unit directions for `normal`: the world axis least aligned with it,
/// projected into the plane, and the normal × that.
fn in_plane_axes(normal: DVec3) -> [DVec3; 2] {
    let a = normal.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let u = (axis - normal * axis.dot(normal)).normalize();
    [u, normal.cross(u)]
}

/// A sphere marking a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Marker {
    /// Centre, world mm.
    pub centre_mm: DVec3,
    /// Radius, mm.
    pub radius_mm: f64,
}

impl Marker {
    /// A marker at `centre_mm` of `radius_mm` (finite and positive).
    pub fn new(centre_mm: DVec3, radius_mm: f64) -> Result<Self, SceneError> {
        if !(centre_mm.is_finite() && radius_mm.is_finite() && radius_mm > 0.0) {
            return Err(SceneError::BadMarker(centre_mm.to_array(), radius_mm));
        }
        Ok(Self {
            centre_mm,
            radius_mm,
        })
    }

    /// Where the ray enters and leaves the sphere (either may lie behind the start).
    pub fn crossings(&self, origin: DVec3, dir: DVec3) -> Option<(f64, f64)> {
        sphere_crossings(origin - self.centre_mm, dir, self.radius_mm)
    }
}

/// The distances where a unit ray from `oc` (relative to the centre) enters and leaves a sphere
/// of radius `r`.
fn sphere_crossings(oc: DVec3, dir: DVec3, r: f64) -> Option<(f64, f64)> {
    let b = oc.dot(dir);
    let c = oc.length_squared() - r * r;
    let h = b * b - c;
    if h < 0.0 {
        return None;
    }
    let s = h.sqrt();
    Some((-b - s, -b + s))
}

/// Relative margin below zero of a ray's discriminant against a capsule's infinite cylinder
/// past which the ray surely misses the capsule ([`Capsule::hit`]).
const MISS_MARGIN: f64 = 1e-9;

/// A rod with rounded ends: the segment from `a` to `b` (world mm) thickened by `radius`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    /// One end of the axis, world mm.
    pub a: DVec3,
    /// The other end (the tip), world mm.
    pub b: DVec3,
    /// Radius, mm.
    pub radius: f64,
}

impl Capsule {
    /// The nearest point where a unit ray from `origin` outside the capsule enters it, within
    /// `(t_min, t_max)`.
    pub fn hit(&self, origin: DVec3, dir: DVec3, t_min: f64, t_max: f64) -> Option<f64> {
        self.seen_from(origin).hit(dir, t_min, t_max)
    }

    /// The capsule's terms for rays from `origin` (many rays of a view share it).
    pub fn seen_from(&self, origin: DVec3) -> CapsuleFrom {
        let (ba, oa) = (self.b - self.a, origin - self.a);
        let (baba, baoa, oaoa) = (ba.dot(ba), ba.dot(oa), oa.dot(oa));
        let r2 = self.radius * self.radius;
        CapsuleFrom {
            ba,
            oa,
            ob: origin - self.b,
            baba,
            baoa,
            qc: baba * oaoa - baoa * baoa - r2 * baba,
            radius: self.radius,
        }
    }

    /// The outward unit normal at surface point `p`.
    pub fn normal(&self, p: DVec3) -> DVec3 {
        let ba = self.b - self.a;
        let h = ((p - self.a).dot(ba) / ba.length_squared()).clamp(0.0, 1.0);
        (p - self.a - ba * h).normalize_or_zero()
    }
}

/// A [`Capsule`] seen from one ray start ([`Capsule::seen_from`]): what its ray test needs
/// that does not depend on the direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CapsuleFrom {
    /// The axis from end `a` to end `b`.
    ba: DVec3,
    /// The start from either end.
    oa: DVec3,
    ob: DVec3,
    /// `ba·ba`, `ba·oa`, and the constant term of the side's quadratic.
    baba: f64,
    baoa: f64,
    qc: f64,
    radius: f64,
}

impl CapsuleFrom {
    /// [`Capsule::hit`] for the unit direction `dir` from this start.
    #[inline]
    pub fn hit(&self, dir: DVec3, t_min: f64, t_max: f64) -> Option<f64> {
        let (bard, rdoa) = (self.ba.dot(dir), dir.dot(self.oa));
        let qa = self.baba - bard * bard;
        let qb = self.baba * rdoa - self.baoa * bard;
        let h = qb * qb - qa * self.qc;
        // Clearly outside the infinite cylinder around the axis, which holds both rounded ends
        // too (the margin is far above the rounding of `h`): most rays of a view.
        if qa > 0.0 && h < -MISS_MARGIN * (qb * qb + (qa * self.qc).abs()) {
            return None;
        }
        self.hit_near(dir, [bard, qa, qb, h], (t_min, t_max))
    }

    /// [`Self::hit`] for a ray near the capsule, given its terms `bard`, `qa`, `qb` and `h`.
    #[inline(never)]
    fn hit_near(
        &self,
        dir: DVec3,
        [bard, qa, qb, h]: [f64; 4],
        (t_min, t_max): (f64, f64),
    ) -> Option<f64> {
        let in_range = |t: f64| (t > t_min && t < t_max).then_some(t);
        // The side, where the ray meets the infinite cylinder between the ends.
        if qa > 0.0 && h >= 0.0 {
            let t = (-qb - h.sqrt()) / qa;
            let y = self.baoa + t * bard;
            if y > 0.0 && y < self.baba {
                return in_range(t);
            }
        }
        // The rounded ends: the nearer sphere the ray meets.
        [self.oa, self.ob]
            .iter()
            .filter_map(|&oc| sphere_crossings(oc, dir, self.radius).map(|(t, _)| t))
            .filter_map(in_range)
            .min_by(f64::total_cmp)
    }
}

/// An endoscope's instruments as the camera sees them (Scharsach et al. 2006, Figure 7): one
/// or two rods of `diameter_mm` leaving the lens plane beside the optical axis, below it, and
/// reaching `length_mm` ahead, where they end in a rounded tip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Endoscope {
    /// Diameter of an instrument, mm.
    pub diameter_mm: f64,
    /// How far ahead of the lens the tip reaches, mm.
    pub length_mm: f64,
    /// Whether a second instrument comes out of a second channel (lower right).
    pub second_instrument: bool,
}

/// The default reach of an instrument ahead of the lens, mm.
pub const DEFAULT_INSTRUMENT_LENGTH_MM: f64 = 20.0;

impl Endoscope {
    /// One instrument of `diameter_mm` reaching `length_mm` ahead (both finite and positive).
    pub fn new(diameter_mm: f64, length_mm: f64) -> Result<Self, SceneError> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(diameter_mm) || !positive(length_mm) {
            return Err(SceneError::BadEndoscope(diameter_mm, length_mm));
        }
        Ok(Self {
            diameter_mm,
            length_mm,
            second_instrument: false,
        })
    }

    /// The same endoscope with a second instrument (or without it).
    pub fn with_second_instrument(self, second: bool) -> Self {
        Self {
            second_instrument: second,
            ..self
        }
    }

    /// The instruments placed for a camera at `eye` with unit `forward`, `right` and `up`: axes
    /// parallel to the view direction, 1.25 diameters from it, 45° to the left of straight
    /// down (the second one 45° to the right), from the lens plane to the tip.
    pub fn instruments(&self, eye: DVec3, [forward, right, up]: [DVec3; 3]) -> Vec<Capsule> {
        let (sin, cos) = 45f64.to_radians().sin_cos();
        let sides: &[f64] = if self.second_instrument {
            &[-1.0, 1.0]
        } else {
            &[-1.0]
        };
        sides
            .iter()
            .map(|side| {
                let offset = (right * (side * sin) - up * cos) * (1.25 * self.diameter_mm);
                Capsule {
                    a: eye + offset,
                    b: eye + offset + forward * self.length_mm,
                    radius: 0.5 * self.diameter_mm,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_lines_lie_on_the_multiples_of_the_spacing() {
        let grid = GridPlane::new(DVec3::new(1.0, 2.0, 3.0), DVec3::Z * 2.0, 10.0).unwrap();
        assert_eq!(grid.axes(), [DVec3::X, DVec3::Y]);
        assert!(grid.on_line(DVec3::new(21.2, 7.0, 3.0)));
        assert!(!grid.on_line(DVec3::new(22.0, 7.0, 3.0)));
        assert!(grid.on_line(DVec3::new(6.0, -7.9, 3.0)));
        let t = grid.hit(DVec3::new(1.0, 5.0, -7.0), DVec3::Z, 0.0, 100.0);
        assert_eq!(t, Some(10.0));
        assert_eq!(
            grid.moved(5.0)
                .hit(DVec3::new(1.0, 5.0, -7.0), DVec3::Z, 0.0, 100.0),
            Some(15.0)
        );
        assert!(grid
            .hit(DVec3::new(1.0, 5.0, -7.0), DVec3::Z, 0.0, 9.0)
            .is_none());
        assert!(GridPlane::new(DVec3::ZERO, DVec3::ZERO, 1.0).is_err());
        assert!(grid.with_spacing(5.0, 6.0).is_err());
    }

    /// The distance from `p` to the segment `a`–`b`.
    fn to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
        let ba = b - a;
        let h = ((p - a).dot(ba) / ba.length_squared()).clamp(0.0, 1.0);
        (p - a - ba * h).length()
    }

    #[test]
    fn a_ray_meets_a_capsule_where_it_comes_within_the_radius_of_its_axis() {
        let mut s = crate::test_rng::Rng::new(23);
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..4000 {
            let (a, b) = (s.vec() * 10.0, s.vec() * 10.0);
            let radius = 0.2 + 2.0 * s.unit();
            let c = Capsule { a, b, radius };
            // Rays from far away through points near the capsule: beside its side, beyond its
            // ends, grazing it.
            let along = a + (b - a) * (1.4 * s.unit() - 0.2);
            let aim = along + s.vec().normalize() * radius * (0.5 + 1.5 * s.unit());
            let origin = aim + s.vec().normalize() * 40.0;
            let dir = (aim - origin).normalize();
            // The distance to the axis along the ray is convex: its minimum by ternary search.
            let gap = |t: f64| to_segment(origin + dir * t, a, b);
            let (mut lo, mut hi) = (0.0, 80.0);
            for _ in 0..200 {
                let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
                (lo, hi) = if gap(m1) < gap(m2) {
                    (lo, m2)
                } else {
                    (m1, hi)
                };
            }
            let closest = gap(lo);
            let found = c.hit(origin, dir, 0.0, 100.0);
            if closest < radius * (1.0 - 1e-6) {
                let t = found.expect("a ray that passes within the radius meets the capsule");
                assert!(
                    (gap(t) - radius).abs() < 1e-9 * (1.0 + radius),
                    "on the surface"
                );
                assert!(t <= lo + 1e-9, "the entry, not the exit");
                hits += 1;
            } else if closest > radius * (1.0 + 1e-6) {
                assert_eq!(found, None, "a ray that stays outside the radius misses");
                misses += 1;
            }
        }
        assert!(hits > 1000 && misses > 1000, "{hits} hits, {misses} misses");
    }

    #[test]
    fn capsule_hits_side_and_tip() {
        let c = Capsule {
            a: DVec3::ZERO,
            b: DVec3::Z * 10.0,
            radius: 1.0,
        };
        let side = c
            .hit(DVec3::new(-5.0, 0.0, 4.0), DVec3::X, 0.0, 100.0)
            .unwrap();
        assert!((side - 4.0).abs() < 1e-12);
        let tip = c
            .hit(DVec3::new(0.0, 0.0, 20.0), -DVec3::Z, 0.0, 100.0)
            .unwrap();
        assert!((tip - 9.0).abs() < 1e-12);
        let n = c.normal(DVec3::new(0.0, 0.0, 11.0));
        assert!((n - DVec3::Z).length() < 1e-12);
        assert!(c
            .hit(DVec3::new(-5.0, 3.0, 4.0), DVec3::X, 0.0, 100.0)
            .is_none());
    }
}
