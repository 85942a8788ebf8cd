//! Putting a stereo pair's two views together for a screen or glasses: the paper's red/blue
//! anaglyph (VIVENDI), red/cyan, Dubois's least-squares colour anaglyph, side by side and top
//! and bottom. (A left/right pair of files needs no combining.)

use super::{Image, ViewError};

/// How a stereo pair is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StereoOutput {
    /// VIVENDI's red/blue anaglyph: the left eye's brightness in red, the right eye's in blue.
    Anaglyph,
    /// Red/cyan: the left eye's red channel, the right eye's green and blue.
    RedCyan,
    /// Dubois's optimised red/cyan colour anaglyph (least-squares projection for typical
    /// filters; fewer ghosts and truer colours).
    Dubois,
    /// Left view beside the right one (twice as wide).
    SideBySide,
    /// Left view above the right one (twice as tall).
    TopBottom,
    /// Two separate images, written as a left and a right file.
    Pair,
}

impl StereoOutput {
    /// Every output, in a fixed order.
    pub const ALL: [StereoOutput; 6] = [
        Self::Anaglyph,
        Self::RedCyan,
        Self::Dubois,
        Self::SideBySide,
        Self::TopBottom,
        Self::Pair,
    ];

    /// The CLI's name: `anaglyph`, `red-cyan`, `dubois`, `side-by-side`, `top-bottom`, `pair`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Anaglyph => "anaglyph",
            Self::RedCyan => "red-cyan",
            Self::Dubois => "dubois",
            Self::SideBySide => "side-by-side",
            Self::TopBottom => "top-bottom",
            Self::Pair => "pair",
        }
    }

    /// The output called `name` (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|o| o.name().eq_ignore_ascii_case(name.trim()))
    }

    /// The size of the combined image of two `[width, height]` views.
    pub fn combined_size(self, [width, height]: [usize; 2]) -> [usize; 2] {
        match self {
            Self::SideBySide => [2 * width, height],
            Self::TopBottom => [width, 2 * height],
            _ => [width, height],
        }
    }
}

/// Dubois's red/cyan matrices (rows: output R, G, B; columns: input R, G, B), applied to linear
/// light of the left and the right view.
const DUBOIS_LEFT: [[f32; 3]; 3] = [
    [0.456, 0.500, 0.176],
    [-0.040, -0.038, -0.016],
    [-0.015, -0.021, -0.005],
];
const DUBOIS_RIGHT: [[f32; 3]; 3] = [
    [-0.043, -0.088, -0.002],
    [0.378, 0.734, -0.018],
    [-0.072, -0.113, 1.226],
];

/// Combines the `left` and `right` views (the same size) into one image; for
/// [`StereoOutput::Pair`] the left view alone (write the right one beside it).
pub fn combine(left: &Image, right: &Image, output: StereoOutput) -> Result<Image, ViewError> {
    let [w, h] = [left.width(), left.height()];
    if [right.width(), right.height()] != [w, h] {
        return Err(ViewError::SizesDiffer(
            [w, h],
            [right.width(), right.height()],
        ));
    }
    let pixels = |f: &dyn Fn([u8; 3], [u8; 3]) -> [u8; 3]| {
        let rgb = left
            .rgb()
            .chunks_exact(3)
            .zip(right.rgb().chunks_exact(3))
            .flat_map(|(l, r)| f([l[0], l[1], l[2]], [r[0], r[1], r[2]]))
            .collect();
        Image::from_rgb(w, h, rgb)
    };
    match output {
        StereoOutput::Anaglyph => pixels(&|l, r| [luma(l), 0, luma(r)]),
        StereoOutput::RedCyan => pixels(&|l, r| [l[0], r[1], r[2]]),
        StereoOutput::Dubois => pixels(&dubois),
        StereoOutput::Pair => Ok(left.clone()),
        StereoOutput::SideBySide | StereoOutput::TopBottom => {
            let [cw, ch] = output.combined_size([w, h]);
            let mut out = Image::new(cw, ch, [0, 0, 0])?;
            out.blit(left, 0, 0);
            let (x, y) = if output == StereoOutput::SideBySide {
                (w, 0)
            } else {
                (0, h)
            };
            out.blit(right, x as i64, y as i64);
            Ok(out)
        }
    }
}

