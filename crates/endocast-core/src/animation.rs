//! Key-frame animation: camera poses *and* render parameters at a few key frames, interpolated
//! into a flight played at constant speed (Sinus Endoscopy, Krüger et al. 2008, §5.1: positions
//! on a Catmull-Rom spline, rotations by quaternion slerp).
//!
//! - Eye positions follow a centripetal Catmull-Rom spline through the key positions
//!   ([`crate::path::spline`]), which cannot loop or overshoot between close keys.
//! - Orientations are slerped along the short arc between consecutive keys (`q` and `−q` are the
//!   same rotation; the interpolation does not care which one a key holds).
//! - Field of view, isovalue and isosurface opacity are interpolated linearly; the transfer
//!   function, a name, switches halfway between two keys.
//! - Playback is parametrised by *playback length* in mm: along a segment where the eye moves,
//!   the playback length is the eye's arc length, so the camera flies at constant speed whatever
//!   the spacing of the keys. A segment that mostly turns (keys at or near one position) lasts as
//!   long as a flight of [`MM_PER_RAD`] mm per radian of turn, and one that neither moves nor
//!   turns (a hold, or a change of isovalue only) lasts [`HOLD_MM`] mm: a segment's playback
//!   length is `max(arc, MM_PER_RAD · turn)`, or `HOLD_MM` when that is zero. Within a segment
//!   the eye moves along its arc, and the rotation and scalars change, in proportion to playback.
//!
//! ```
//! use endocast_core::animation::{Animation, KeyFrame};
//! use glam::DVec3;
//!
//! let key = |x: f64, forward: DVec3| KeyFrame::new(DVec3::new(x, 0.0, 0.0), forward, DVec3::Z, 60.0, -500.0, 1.0);
//! let animation = Animation::new(vec![key(0.0, DVec3::X)?, key(30.0, DVec3::Y)?])?;
//! let frames: Vec<KeyFrame> = animation.frames(31).collect();
//! assert!((frames[15].eye_mm.x - 15.0).abs() < 1e-6);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::path::spline::{ArcTable, CatmullRom};
use crate::path::PathError;
use crate::pose::Pose;
use crate::render::{Camera, CameraError, FOV_RANGE_DEG};
use glam::{DMat3, DQuat, DVec3};
use thiserror::Error;

/// Playback length of a turn of one radian without movement, mm.
pub const MM_PER_RAD: f64 = 10.0;
/// Playback length of a segment whose keys share position and orientation, mm.
pub const HOLD_MM: f64 = 10.0;
/// Arc-length table pieces per eye path: a relative arc-length error far below 1 %.
const TABLE_PIECES: f64 = 10_000.0;

/// A key frame that is not usable.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum KeyFrameError {
    /// A position, vector or number is NaN or infinite.
    #[error("{0} {1:?} is not finite")]
    NotFinite(&'static str, Vec<f64>),
    /// The forward direction is zero, or the up vector is zero or parallel to it.
    #[error("forward {0:?} and up {1:?} do not span a camera frame")]
    NoFrame([f64; 3], [f64; 3]),
    /// The orientation quaternion is zero (it is normalised otherwise).
    #[error("orientation quaternion {0:?} is zero")]
    ZeroOrientation([f64; 4]),
    /// The vertical field of view lies outside [`FOV_RANGE_DEG`].
    #[error("field of view {0}° lies outside 10°–170°")]
    BadFov(f64),
    /// The isosurface opacity lies outside [0, 1].
    #[error("isosurface opacity {0} lies outside [0, 1]")]
    BadOpacity(f64),
}

/// An animation that cannot be built.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum AnimationError {
    /// No key frames at all.
    #[error("an animation needs at least one key frame, found none")]
    NoKeys,
    /// One key frame is not usable.
    #[error("key frame {index}: {source}")]
    Key {
        /// Index of the key frame.
        index: usize,
        /// What is wrong with it.
        source: KeyFrameError,
    },
    /// The eye path cannot be tabulated.
    #[error("eye path: {0}")]
    Path(#[from] PathError),
}

