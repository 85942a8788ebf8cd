//! The keyboard: which keys fly, and the motion they ask for in one UI frame.

use crate::controller::LocalMove;
use egui::{InputState, Key};

/// Faster flight while Shift is held.
pub const SHIFT_FACTOR: f64 = 3.0;
/// Roll speed while Q or E is held, radians per second.
pub const ROLL_RAD_S: f64 = 1.2;

/// The keys, for the help text and the README.
pub const HELP: &[(&str, &str)] = &[
    ("W / S or the up / down arrows", "fly forward / back"),
    ("A / D or the left / right arrows", "slide left / right"),
    ("R / F", "rise / sink"),
    ("Q / E", "roll left / right"),
    ("Shift", "three times faster"),
    ("drag in the view", "look around"),
    (
        "click in the view",
        "turn toward that point (with a marking tool: label, draw, measure)",
    ),
    ("click in a slice", "jump there (into the lumen nearby)"),
    ("double click a slice", "show it large beside the view"),
    ("wheel in the large slice", "page through it (Ctrl: zoom)"),
    (
        "drag in the large slice",
        "window: across for width, up and down for level (Shift or middle button: pan; right button: zoom)",
    ),
    ("K", "record a key frame"),
    ("P / Space", "play / pause the key frames"),
    ("C", "collision on / off"),
    ("Z", "centre in the lumen (across the view)"),
    ("N", "next unseen patch (after \"Review unseen\")"),
    (
        "click in the flat view",
        "look at that wall point from the path (after \"Dissect\")",
    ),
    ("H", "back to the start"),
    ("+ / -", "faster / slower"),
];

/// What the held keys ask for during `dt_s` seconds at `speed_mm_s`: a move in the camera's
/// axes and a roll (radians, clockwise).
pub fn held_motion(input: &InputState, speed_mm_s: f64, dt_s: f64) -> (LocalMove, f64) {
    let axis = |plus: &[Key], minus: &[Key]| {
        let held = |keys: &[Key]| keys.iter().any(|&k| input.key_down(k));
        f64::from(i8::from(held(plus)) - i8::from(held(minus)))
    };
    let boost = if input.modifiers.shift {
        SHIFT_FACTOR
    } else {
        1.0
    };
    let step = speed_mm_s * boost * dt_s;
    let motion = LocalMove {
        right_mm: axis(&[Key::D, Key::ArrowRight], &[Key::A, Key::ArrowLeft]) * step,
        up_mm: axis(&[Key::R, Key::PageUp], &[Key::F, Key::PageDown]) * step,
        forward_mm: axis(&[Key::W, Key::ArrowUp], &[Key::S, Key::ArrowDown]) * step,
    };
    let roll = axis(&[Key::E], &[Key::Q]) * ROLL_RAD_S * dt_s;
    (motion, roll)
}

/// The keys pressed this frame that are commands.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Commands {
    /// K.
    pub record_key_frame: bool,
    /// P or Space.
    pub play_pause: bool,
    /// C.
    pub toggle_collision: bool,
    /// H.
    pub reset: bool,
    /// Z.
    pub centre: bool,
    /// + (doubles the speed).
    pub faster: bool,
    /// − (halves the speed).
    pub slower: bool,
}

impl Commands {
    /// The commands pressed in `input`.
    pub fn pressed(input: &InputState) -> Self {
        let p = |k: Key| input.key_pressed(k);
        Self {
            record_key_frame: p(Key::K),
            play_pause: p(Key::P) || p(Key::Space),
            toggle_collision: p(Key::C),
            reset: p(Key::H),
            centre: p(Key::Z),
            faster: p(Key::Plus) || p(Key::Equals),
            slower: p(Key::Minus),
        }
    }
}