/// Rec. 709 luma of an 8-bit colour (on the stored, display-encoded values).
fn luma([r, g, b]: [u8; 3]) -> u8 {
    let y = 0.2126 * f32::from(r) + 0.7152 * f32::from(g) + 0.0722 * f32::from(b);
    (y + 0.5).min(255.0) as u8
}

/// One pixel of Dubois's anaglyph.
fn dubois(l: [u8; 3], r: [u8; 3]) -> [u8; 3] {
    let (l, r) = (l.map(to_linear), r.map(to_linear));
    std::array::from_fn(|row| {
        let mut c = 0.0;
        for k in 0..3 {
            c += DUBOIS_LEFT[row][k] * l[k] + DUBOIS_RIGHT[row][k] * r[k];
        }
        from_linear(c)
    })
}

/// An 8-bit sRGB code as linear light, 0–1.
fn to_linear(code: u8) -> f32 {
    let c = f32::from(code) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light (clamped to 0–1) as an 8-bit sRGB code.
fn from_linear(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two 2×1 views that differ in every channel.
    fn views() -> (Image, Image) {
        let left = Image::from_rgb(2, 1, vec![200, 40, 10, 90, 90, 90]).unwrap();
        let right = Image::from_rgb(2, 1, vec![5, 150, 220, 30, 60, 250]).unwrap();
        (left, right)
    }

    #[test]
    fn anaglyph_channels_hold_the_right_eye() {
        let (left, right) = views();
        let black = Image::new(2, 1, [0, 0, 0]).unwrap();
        for output in [
            StereoOutput::Anaglyph,
            StereoOutput::RedCyan,
            StereoOutput::Dubois,
        ] {
            let both = combine(&left, &right, output).unwrap();
            let left_only = combine(&left, &black, output).unwrap();
            let right_only = combine(&black, &right, output).unwrap();
            for x in 0..2 {
                let [b, l, r] = [&both, &left_only, &right_only].map(|i| i.pixel(x, 0).unwrap());
                // Red comes from the left eye; blue (and for red/cyan green) from the right.
                assert_eq!(r[0], 0, "{output:?}: right eye leaks into red");
                assert!(l[0] > 0 && b[0] > 0, "{output:?}: no left eye in red");
                assert_eq!(l[2], 0, "{output:?}: left eye leaks into blue");
                assert!(r[2] > 0, "{output:?}: no right eye in blue");
                if output != StereoOutput::Anaglyph {
                    assert_eq!(l[1], 0, "{output:?}: left eye leaks into green");
                    assert!(r[1] > 0, "{output:?}: no right eye in green");
                } else {
                    assert_eq!(b[1], 0);
                }
            }
        }
        let [l, r] = [left.pixel(0, 0).unwrap(), right.pixel(0, 0).unwrap()];
        let red_cyan = combine(&left, &right, StereoOutput::RedCyan).unwrap();
        assert_eq!(red_cyan.pixel(0, 0).unwrap(), [l[0], r[1], r[2]]);
    }

    #[test]
    fn side_by_side_and_top_bottom_place_the_left_eye_first() {
        let (left, right) = views();
        let sbs = combine(&left, &right, StereoOutput::SideBySide).unwrap();
        assert_eq!([sbs.width(), sbs.height()], [4, 1]);
        assert_eq!(sbs.pixel(0, 0), left.pixel(0, 0));
        assert_eq!(sbs.pixel(2, 0), right.pixel(0, 0));
        let tb = combine(&left, &right, StereoOutput::TopBottom).unwrap();
        assert_eq!([tb.width(), tb.height()], [2, 2]);
        assert_eq!(tb.pixel(1, 0), left.pixel(1, 0));
        assert_eq!(tb.pixel(1, 1), right.pixel(1, 0));
        let small = Image::new(1, 1, [0, 0, 0]).unwrap();
        assert!(combine(&left, &small, StereoOutput::Anaglyph).is_err());
    }

    #[test]
    fn names_round_trip() {
        for output in StereoOutput::ALL {
            assert_eq!(StereoOutput::from_name(output.name()), Some(output));
        }
        assert_eq!(StereoOutput::from_name("nope"), None);
    }
}