/// The state of the camera and renderer at one moment of a flight.
///
/// `orientation` rotates camera axes into world (LPS) axes, with the OpenGL convention: the
/// camera looks along its −Z axis, +Y is up in the image and +X is right. So
/// `forward = orientation · (−Z)`, `up = orientation · Y` and `right = orientation · X =
/// forward × up`, as [`Camera`] has it.
#[derive(Debug, Clone, PartialEq)]
pub struct KeyFrame {
    /// Eye position, world mm.
    pub eye_mm: DVec3,
    /// Camera-to-world rotation (unit quaternion), see the type's docs.
    pub orientation: DQuat,
    /// Vertical field of view, degrees.
    pub fov_deg: f64,
    /// Isovalue of the wall surface, physical units (HU for CT).
    pub iso_hu: f64,
    /// Opacity of the isosurface in [0, 1].
    pub iso_opacity: f64,
    /// Transfer function: a preset name or a file name; `None` keeps the renderer's.
    pub tf: Option<String>,
}

impl KeyFrame {
    /// A key frame at `eye_mm` looking along `forward` with `up` (only its part perpendicular
    /// to `forward` counts), no transfer function change.
    pub fn new(
        eye_mm: DVec3,
        forward: DVec3,
        up: DVec3,
        fov_deg: f64,
        iso_hu: f64,
        iso_opacity: f64,
    ) -> Result<Self, KeyFrameError> {
        let no_frame = || KeyFrameError::NoFrame(forward.to_array(), up.to_array());
        for (what, v) in [("forward", forward), ("up", up)] {
            if !v.is_finite() {
                return Err(KeyFrameError::NotFinite(what, v.to_array().to_vec()));
            }
        }
        let forward = forward.try_normalize().ok_or_else(no_frame)?;
        let right = forward.cross(up).try_normalize().ok_or_else(no_frame)?;
        let up = right.cross(forward);
        let orientation = DQuat::from_mat3(&DMat3::from_cols(right, up, -forward));
        let key = Self {
            eye_mm,
            orientation,
            fov_deg,
            iso_hu,
            iso_opacity,
            tf: None,
        };
        key.checked()
    }

    /// A key frame with the camera of `pose`.
    pub fn from_pose(
        pose: &Pose,
        fov_deg: f64,
        iso_hu: f64,
        iso_opacity: f64,
    ) -> Result<Self, KeyFrameError> {
        let forward = pose.look_at_mm - pose.eye_mm;
        Self::new(pose.eye_mm, forward, pose.up, fov_deg, iso_hu, iso_opacity)
    }

    /// Unit viewing direction, world.
    pub fn forward(&self) -> DVec3 {
        self.orientation * DVec3::NEG_Z
    }

    /// Unit up direction of the image, world.
    pub fn up(&self) -> DVec3 {
        self.orientation * DVec3::Y
    }

    /// Unit right direction of the image (`forward × up`), world.
    pub fn right(&self) -> DVec3 {
        self.orientation * DVec3::X
    }

    /// The pose looking at the point `look_distance_mm` ahead of the eye.
    pub fn pose(&self, look_distance_mm: f64) -> Pose {
        Pose {
            eye_mm: self.eye_mm,
            look_at_mm: self.eye_mm + self.forward() * look_distance_mm,
            up: self.up(),
        }
    }

    /// The camera of this key frame for an image of `size` pixels.
    pub fn camera(&self, size: [usize; 2]) -> Result<Camera, CameraError> {
        let at = self.eye_mm + self.forward();
        Camera::look_at(self.eye_mm, at, self.up(), self.fov_deg, size)
    }

    /// The key frame with its orientation normalised, or why it is not usable.
    fn checked(mut self) -> Result<Self, KeyFrameError> {
        let numbers = [self.fov_deg, self.iso_hu, self.iso_opacity];
        if !self.eye_mm.is_finite() {
            return Err(KeyFrameError::NotFinite(
                "eye",
                self.eye_mm.to_array().to_vec(),
            ));
        }
        if !self.orientation.is_finite() || !numbers.iter().all(|x| x.is_finite()) {
            let mut values = self.orientation.to_array().to_vec();
            values.extend(numbers);
            return Err(KeyFrameError::NotFinite(
                "orientation, fov, iso, opacity",
                values,
            ));
        }
        let length = self.orientation.length();
        if length < 1e-12 {
            return Err(KeyFrameError::ZeroOrientation(self.orientation.to_array()));
        }
        self.orientation /= length;
        if !(FOV_RANGE_DEG.0..=FOV_RANGE_DEG.1).contains(&self.fov_deg) {
            return Err(KeyFrameError::BadFov(self.fov_deg));
        }
        if !(0.0..=1.0).contains(&self.iso_opacity) {
            return Err(KeyFrameError::BadOpacity(self.iso_opacity));
        }
        Ok(self)
    }
}

