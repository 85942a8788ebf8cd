//! The still mode: while the view stands, jittered frames of it are averaged, which smooths the
//! sampling's aliasing (wood-grain rings of the fixed sample grid, stair-stepped silhouettes).
//!
//! Frame `k` moves every pixel's sample point by a sub-pixel offset and every ray's sample
//! grid by a fraction of a step, both from low-discrepancy sequences (the R2 sequence for the
//! 2-D offset, the golden ratio for the shift), so a few frames already cover the pixel and the
//! step evenly. Frame 0 is not moved: one frame is the plain render, bit for bit.

use super::frame::{Frame, Layers};
use super::options::{Cancelled, Quality, RenderOptions};
use super::{Camera, Prepared};
use rayon::prelude::*;

/// How frame `k` of a still is moved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jitter {
    /// Offset of every pixel's sample point from its centre, pixels (`x` right, `y` down),
    /// each within ±½.
    pub pixel_offset: (f64, f64),
    /// Shift of every ray's sample grid, steps (0–1).
    pub grid_shift: f32,
}

impl Jitter {
    /// The jitter of frame `k` (frame 0: none).
    pub fn of_frame(k: usize) -> Self {
        // The R2 sequence's generators (the plastic number's powers) and the golden ratio.
        const A1: f64 = 0.754_877_666_246_692_8;
        const A2: f64 = 0.569_840_290_998_053_3;
        const GOLDEN: f64 = 0.618_033_988_749_894_8;
        if k == 0 {
            return Self {
                pixel_offset: (0.0, 0.0),
                grid_shift: 0.0,
            };
        }
        let k = k as f64;
        let wrap = |x: f64| x - x.floor();
        Self {
            pixel_offset: (wrap(0.5 + k * A1) - 0.5, wrap(0.5 + k * A2) - 0.5),
            grid_shift: wrap(k * GOLDEN) as f32,
        }
    }
}

/// The running average of a still's frames: [`Still::render_next`] renders the next jittered
/// frame and adds it. Colour and transmittance are averaged; depth, value and the optional
/// layers are frame 0's (unjittered, so they stay exact).
#[derive(Debug, Clone, Default)]
pub struct Still {
    frames: usize,
    mean: Frame,
    scratch: Frame,
}

impl Still {
    /// An empty still.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets every frame (the view changed); keeps the buffers.
    pub fn reset(&mut self) {
        self.frames = 0;
    }

    /// Frames averaged so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// The average so far (empty before the first frame).
    pub fn frame(&self) -> &Frame {
        &self.mean
    }

    /// Renders frame [`Self::frames`] of `camera` with its [`Jitter`] at full quality (the
    /// options' layers only for frame 0) and adds it to the average.
    pub fn render_next(
        &mut self,
        prepared: &Prepared,
        camera: &Camera,
        options: &RenderOptions<'_>,
    ) -> Result<&Frame, Cancelled> {
        let jitter = Jitter::of_frame(self.frames);
        let (dx, dy) = jitter.pixel_offset;
        let jittered = camera.with_pixel_offset(dx, dy);
        let options = RenderOptions {
            quality: Quality::Full,
            grid_shift: jitter.grid_shift,
            layers: if self.frames == 0 {
                options.layers
            } else {
                Layers::NONE
            },
            ..*options
        };
        let mut scratch = std::mem::take(&mut self.scratch);
        let rendered = prepared.render_with(&jittered, &options, &mut scratch);
        if rendered.is_ok() {
            self.add(&scratch);
        }
        self.scratch = scratch;
        rendered.map(|()| &self.mean)
    }

    /// Adds `frame`, rendered with [`Jitter::of_frame`]`(self.frames())`, to the average (a
    /// frame of another size starts the still again).
    pub fn add(&mut self, frame: &Frame) {
        let sized = [self.mean.width, self.mean.height] == [frame.width, frame.height];
        if self.frames == 0 || !sized {
            self.mean.clone_from(frame);
            self.frames = 1;
            return;
        }
        self.frames += 1;
        let n = self.frames as f32;
        self.mean
            .color
            .par_iter_mut()
            .zip(frame.color.par_iter())
            .for_each(|(mean, c)| {
                for (m, c) in mean.rgb.iter_mut().zip(c.rgb) {
                    *m += (c - *m) / n;
                }
                mean.transmittance += (c.transmittance - mean.transmittance) / n;
            });
        self.mean.stats.add(&frame.stats);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jitter_covers_the_pixel_and_the_step() {
        assert_eq!(Jitter::of_frame(0).pixel_offset, (0.0, 0.0));
        assert_eq!(Jitter::of_frame(0).grid_shift, 0.0);
        let mut quadrants = [0; 4];
        for k in 1..=16 {
            let j = Jitter::of_frame(k);
            let (dx, dy) = j.pixel_offset;
            assert!(dx.abs() <= 0.5 && dy.abs() <= 0.5);
            assert!((0.0..1.0).contains(&j.grid_shift));
            quadrants[usize::from(dx > 0.0) + 2 * usize::from(dy > 0.0)] += 1;
        }
        assert!(quadrants.iter().all(|&q| q >= 2), "{quadrants:?}");
    }
}
