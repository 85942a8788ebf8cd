//! What a real endoscope's optics add to the ideal projection: radial (Brown–Conrady) lens
//! distortion and vignetting.
//!
//! Both act on normalised image coordinates `(u, v)`: the image centre is `(0, 0)`, `v = 1` at
//! the top edge and `u` grows to the right in the same unit (half the image height), so the
//! coefficients do not depend on the image size. As in OpenCV's model, the distortion maps the
//! ideal position to the one the sensor records, `p_d = p_u · (1 + k1·r_u² + k2·r_u⁴)`: barrel
//! distortion (the wide endoscope look) has `k1 < 0`.

/// Largest magnitude accepted for each distortion coefficient.
pub const MAX_DISTORTION: f64 = 2.0;

/// Radial distortion and vignetting of a camera. The default is a perfect lens.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Lens {
    /// Brown–Conrady radial coefficients `[k1, k2]`, see the module doc.
    pub distortion: [f64; 2],
    /// Darkening toward the edge, 0–1: the brightness is `1 − vignetting · ρ²`, with `ρ` the
    /// distance from the centre relative to the image's half diagonal (or, for a fisheye, to
    /// the radius of its image circle).
    pub vignetting: f64,
}

impl Lens {
    /// Whether the lens leaves the ideal projection as it is.
    pub fn is_ideal(&self) -> bool {
        self.distortion == [0.0, 0.0]
    }

    /// Whether the lens neither distorts nor darkens the image.
    pub fn is_plain(&self) -> bool {
        self.is_ideal() && self.vignetting == 0.0
    }

    /// The radial factor `1 + k1·r² + k2·r⁴` at undistorted radius² `r2`.
    fn factor(&self, r2: f64) -> f64 {
        let [k1, k2] = self.distortion;
        1.0 + r2 * (k1 + k2 * r2)
    }

    /// The recorded (distorted) position of the ideal position `(u, v)`.
    pub fn distort(&self, (u, v): (f64, f64)) -> (f64, f64) {
        if self.is_ideal() {
            return (u, v);
        }
        let f = self.factor(u * u + v * v);
        (u * f, v * f)
    }

    /// The factor `s` with ideal position = recorded position · `s`, for a recorded position at
    /// radius `r_d`; `None` where no ideal position maps there (beyond the radius at which a
    /// strong barrel distortion folds back). Newton's method on `r·(1 + k1 r² + k2 r⁴) = r_d`,
    /// converged to 1e-14.
    pub fn undistort_scale(&self, r_d: f64) -> Option<f64> {
        if self.is_ideal() || r_d == 0.0 {
            return Some(1.0);
        }
        let [k1, k2] = self.distortion;
        let mut r = r_d;
        for _ in 0..50 {
            let r2 = r * r;
            let g = r * self.factor(r2) - r_d;
            let slope = 1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2;
            if slope <= 1e-9 {
                return None;
            }
            let next = r - g / slope;
            if !next.is_finite() || next <= 0.0 {
                return None;
            }
            let done = (next - r).abs() <= 1e-14 * r.max(1.0);
            r = next;
            if done {
                // Only the branch before the fold is the lens's image.
                let r2 = r * r;
                let slope = 1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2;
                return (slope > 0.0).then_some(r / r_d);
            }
        }
        None
    }

    /// The brightness factor (0–1) at relative radius² `rho2` (see [`Lens::vignetting`]).
    pub fn brightness(&self, rho2: f64) -> f64 {
        (1.0 - self.vignetting * rho2).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undistortion_inverts_distortion() {
        for distortion in [[-0.3, 0.05], [0.2, 0.0], [-0.1, -0.02], [0.0, 0.3]] {
            let lens = Lens {
                distortion,
                vignetting: 0.0,
            };
            for &(u, v) in &[(0.3, 0.1), (-0.7, 0.5), (0.0, -0.9), (1.1, 0.4)] {
                let (du, dv) = lens.distort((u, v));
                let s = lens
                    .undistort_scale(du.hypot(dv))
                    .expect("inside the image");
                assert!((du * s - u).abs() < 1e-12 && (dv * s - v).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn barrel_distortion_pulls_the_edge_in_and_folds_beyond_its_image() {
        let lens = Lens {
            distortion: [-0.4, 0.0],
            vignetting: 0.0,
        };
        let (u, _) = lens.distort((1.0, 0.0));
        assert!(u < 1.0);
        // r(1 − 0.4 r²) peaks at r = 0.913 with r_d = 0.609: nothing is recorded beyond.
        assert!(lens.undistort_scale(0.6).is_some());
        assert!(lens.undistort_scale(0.7).is_none());
    }

    #[test]
    fn vignetting_darkens_toward_the_edge() {
        let lens = Lens {
            distortion: [0.0; 2],
            vignetting: 0.5,
        };
        assert_eq!(lens.brightness(0.0), 1.0);
        assert!((lens.brightness(1.0) - 0.5).abs() < 1e-12);
        assert_eq!(Lens::default().brightness(1.0), 1.0);
    }
}