/// Key frames interpolated for constant-speed playback (see the module docs for the rules).
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    keys: Vec<KeyFrame>,
    /// The eye spline and its arc table; `None` for a single key.
    eye_path: Option<(CatmullRom, ArcTable)>,
    /// Playback length at each key, mm (0 at the first).
    key_playback_mm: Vec<f64>,
}

impl Animation {
    /// The animation through `keys` (at least one; orientations are normalised).
    pub fn new(keys: Vec<KeyFrame>) -> Result<Self, AnimationError> {
        if keys.is_empty() {
            return Err(AnimationError::NoKeys);
        }
        let keys = keys
            .into_iter()
            .enumerate()
            .map(|(index, key)| {
                key.checked()
                    .map_err(|source| AnimationError::Key { index, source })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let eye_path = if keys.len() > 1 {
            let eyes: Vec<DVec3> = keys.iter().map(|k| k.eye_mm).collect();
            let spline = CatmullRom::new(eyes)?;
            let table = ArcTable::new(&spline, table_piece_mm(spline.points()))?;
            Some((spline, table))
        } else {
            None
        };
        let mut key_playback_mm = vec![0.0];
        for (i, pair) in keys.windows(2).enumerate() {
            let arc = eye_path.as_ref().map_or(0.0, |(_, t)| {
                t.arc_at_point_mm(i + 1) - t.arc_at_point_mm(i)
            });
            let length = segment_playback_mm(arc, turn_rad(&pair[0], &pair[1]));
            key_playback_mm.push(key_playback_mm[i] + length);
        }
        Ok(Self {
            keys,
            eye_path,
            key_playback_mm,
        })
    }

    /// The key frames (orientations normalised).
    pub fn keys(&self) -> &[KeyFrame] {
        &self.keys
    }

    /// Playback length of the whole animation, mm (0 for a single key).
    pub fn len_mm(&self) -> f64 {
        self.key_playback_mm.last().copied().unwrap_or(0.0)
    }

    /// Playback position of each key, mm: [`Animation::sample_at_arc`] there returns the key.
    pub fn key_positions_mm(&self) -> &[f64] {
        &self.key_playback_mm
    }

    /// The interpolated state at playback length `s_mm` (clamped to `[0, len_mm]`; NaN gives
    /// the first key). Exactly the key at a key's playback position.
    pub fn sample_at_arc(&self, s_mm: f64) -> KeyFrame {
        let positions = &self.key_playback_mm;
        let last = self.keys.len() - 1;
        let Some((spline, table)) = &self.eye_path else {
            return self.keys[0].clone();
        };
        if s_mm >= self.len_mm() {
            return self.keys[last].clone();
        }
        if s_mm.is_nan() || s_mm <= 0.0 {
            return self.keys[0].clone();
        }
        let i = (positions.partition_point(|&p| p <= s_mm) - 1).min(last - 1);
        let f = (s_mm - positions[i]) / (positions[i + 1] - positions[i]);
        if f <= 0.0 {
            return self.keys[i].clone();
        }
        let (a, b) = (&self.keys[i], &self.keys[i + 1]);
        let (arc_a, arc_b) = (table.arc_at_point_mm(i), table.arc_at_point_mm(i + 1));
        let lerp = |x: f64, y: f64| x + (y - x) * f;
        KeyFrame {
            eye_mm: spline.point(table.parameter_at(lerp(arc_a, arc_b))),
            // glam's slerp flips `b` when the dot product is negative: the short arc.
            orientation: a.orientation.slerp(b.orientation, f).normalize(),
            fov_deg: lerp(a.fov_deg, b.fov_deg),
            iso_hu: lerp(a.iso_hu, b.iso_hu),
            iso_opacity: lerp(a.iso_opacity, b.iso_opacity),
            tf: if f < 0.5 { a.tf.clone() } else { b.tf.clone() },
        }
    }

    /// `n` states evenly spaced in playback length from the first key to the last (both
    /// included; one frame is the first key), computed lazily so a long flight needs no memory.
    pub fn frames(&self, n: usize) -> impl Iterator<Item = KeyFrame> + '_ {
        let step = if n > 1 {
            self.len_mm() / (n - 1) as f64
        } else {
            0.0
        };
        (0..n).map(move |k| {
            let s = if k + 1 == n {
                self.len_mm()
            } else {
                k as f64 * step
            };
            self.sample_at_arc(s)
        })
    }
}

/// Rotation angle between the orientations of two keys, radians in [0, π].
fn turn_rad(a: &KeyFrame, b: &KeyFrame) -> f64 {
    2.0 * a.orientation.dot(b.orientation).abs().min(1.0).acos()
}

/// Playback length of a segment with eye arc `arc_mm` and turn `turn_rad` (module docs).
fn segment_playback_mm(arc_mm: f64, turn_rad: f64) -> f64 {
    let length = arc_mm.max(MM_PER_RAD * turn_rad);
    if length > 1e-9 {
        length
    } else {
        HOLD_MM
    }
}

/// Arc table piece length for an eye path through `points`: about [`TABLE_PIECES`] pieces
/// whatever its scale.
fn table_piece_mm(points: &[DVec3]) -> f64 {
    let chords: f64 = points.windows(2).map(|p| p[0].distance(p[1])).sum();
    (chords / TABLE_PIECES).max(1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(eye: [f64; 3], forward: DVec3, fov: f64, iso: f64, opacity: f64) -> KeyFrame {
        KeyFrame::new(DVec3::from(eye), forward, DVec3::Z, fov, iso, opacity).unwrap()
    }

    /// Angle between two rotations, degrees (q and −q are the same rotation).
    fn angle_deg(a: DQuat, b: DQuat) -> f64 {
        (2.0 * a.dot(b).abs().min(1.0).acos()).to_degrees()
    }

    #[test]
    fn orientation_follows_the_camera_convention() {
        let pose = Pose {
            eye_mm: DVec3::new(1.0, 2.0, 3.0),
            look_at_mm: DVec3::new(1.0, 5.0, 3.0),
            up: DVec3::new(0.0, 0.3, 2.0),
        };
        let k = KeyFrame::from_pose(&pose, 70.0, -500.0, 1.0).unwrap();
        let camera = Camera::look_at(pose.eye_mm, pose.look_at_mm, pose.up, 70.0, [8, 8]).unwrap();
        let from_key = k.camera([8, 8]).unwrap();
        for (a, b) in [
            (k.forward(), camera.forward()),
            (k.up(), camera.up()),
            (k.right(), camera.right()),
            (from_key.up(), camera.up()),
        ] {
            assert!(a.distance(b) < 1e-12, "{a} vs {b}");
        }
        let back = k.pose(3.0);
        assert!(back.look_at_mm.distance(pose.look_at_mm) < 1e-12);
        assert!(back.up.distance(DVec3::Z) < 1e-12);
    }

    #[test]
    fn passes_exactly_through_the_keys() {
        let mut keys = vec![
            key([0.0, 0.0, 0.0], DVec3::X, 60.0, -500.0, 1.0),
            key(
                [5.0, 1.0, 0.0],
                DVec3::new(1.0, 1.0, 0.0),
                80.0,
                -400.0,
                0.5,
            ),
            key([20.0, 3.0, 2.0], DVec3::Y, 45.0, -700.0, 0.2),
            key([21.0, 9.0, 2.0], -DVec3::X, 45.0, -600.0, 0.9),
        ];
        keys[1].tf = Some("colonoscopy".into());
        keys[3].tf = Some("tf.json".into());
        let animation = Animation::new(keys.clone()).unwrap();
        for (i, &s) in animation.key_positions_mm().iter().enumerate() {
            assert_eq!(animation.sample_at_arc(s), keys[i], "key {i}");
        }
        // Just after key 2 the transfer function is still key 2's; after halfway, key 3's.
        let p = animation.key_positions_mm();
        let at = |f: f64| animation.sample_at_arc(p[2] + f * (p[3] - p[2]));
        assert_eq!(at(0.49).tf, None);
        assert_eq!(at(0.51).tf.as_deref(), Some("tf.json"));
        let mid = at(0.25);
        assert!((mid.iso_hu - (-675.0)).abs() < 1e-9);
        assert!((mid.iso_opacity - 0.375).abs() < 1e-12);
        assert_eq!(animation.sample_at_arc(-1.0), keys[0]);
        assert_eq!(animation.sample_at_arc(1e9), keys[3]);
        assert_eq!(animation.sample_at_arc(f64::NAN), keys[0]);
    }

    #[test]
    fn slerp_takes_the_short_arc_whatever_the_sign() {
        let a = key([0.0; 3], DVec3::X, 60.0, -500.0, 1.0);
        let b = key([10.0, 0.0, 0.0], DVec3::Y, 60.0, -500.0, 1.0);
        let mut b_negated = b.clone();
        b_negated.orientation = -b.orientation;
        let plus = Animation::new(vec![a.clone(), b.clone()]).unwrap();
        let minus = Animation::new(vec![a.clone(), b_negated]).unwrap();
        for k in 0..=10 {
            let s = plus.len_mm() * f64::from(k) / 10.0;
            let (p, m) = (plus.sample_at_arc(s), minus.sample_at_arc(s));
            assert!(angle_deg(p.orientation, m.orientation) < 1e-9);
            // The short arc is 90° about z: k/10 of it, never the 270° way round.
            let turned = angle_deg(a.orientation, p.orientation);
            assert!((turned - 9.0 * f64::from(k)).abs() < 1e-6, "{turned}");
            assert!(p.forward().z.abs() < 1e-12);
        }
    }

    #[test]
    fn plays_at_constant_speed_despite_uneven_keys() {
        let eyes = [
            [0.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [30.0, 4.0, 3.0],
            [33.0, 10.0, 3.0],
            [34.0, 11.0, 3.5],
            [60.0, -5.0, 0.0],
        ];
        let keys: Vec<KeyFrame> = eyes
            .iter()
            .map(|&e| key(e, DVec3::X, 60.0, -500.0, 1.0))
            .collect();
        let animation = Animation::new(keys).unwrap();
        let eyes: Vec<DVec3> = animation.frames(400).map(|k| k.eye_mm).collect();
        let steps: Vec<f64> = eyes.windows(2).map(|p| p[0].distance(p[1])).collect();
        let mean = animation.len_mm() / 399.0;
        for (i, d) in steps.iter().enumerate() {
            assert!(
                (d / mean - 1.0).abs() < 0.02,
                "step {i}: {d} mm, mean {mean} mm"
            );
        }
    }

    #[test]
    fn pure_turns_and_holds_take_time() {
        let a = key([1.0, 2.0, 3.0], DVec3::X, 60.0, -500.0, 1.0);
        let b = key([1.0, 2.0, 3.0], DVec3::Y, 60.0, -500.0, 1.0);
        let mut c = b.clone();
        c.iso_hu = -300.0;
        let animation = Animation::new(vec![a.clone(), b, c]).unwrap();
        let turn = MM_PER_RAD * std::f64::consts::FRAC_PI_2;
        assert!((animation.key_positions_mm()[1] - turn).abs() < 1e-9);
        assert!((animation.len_mm() - turn - HOLD_MM).abs() < 1e-9);
        // The turn is played at constant angular speed.
        let frames: Vec<KeyFrame> = animation.frames(41).collect();
        let turn_frames = (turn / animation.len_mm() * 40.0).floor() as usize;
        for pair in frames[..turn_frames].windows(2) {
            let step = angle_deg(pair[0].orientation, pair[1].orientation);
            assert!((step - 90.0 / turn * animation.len_mm() / 40.0).abs() < 1e-6);
            assert_eq!(pair[0].eye_mm, a.eye_mm);
        }
        let single = Animation::new(vec![a.clone()]).unwrap();
        assert_eq!(single.len_mm(), 0.0);
        assert_eq!(single.frames(3).collect::<Vec<_>>(), vec![a.clone(); 3]);
        assert_eq!(single.frames(0).count(), 0);
    }

    #[test]
    fn bad_keys_are_errors() {
        let z = DVec3::Z;
        assert_eq!(Animation::new(vec![]), Err(AnimationError::NoKeys));
        assert!(KeyFrame::new(DVec3::NAN, DVec3::X, z, 60.0, 0.0, 1.0).is_err());
        assert!(KeyFrame::new(DVec3::ZERO, DVec3::ZERO, z, 60.0, 0.0, 1.0).is_err());
        assert!(KeyFrame::new(DVec3::ZERO, z, z, 60.0, 0.0, 1.0).is_err());
        assert!(KeyFrame::new(DVec3::ZERO, DVec3::X, z, 5.0, 0.0, 1.0).is_err());
        assert!(KeyFrame::new(DVec3::ZERO, DVec3::X, z, 60.0, f64::NAN, 1.0).is_err());
        assert!(KeyFrame::new(DVec3::ZERO, DVec3::X, z, 60.0, 0.0, 1.5).is_err());
        let good = key([0.0; 3], DVec3::X, 60.0, 0.0, 1.0);
        let mut zero = good.clone();
        zero.orientation = DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0);
        let error = Animation::new(vec![good.clone(), zero]).unwrap_err();
        assert!(
            error.to_string().starts_with("key frame 1: orientation"),
            "{error}"
        );
        let mut scaled = good.clone();
        scaled.orientation = good.orientation * 3.0;
        let animation = Animation::new(vec![scaled]).unwrap();
        assert!((animation.keys()[0].orientation.length() - 1.0).abs() < 1e-12);
    }
}
