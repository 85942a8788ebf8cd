//! A rendered image: 8-bit colour, opacity, and the small G-buffer the outputs need.

use std::time::Duration;

/// Counters of one frame. Everything but `time` depends only on the scene, not on the thread
/// count.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RenderStats {
    /// Wall time of the frame.
    pub time: Duration,
    /// Rays cast (pixels whose ray meets the volume).
    pub rays: u64,
    /// Trilinear samples taken along the rays (excluding refinement and gradients).
    pub samples: u64,
    /// Bricks sampled in (per ray and walk).
    pub bricks_visited: u64,
    /// Bricks skipped as inactive (per ray and walk).
    pub bricks_skipped: u64,
    /// Rays stopped by early termination.
    pub terminated_early: u64,
    /// Rays that hit an isosurface.
    pub iso_hits: u64,
}

impl RenderStats {
    /// Adds another set of counters (times add too).
    pub fn add(&mut self, other: &Self) {
        self.time += other.time;
        self.rays += other.rays;
        self.samples += other.samples;
        self.bricks_visited += other.bricks_visited;
        self.bricks_skipped += other.bricks_skipped;
        self.terminated_early += other.terminated_early;
        self.iso_hits += other.iso_hits;
    }
}

/// A rendered frame: row 0 is the top; pixel `(x, y)` is at index `x + width · y`. The default
/// is an empty 0×0 frame (to render into).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Colour composited over the background, 8-bit sRGB, `R G B` interleaved.
    pub rgb: Vec<u8>,
    /// Accumulated opacity per pixel before the background, 0–1.
    pub alpha: Vec<f32>,
    /// Distance from the eye along the ray to the first isosurface hit, mm; NaN where none.
    pub depth_mm: Vec<f32>,
    /// MIP/MinIP: the extreme physical value along the ray; NaN otherwise.
    pub value: Vec<f32>,
    /// What it took.
    pub stats: RenderStats,
}

impl Frame {
    /// The colour of pixel `(x, y)`.
    pub fn pixel(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (x + self.width * y);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }
}

/// A display value in [0, 1] as an 8-bit code (rounded, clamped; NaN → 0).
#[inline]
pub(crate) fn to_u8(c: f32) -> u8 {
    (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantises_display_values() {
        assert_eq!(to_u8(0.0), 0);
        assert_eq!(to_u8(1.0), 255);
        assert_eq!(to_u8(0.5), 128);
        assert_eq!(to_u8(-3.0), 0);
        assert_eq!(to_u8(f32::NAN), 0);
    }
}
