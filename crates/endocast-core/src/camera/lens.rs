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

/// Width of the soft edge of the field stop where a strong barrel distortion folds (see
/// [`Lens::image_radius`]), pixels.
const STOP_EDGE_PX: f64 = 2.0;

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
    /// A typical rigid (sinus, 4 mm Hopkins-type) endoscope: barrel distortion
    /// `k1 = −0.166, k2 = 0.0246` and vignetting 0.6 — the realistic look's lens on a pinhole
    /// camera ([`crate::look::LookKind::default_lens`]).
    ///
    /// The distortion follows the measurements of 4 mm 0°–70° rigid sinus endoscopes in
    /// "Defining optical distortion in rigid endoscopes" (Laryngoscope 2015, 125(3):561–566,
    /// doi:10.1002/lary.24971, PMID 25346136): all showed similar barrel distortion, with
    /// the relative size of an object at the periphery of the image 52 % of its size at the
    /// centre and its relative distance from the centre 80 %. Read as the radial model's
    /// ratio `r_d / r_u = 1 + k1 R² + k2 R⁴ = 0.80` and local radial magnification
    /// `d r_d / d r_u = 1 + 3 k1 R² + 5 k2 R⁴ = 0.52` at the periphery's undistorted radius
    /// `R`, this gives `k1 R² = −0.26, k2 R⁴ = 0.06`. The endoscope's round image is put on the
    /// circle inscribed in the image height (recorded radius 1 in our normalisation, half the
    /// image height), so `R = 1 / 0.80 = 1.25` and `k1 = −0.26 / 1.25² = −0.166`,
    /// `k2 = 0.06 / 1.25⁴ = 0.0246`. With these, `r·(1 + k1 r² + k2 r⁴)` rises everywhere (no
    /// fold: every pixel, the corners of any aspect included, has a ray).
    ///
    /// The vignetting follows "Light intensity distribution in images from rigid endoscopes
    /// used in minimal access sinus surgery" (Abel, Fotiadis, White; Laryngoscope Investig.
    /// Otolaryngol. 2021, 6(6):1283–1288, PMC8665470): a 0° endoscope 10 mm from a flat grid
    /// records about 230 grey levels at the centre and 100 at the periphery (0.43). The look's
    /// own tip light already darkens that periphery (51° off axis through this lens at a 90°
    /// field: Lambert `0.12 + 0.88 cos`, and the fall-off with distance) to 0.61 of the centre;
    /// the optics take the rest, `0.43 / 0.61 = 0.71 = 1 − v · ρ²` with `ρ² = ½` on the inscribed
    /// circle of a square image, so `v ≈ 0.6`.
    pub const RIGID_ENDOSCOPE: Lens = Lens {
        distortion: [-0.166, 0.0246],
        vignetting: 0.6,
    };

    /// Whether the lens leaves the ideal projection as it is.
    pub fn is_ideal(&self) -> bool {
        self.distortion == [0.0, 0.0]
    }

    /// Whether the lens darkens any pixel: vignetting, or the field stop of a distortion that
    /// folds ([`Lens::image_radius`]).
    pub fn darkens(&self) -> bool {
        self.vignetting > 0.0 || self.image_radius().is_some()
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

    /// The largest recorded radius the lens forms an image at, where a strong barrel
    /// distortion folds back (`d r_d / d r_u = 1 + 3 k1 r² + 5 k2 r⁴` reaches 0); `None` when
    /// it never folds. Beyond it the camera has no ray: the endoscope's round field stop.
    pub fn image_radius(&self) -> Option<f64> {
        let [k1, k2] = self.distortion;
        // The smallest positive root s = r² of 5 k2 s² + 3 k1 s + 1.
        let fold = if k2 == 0.0 {
            (k1 < 0.0).then(|| -1.0 / (3.0 * k1))
        } else {
            let disc = 9.0 * k1 * k1 - 20.0 * k2;
            let roots = (disc >= 0.0).then(|| {
                let root = disc.sqrt();
                [
                    (-3.0 * k1 - root) / (10.0 * k2),
                    (-3.0 * k1 + root) / (10.0 * k2),
                ]
            });
            roots.and_then(|r| r.into_iter().filter(|s| *s > 0.0).reduce(f64::min))
        }?;
        Some(fold.sqrt() * self.factor(fold))
    }

    /// The field stop's soft edge at recorded radius `r_d`: 1 inside, falling smoothly to 0
    /// over the last [`STOP_EDGE_PX`] pixels (of `px` normalised units each) before the
    /// [`Lens::image_radius`], so the round edge of the picture is drawn, not cut.
    pub fn field_stop(&self, r_d: f64, px: f64) -> f64 {
        self.image_radius().map_or(1.0, |edge| {
            let x = ((edge - r_d) / (STOP_EDGE_PX * px)).clamp(0.0, 1.0);
            x * x * (3.0 - 2.0 * x)
        })
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
    fn the_fold_is_the_image_radius() {
        // k2 = 0: r(1 − 0.4 r²) peaks at r = 0.913, r_d = 0.609 (as above).
        let lens = Lens {
            distortion: [-0.4, 0.0],
            vignetting: 0.0,
        };
        let edge = lens.image_radius().unwrap();
        assert!((edge - 2.0 / 3.0 / 1.2f64.sqrt()).abs() < 1e-12);
        assert!(lens.undistort_scale(edge * 0.999).is_some());
        assert!(lens.undistort_scale(edge * 1.001).is_none());
        assert_eq!(lens.field_stop(edge * 0.5, 0.01), 1.0);
        assert_eq!(lens.field_stop(edge, 0.01), 0.0);
        let soft = lens.field_stop(edge - 0.01, 0.01);
        assert!(soft > 0.0 && soft < 1.0);
        // Both roots: 1 − 1.5 s + 0.5 s² (k1 = −0.5, k2 = 0.1) folds at s = 1.
        let both = Lens {
            distortion: [-0.5, 0.1],
            vignetting: 0.0,
        };
        assert!((both.image_radius().unwrap() - 0.6).abs() < 1e-12);
        for ideal in [Lens::default(), Lens::RIGID_ENDOSCOPE] {
            assert_eq!(ideal.image_radius(), None);
            assert_eq!(ideal.field_stop(5.0, 0.01), 1.0);
        }
    }

    #[test]
    fn the_rigid_endoscope_matches_its_measurements() {
        // Relative distance 0.80 and relative size 0.52 at the periphery, recorded at radius 1.
        let lens = Lens::RIGID_ENDOSCOPE;
        let r = 1.0 / lens.undistort_scale(1.0).unwrap();
        assert!((r - 0.8).abs() < 0.005, "{r}");
        let [k1, k2] = lens.distortion;
        let big_r2 = (1.0 / r).powi(2);
        let size = 1.0 + 3.0 * k1 * big_r2 + 5.0 * k2 * big_r2 * big_r2;
        assert!((size - 0.52).abs() < 0.01, "{size}");
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
