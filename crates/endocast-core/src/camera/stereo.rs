//! Stereo as in VIVENDI (del Río et al., WSCG 2003): two eyes `e` mm apart, each an off-axis
//! camera (an asymmetric frustum, never toe-in) whose rays meet the centre camera's on the
//! focus (zero-parallax) surface. The paper puts that surface in the foreground, so the scene
//! lies behind the screen (positive, uncrossed parallax), which is what the default does.

use super::{Camera, CameraError, EyeShift, Projection};

/// The eye separation the default rig takes per mm of focus distance: the usual 1/30 rule,
/// which keeps the largest disparity (a point at infinity) at 1/30 of the image plane's
/// half-height at 90°.
pub const SEPARATION_PER_FOCUS: f64 = 1.0 / 30.0;

/// The focus distance of a view that shows no surface, mm.
pub const FALLBACK_FOCUS_MM: f64 = 10.0;

/// A stereo rig: eye separation and focus distance, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StereoRig {
    /// Distance between the two eyes, mm.
    pub eye_separation_mm: f64,
    /// Distance from the centre eye to the zero-parallax plane (sphere for a fisheye), mm.
    pub focus_mm: f64,
}

impl StereoRig {
    /// A rig focused at `focus_mm` with the eye separation of the 1/30 rule
    /// ([`SEPARATION_PER_FOCUS`]).
    pub fn focused_at(focus_mm: f64) -> Self {
        Self {
            eye_separation_mm: focus_mm * SEPARATION_PER_FOCUS,
            focus_mm,
        }
    }

    /// The rig for a view: `focus_mm` when given, else the nearest surface in view
    /// (`nearest`, mm; [`FALLBACK_FOCUS_MM`] where it sees none), so the scene lies behind the
    /// screen; `eye_separation_mm` when given, else the 1/30 rule. Fails on a non-positive or
    /// non-finite distance, or eyes farther apart than twice the focus distance.
    pub fn for_view(
        eye_separation_mm: Option<f64>,
        focus_mm: Option<f64>,
        nearest: impl FnOnce() -> Option<f64>,
    ) -> Result<Self, CameraError> {
        let focus_mm = match focus_mm {
            Some(f) => f,
            None => nearest().unwrap_or(FALLBACK_FOCUS_MM),
        };
        let eye_separation_mm = eye_separation_mm.unwrap_or(focus_mm * SEPARATION_PER_FOCUS);
        for (name, value) in [
            ("focus distance", focus_mm),
            ("eye separation", eye_separation_mm),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(CameraError::BadStereo(format!(
                    "the {name} must be a positive number of mm, not {value}"
                )));
            }
        }
        if eye_separation_mm >= 2.0 * focus_mm {
            return Err(CameraError::BadStereo(format!(
                "the eye separation {eye_separation_mm} mm must be less than twice the focus distance {focus_mm} mm"
            )));
        }
        Ok(Self {
            eye_separation_mm,
            focus_mm,
        })
    }

    /// The left and right eyes of `camera`.
    pub fn eyes(&self, camera: &Camera) -> Result<[Camera; 2], CameraError> {
        let (e, f) = (self.eye_separation_mm, self.focus_mm);
        if !(e.is_finite() && e > 0.0) {
            return Err(CameraError::BadStereo(format!(
                "the eye separation must be a positive number of mm, not {e}"
            )));
        }
        if camera.projection() == Projection::Orthographic {
            return Err(CameraError::BadStereo(
                "an orthographic camera has no stereo eyes".into(),
            ));
        }
        let eye = |sign: f64| {
            camera.with_eye_shift(EyeShift {
                offset_mm: sign * e / 2.0,
                focus_mm: f,
            })
        };
        Ok([eye(-1.0)?, eye(1.0)?])
    }
}

/// The horizontal disparity `x_right − x_left`, in pixels, of a point `depth_mm` in front of a
/// pinhole rig's centre eye (depth along the view axis): `e · (1/f − 1/z)` on the image plane at
/// distance 1, scaled to pixels. Zero on the focus plane, positive (uncrossed) behind it.
pub fn disparity_px(camera: &Camera, rig: &StereoRig, depth_mm: f64) -> f64 {
    let tan_half = (camera.fov_deg().to_radians() / 2.0).tan();
    let plane = rig.eye_separation_mm * (1.0 / rig.focus_mm - 1.0 / depth_mm);
    plane / tan_half * camera.size()[1] as f64 / 2.0
}
