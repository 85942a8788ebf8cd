//! The lens a user asks for over a look's own ([`LookKind::default_lens`]: the realistic
//! look's rigid endoscope), checked once for every front end.

use super::options::OptionError;
use crate::camera::lens::MAX_DISTORTION;
use crate::camera::{Lens, Projection};
use crate::look::{Look, LookKind};

/// The lens options given; `None` keeps the look's default lens.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LensOptions {
    /// Brown–Conrady radial coefficients `[k1, k2]` (`[0, 0]`: no distortion).
    pub distortion: Option<[f64; 2]>,
    /// Vignetting, 0–1 (0: none).
    pub vignetting: Option<f64>,
}

impl LensOptions {
    /// The lens of a `projection` camera in `look` (`None`: the plain look): the look's default
    /// with every option given on top, so `distortion [0, 0]` and `vignetting 0` give the
    /// ideal lens back. Errors name the option (NaN, infinite or out of range).
    pub fn resolve(
        &self,
        look: Option<&Look>,
        projection: Projection,
    ) -> Result<Lens, OptionError> {
        let kind = look.map_or(LookKind::Plain, |l| l.kind);
        let mut lens = kind.default_lens(projection);
        if let Some(k) = self.distortion {
            if k.iter()
                .any(|k| !(k.is_finite() && k.abs() <= MAX_DISTORTION))
            {
                return Err(OptionError {
                    option: "distortion",
                    problem: format!(
                        "must be two finite numbers K1,K2 within ±{MAX_DISTORTION}, not {},{}",
                        k[0], k[1]
                    ),
                });
            }
            lens.distortion = k;
        }
        if let Some(v) = self.vignetting {
            if !(0.0..=1.0).contains(&v) {
                return Err(OptionError {
                    option: "vignetting",
                    problem: format!("must be between 0 and 1, not {v}"),
                });
            }
            lens.vignetting = v;
        }
        Ok(lens)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::look::PresetLook;

    #[test]
    fn the_realistic_look_sees_through_the_endoscope_and_options_win() {
        let realistic = Look::of_kind(LookKind::Realistic, &PresetLook::CT);
        let clinical = Look::of_kind(LookKind::Clinical, &PresetLook::CT);
        let none = LensOptions::default();
        let pinhole = Projection::Pinhole;
        let lens = |o: &LensOptions, look: Option<&Look>, p| o.resolve(look, p).unwrap();
        assert_eq!(
            lens(&none, realistic.as_ref(), pinhole),
            Lens::RIGID_ENDOSCOPE
        );
        assert_eq!(lens(&none, clinical.as_ref(), pinhole), Lens::default());
        assert_eq!(lens(&none, None, pinhole), Lens::default());
        let fisheye = lens(&none, realistic.as_ref(), Projection::Equidistant);
        assert!(fisheye.is_ideal() && fisheye.vignetting > 0.0);
        let ideal = LensOptions {
            distortion: Some([0.0, 0.0]),
            vignetting: Some(0.0),
        };
        assert_eq!(lens(&ideal, realistic.as_ref(), pinhole), Lens::default());
        let only_k = LensOptions {
            distortion: Some([-0.1, 0.0]),
            ..LensOptions::default()
        };
        let given = lens(&only_k, realistic.as_ref(), pinhole);
        assert_eq!(given.distortion, [-0.1, 0.0]);
        assert_eq!(given.vignetting, Lens::RIGID_ENDOSCOPE.vignetting);
    }

    #[test]
    fn nan_and_out_of_range_lenses_name_the_option() {
        for (options, key) in [
            (
                LensOptions {
                    distortion: Some([f64::NAN, 0.0]),
                    ..LensOptions::default()
                },
                "distortion",
            ),
            (
                LensOptions {
                    distortion: Some([0.0, 3.0]),
                    ..LensOptions::default()
                },
                "distortion",
            ),
            (
                LensOptions {
                    vignetting: Some(f64::NAN),
                    ..LensOptions::default()
                },
                "vignetting",
            ),
            (
                LensOptions {
                    vignetting: Some(-0.1),
                    ..LensOptions::default()
                },
                "vignetting",
            ),
        ] {
            let e = options.resolve(None, Projection::Pinhole).unwrap_err();
            assert_eq!(e.option, key);
        }
    }
}
