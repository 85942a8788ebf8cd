//! The camera options `render`, `fly` and `bench` share — the lens's projection, distortion
//! and vignetting — and the stereo options of `render` and `fly`.

use crate::look::flag_error;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::camera::{Optics, Projection, StereoRig};
use endocast_core::look::Look;
use endocast_core::presets::{self, Preset};
use endocast_core::study::LensOptions;
use endocast_core::views::stereo::StereoOutput;
use std::path::{Path, PathBuf};

/// How the camera forms its image.
#[derive(Args, Debug, Clone, Default)]
pub struct LensArgs {
    /// Lens projection: pinhole; equidistant or equisolid (fisheye: a round image, --fov up to
    /// 360°, default 170°); orthographic (parallel rays: --fov is the view height in mm); cube
    /// (the unfolded cube: six 90° views around the eye in a cross — up above front; left,
    /// front, right, back in a row; down below front — labelled; a 4:3 image such as 768x576
    /// fills it); panorama (360° equirectangular around the camera's up: front in the middle,
    /// the seam behind at both edges, --fov the latitudes spanned, default 180; 2:1 for square
    /// pixels, e.g. 1024x512). The cube and the panorama take no distortion, vignetting or
    /// stereo. Default: the preset's, else pinhole.
    #[arg(long, value_name = "PROJECTION", value_parser = parse_projection)]
    pub lens: Option<Projection>,
    /// Radial lens distortion (Brown–Conrady) on image coordinates normalised to the half
    /// height: K1 < 0 is the barrel distortion of a real endoscope. Default: the look's lens —
    /// with --look realistic a rigid sinus endoscope's (-0.166,0.0246 on a pinhole; none on a
    /// fisheye, which is its own wide-angle compression), else none; 0,0 for an ideal lens.
    /// Where a strong barrel distortion folds, the picture ends in a round field stop.
    #[arg(long, value_name = "K1,K2", value_parser = parse_pair, allow_hyphen_values = true)]
    pub distortion: Option<[f64; 2]>,
    /// Darkening toward the image edge, 0–1 (1: black corners). Default: the look's lens —
    /// with --look realistic a rigid endoscope's 0.6 (0.3 on a fisheye, whose edge is its
    /// circle's), else 0.
    #[arg(long, value_name = "0..1", allow_negative_numbers = true)]
    pub vignetting: Option<f64>,
}

impl LensArgs {
    /// The optics for `fov` (the `--fov` given, if any) under `preset` and `look` (its default
    /// lens; `None`: the plain look), with `near_mm`. An orthographic view without `--fov` is
    /// `default_height_mm` tall.
    pub fn optics(
        &self,
        preset: Option<&Preset>,
        look: Option<&Look>,
        fov: Option<f64>,
        near_mm: f64,
        default_height_mm: f64,
    ) -> Result<Optics> {
        let (projection, field) = presets::lens_defaults(preset, self.lens, fov, default_height_mm);
        let (min, max) = projection.field_range();
        if !(min..=max).contains(&field) {
            bail!(
                "invalid camera: --fov {field} lies outside {min}–{max} {} for --lens {}",
                projection.field_unit(),
                projection.name()
            );
        }
        Ok(Optics {
            projection,
            field,
            lens: LensOptions {
                distortion: self.distortion,
                vignetting: self.vignetting,
            }
            .resolve(look, projection)
            .map_err(flag_error)?,
            near_mm,
        })
    }
}

/// Stereo viewing.
#[derive(Args, Debug, Clone, Default)]
pub struct StereoArgs {
    /// Render a stereo pair (two off-axis eyes): anaglyph (red/blue, VIVENDI's), red-cyan,
    /// dubois (colour anaglyph), side-by-side, top-bottom, or pair (OUT-left and OUT-right);
    /// in any --look, meshes and markers drawn in each eye.
    #[arg(long, value_name = "OUTPUT", value_parser = parse_stereo)]
    pub stereo: Option<StereoOutput>,
    /// Distance between the eyes, mm (default: the focus distance / 30).
    #[arg(
        long,
        value_name = "MM",
        requires = "stereo",
        allow_negative_numbers = true
    )]
    pub eye_separation: Option<f64>,
    /// Distance of the zero-parallax (focus) plane, mm (default: the nearest surface in view,
    /// so that the scene lies behind the screen).
    #[arg(
        long,
        value_name = "MM",
        requires = "stereo",
        allow_negative_numbers = true
    )]
    pub focus: Option<f64>,
}

