//! The session's key frames — recorded, inserted, moved, deleted, with undo — and their
//! playback along the camera path they span.

use super::Session;
use crate::controller::FlyCamera;
use endocast_core::animation::{Animation, KeyFrame};

/// How many changes to the key frames can be taken back.
pub const KEY_FRAME_UNDO: usize = 50;

/// A flight along the recorded key frames.
#[derive(Debug, Clone)]
pub struct Playback {
    animation: Animation,
    /// Arc length flown, mm.
    pub s_mm: f64,
    /// Playing (not paused).
    pub playing: bool,
}

impl Playback {
    /// Length of the flight, mm.
    pub fn len_mm(&self) -> f64 {
        self.animation.len_mm()
    }

    /// Whether the flight has reached its end.
    pub fn finished(&self) -> bool {
        self.s_mm >= self.animation.len_mm()
    }
}

impl Session {
    /// Records the current view as a key frame (after the last); undoable.
    pub fn record_key_frame(&mut self) -> Result<(), String> {
        self.insert_key_frame(usize::MAX)
    }

    /// The current view as a key frame.
    fn current_key_frame(&self) -> Result<KeyFrame, String> {
        let c = &self.camera;
        KeyFrame::new(
            c.eye_mm(),
            c.forward(),
            c.up(),
            self.controls.fov_deg,
            self.controls.iso_hu,
            f64::from(self.controls.iso_opacity),
        )
        .map_err(|e| e.to_string())
    }

    /// The recorded key frames.
    pub fn key_frames(&self) -> &[KeyFrame] {
        &self.key_frames
    }

    /// Replaces the key frames (a reopened case, an imported path); undoable.
    pub fn set_key_frames(&mut self, keys: Vec<KeyFrame>) {
        self.edit_key_frames(|frames| *frames = keys);
    }

    /// Deletes key frame `index`; undoable.
    pub fn delete_key_frame(&mut self, index: usize) {
        if index < self.key_frames.len() {
            self.edit_key_frames(|frames| {
                frames.remove(index);
            });
        }
    }

    /// Records the current view as a key frame before key frame `index` (after the last when
    /// `index` is past it); undoable.
    pub fn insert_key_frame(&mut self, index: usize) -> Result<(), String> {
        let key = self.current_key_frame()?;
        let at = index.min(self.key_frames.len());
        self.edit_key_frames(|frames| frames.insert(at, key));
        Ok(())
    }

    /// Moves key frame `from` to place `to` (both within the list); undoable.
    pub fn move_key_frame(&mut self, from: usize, to: usize) {
        let n = self.key_frames.len();
        if from < n && to < n && from != to {
            self.edit_key_frames(|frames| {
                let key = frames.remove(from);
                frames.insert(to, key);
            });
        }
    }

    /// Takes back the last change to the key frames; false when there is none to take back.
    pub fn undo_key_frames(&mut self) -> bool {
        let Some(before) = self.key_frame_history.pop() else {
            return false;
        };
        self.key_frames = before;
        self.playback = None;
        true
    }

    /// Whether a change to the key frames can be taken back.
    pub fn can_undo_key_frames(&self) -> bool {
        !self.key_frame_history.is_empty()
    }

    /// Changes the key frames by `change`, keeping what they were for [`Self::undo_key_frames`]
    /// (the last [`KEY_FRAME_UNDO`] changes); a flight being played stops.
    fn edit_key_frames(&mut self, change: impl FnOnce(&mut Vec<KeyFrame>)) {
        if self.key_frame_history.len() == KEY_FRAME_UNDO {
            self.key_frame_history.remove(0);
        }
        self.key_frame_history.push(self.key_frames.clone());
        change(&mut self.key_frames);
        self.playback = None;
    }

    /// Moves to key frame `index` (its pose, field of view and wall).
    pub fn go_to_key_frame(&mut self, index: usize) {
        if let Some(key) = self.key_frames.get(index).cloned() {
            self.apply_key_frame(&key);
        }
    }

    /// Starts playing the key frames from the first; fails with fewer than two distinct ones.
    pub fn play(&mut self) -> Result<(), String> {
        let animation = Animation::new(self.key_frames.clone()).map_err(|e| e.to_string())?;
        self.playback = Some(Playback {
            animation,
            s_mm: 0.0,
            playing: true,
        });
        self.advance_playback(0.0);
        Ok(())
    }

    /// The flight being played, if any.
    pub fn playback(&self) -> Option<&Playback> {
        self.playback.as_ref()
    }

    /// Pauses or resumes the flight.
    pub fn toggle_pause(&mut self) {
        if let Some(p) = &mut self.playback {
            p.playing = !p.playing;
        }
    }

    /// Stops the flight (the camera stays where it is).
    pub fn stop(&mut self) {
        self.playback = None;
    }

    /// Moves the flight to arc length `s_mm` (scrubbing).
    pub fn scrub(&mut self, s_mm: f64) {
        if let Some(p) = &mut self.playback {
            p.s_mm = s_mm.clamp(0.0, p.len_mm());
        }
        self.advance_playback(0.0);
    }

    /// Advances a playing flight by `dt_s` seconds at the flying speed and puts the camera
    /// there; true while it is playing. A paused or finished flight leaves the camera to the
    /// user (mouse-look, keys, reset) until it is played or scrubbed again (`dt_s` 0).
    pub fn advance_playback(&mut self, dt_s: f64) -> bool {
        let speed = self.controls.speed_mm_s;
        let Some(p) = &mut self.playback else {
            return false;
        };
        if !p.playing && dt_s > 0.0 {
            return false;
        }
        if p.playing {
            p.s_mm = (p.s_mm + dt_s * speed).min(p.len_mm());
        }
        let key = p.animation.sample_at_arc(p.s_mm);
        if p.finished() {
            p.playing = false;
        }
        let playing = p.playing;
        self.apply_key_frame(&key);
        playing
    }

    fn apply_key_frame(&mut self, key: &KeyFrame) {
        if let Some(camera) = FlyCamera::new(key.eye_mm, key.forward(), key.up()) {
            self.camera = camera;
        }
        self.controls.fov_deg = key.fov_deg;
        self.controls.iso_hu = key.iso_hu;
        self.controls.iso_opacity = key.iso_opacity as f32;
        self.find_lumen();
    }
}