impl StereoArgs {
    /// The rig, the focus distance taken from `nearest` (mm) when not given; `None` without
    /// `--stereo`.
    pub fn rig(
        &self,
        nearest: impl FnOnce() -> Option<f64>,
    ) -> Result<Option<(StereoRig, StereoOutput)>> {
        let Some(output) = self.stereo else {
            return Ok(None);
        };
        let rig = StereoRig::for_view(self.eye_separation, self.focus, nearest)
            .context("invalid --stereo options")?;
        Ok(Some((rig, output)))
    }
}

/// `dir/name.ext` as `dir/name-ending.ext` (a folder `dir/name` as `dir/name-ending`).
pub fn beside(path: &Path, ending: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or_else(Default::default, |s| s.to_string_lossy());
    let name = match path.extension() {
        Some(e) => format!("{stem}-{ending}.{}", e.to_string_lossy()),
        None => format!("{stem}-{ending}"),
    };
    path.with_file_name(name)
}

/// A projection by name.
fn parse_projection(text: &str) -> Result<Projection, String> {
    Projection::from_name(text)
        .ok_or_else(|| format!("unknown lens {text:?}: use {}", Projection::choices()))
}

/// A stereo output by name.
fn parse_stereo(text: &str) -> Result<StereoOutput, String> {
    StereoOutput::from_name(text).ok_or_else(|| {
        format!("unknown stereo output {text:?}: use anaglyph, red-cyan, dubois, side-by-side, top-bottom or pair")
    })
}

/// Two comma-separated finite numbers.
fn parse_pair(text: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [a, b] = parts[..] else {
        return Err(format!("expected two numbers K1,K2, not {text:?}"));
    };
    let number = |s: &str| match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("{s:?} is not a finite number")),
    };
    Ok([number(a)?, number(b)?])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lens_defaults_follow_the_projection() {
        let args = |lens| LensArgs {
            lens,
            ..LensArgs::default()
        };
        let pinhole = args(None).optics(None, None, None, 0.0, 50.0).unwrap();
        assert_eq!(
            (pinhole.projection, pinhole.field),
            (Projection::Pinhole, 90.0)
        );
        let fisheye = args(Some(Projection::Equidistant));
        assert_eq!(
            fisheye.optics(None, None, None, 0.0, 50.0).unwrap().field,
            170.0
        );
        assert_eq!(
            fisheye
                .optics(None, None, Some(200.0), 0.0, 50.0)
                .unwrap()
                .field,
            200.0
        );
        let ortho = args(Some(Projection::Orthographic));
        assert_eq!(
            ortho.optics(None, None, None, 0.0, 50.0).unwrap().field,
            50.0
        );
        assert!(args(None)
            .optics(None, None, Some(200.0), 0.0, 50.0)
            .is_err());
        assert!(parse_pair("-0.2,0.05").is_ok());
        assert!(parse_pair("nan,0").is_err() && parse_pair("1").is_err());
        assert!(parse_projection("fisheye").is_err());
    }

    #[test]
    fn stereo_defaults_put_the_focus_on_the_nearest_surface() {
        let none = StereoArgs::default();
        assert!(none.rig(|| Some(10.0)).unwrap().is_none());
        let args = StereoArgs {
            stereo: Some(StereoOutput::Anaglyph),
            ..StereoArgs::default()
        };
        let (rig, _) = args.rig(|| Some(12.0)).unwrap().unwrap();
        let (blind, _) = args.rig(|| None).unwrap().unwrap();
        assert_eq!(blind.focus_mm, endocast_core::camera::FALLBACK_FOCUS_MM);
        assert_eq!(rig.focus_mm, 12.0);
        assert!((rig.eye_separation_mm - 0.4).abs() < 1e-12);
        let bad = StereoArgs {
            focus: Some(f64::NAN),
            ..args
        };
        assert!(bad.rig(|| Some(12.0)).is_err());
    }
}
