//! A rendered image as float layers: the integrator's premultiplied colour and transmittance
//! (before any background), the first-hit depth, the MIP/MinIP value and, on request, a small
//! G-buffer (hit positions, normals, the depths of successive surfaces). The background and
//! the 8-bit conversion come last ([`Frame::to_rgb8`]), so that image-space stages (upsampling,
//! accumulation, later compositing of geometry or layers) work on exact float values.
//!
//! **No gamma curve.** The renderer's colours (transfer function, isosurface colours, Phong
//! shading) are display values, as in the VTK peer and the paper: the 8-bit code is the value
//! times 255, rounded. The conversion is the one the renderer always made,
//! `rgb + background · transmittance`, in the same `f32` operations, so 8-bit images are
//! bit-identical to those made before the frame held floats.

use std::ops::BitOr;
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

/// A pixel's colour before the background, as the integrator accumulated it: premultiplied
/// colour and the transmittance (the share of the background that shows through).
///
/// The transmittance is kept rather than the opacity because the display value
/// `rgb + background · transmittance` must be exact: `1 − (1 − T)` loses the low bits of `T`
/// below ½. [`Premultiplied::alpha`] gives the opacity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Premultiplied {
    /// Premultiplied colour, display values (0–1).
    pub rgb: [f32; 3],
    /// Transmittance, 0 (opaque) – 1 (nothing in front of the background).
    pub transmittance: f32,
}

impl Default for Premultiplied {
    /// Nothing: black, fully transparent.
    fn default() -> Self {
        Self {
            rgb: [0.0; 3],
            transmittance: 1.0,
        }
    }
}

impl Premultiplied {
    /// Opacity, 0–1.
    #[inline]
    pub fn alpha(&self) -> f32 {
        1.0 - self.transmittance
    }

    /// The colour over `background`, display values (the renderer's one compositing step).
    #[inline]
    pub fn over(&self, [r, g, b]: [f32; 3]) -> [f32; 3] {
        let [cr, cg, cb] = self.rgb;
        let t = self.transmittance;
        [cr + r * t, cg + g * t, cb + b * t]
    }

    /// The colour over `background` as 8-bit codes.
    #[inline]
    pub fn over_rgb8(&self, background: [f32; 3]) -> [u8; 3] {
        self.over(background).map(to_u8)
    }
}

/// Which optional layers a render fills (a set of flags; `Layers::default()` is none). Layers
/// not asked for are not computed and their buffers stay empty.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Layers(u8);

impl Layers {
    /// No optional layer.
    pub const NONE: Self = Self(0);
    /// [`Frame::hit_mm`]: the world position of the first isosurface hit.
    pub const HIT_POSITION: Self = Self(1);
    /// [`Frame::normal`]: the unit world normal of the isosurface at the first hit.
    pub const NORMAL: Self = Self(2);
    /// [`Frame::layer_depths_mm`]: the depths of the first [`DEPTH_LAYERS`] crossings of the
    /// (lower) isovalue along the ray, found by resuming the search after each hit.
    pub const DEPTHS: Self = Self(4);
    /// Every optional layer.
    pub const ALL: Self = Self(7);

    /// Whether every layer of `other` is in `self`.
    pub fn contains(self, other: Self) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether no layer is asked for.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }
}

impl BitOr for Layers {
    type Output = Self;

    fn bitor(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }
}

/// How many surface crossings [`Layers::DEPTHS`] records per pixel.
pub const DEPTH_LAYERS: usize = 4;

/// A rendered frame: row 0 is the top; pixel `(x, y)` is at index `x + width · y` of every
/// layer. The default is an empty 0×0 frame (to render into).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frame {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Premultiplied colour and transmittance before the background.
    pub color: Vec<Premultiplied>,
    /// Distance from the eye along the ray to the first isosurface hit, mm; NaN where none.
    pub depth_mm: Vec<f32>,
    /// MIP/MinIP: the extreme physical value along the ray; NaN otherwise.
    pub value: Vec<f32>,
    /// With [`Layers::HIT_POSITION`]: the first hit's world position, mm (NaN where none);
    /// empty otherwise.
    pub hit_mm: Vec<[f32; 3]>,
    /// With [`Layers::NORMAL`]: the unit world normal at the first hit, pointing up the value
    /// gradient (NaN where none); empty otherwise.
    pub normal: Vec<[f32; 3]>,
    /// With [`Layers::DEPTHS`]: the distances of the first crossings of the isovalue along the
    /// ray, nearest first, mm (NaN past the last); empty otherwise.
    pub layer_depths_mm: Vec<[f32; DEPTH_LAYERS]>,
    /// What it took.
    pub stats: RenderStats,
}

impl Frame {
    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    /// Whether the frame has no pixel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The layers the frame holds.
    pub fn layers(&self) -> Layers {
        let n = self.len();
        let has = |len: usize, layer: Layers| {
            if len == n && n > 0 {
                layer
            } else {
                Layers::NONE
            }
        };
        has(self.hit_mm.len(), Layers::HIT_POSITION)
            | has(self.normal.len(), Layers::NORMAL)
            | has(self.layer_depths_mm.len(), Layers::DEPTHS)
    }

    /// Opacity of pixel `(x, y)`, 0–1.
    pub fn alpha(&self, x: usize, y: usize) -> f32 {
        self.color[x + self.width * y].alpha()
    }

    /// The colour of pixel `(x, y)` over `background`, 8-bit.
    pub fn pixel(&self, x: usize, y: usize, background: [f32; 3]) -> [u8; 3] {
        self.color[x + self.width * y].over_rgb8(background)
    }

    /// The image over `background` as 8-bit `R G B` bytes, row 0 first.
    pub fn to_rgb8(&self, background: [f32; 3]) -> Vec<u8> {
        let mut rgb = Vec::new();
        self.write_rgb8(background, &mut rgb);
        rgb
    }

    /// [`Self::to_rgb8`] into `rgb`, reusing its buffer.
    pub fn write_rgb8(&self, background: [f32; 3], rgb: &mut Vec<u8>) {
        rgb.clear();
        rgb.reserve(3 * self.color.len());
        for c in &self.color {
            rgb.extend_from_slice(&c.over_rgb8(background));
        }
    }

    /// The image over `background` as 8-bit `R G B A` bytes with opaque alpha (255): the
    /// layout GUI textures take.
    pub fn to_rgba8(&self, background: [f32; 3]) -> Vec<u8> {
        let mut rgba = Vec::with_capacity(4 * self.color.len());
        for c in &self.color {
            let [r, g, b] = c.over_rgb8(background);
            rgba.extend_from_slice(&[r, g, b, 255]);
        }
        rgba
    }

    /// The bytes a pixel of a frame without optional layers takes: colour, depth and value.
    pub const BYTES_PER_PIXEL: usize = size_of::<Premultiplied>() + 2 * size_of::<f32>();

    /// The bytes a pixel of a frame with `layers` takes: colour, depth and value always, the
    /// optional layers asked for. Rendering into a frame holds more for a while (see
    /// [`Frame::rendering_bytes_per_pixel`]).
    pub fn bytes_per_pixel(layers: Layers) -> usize {
        let optional = |on: Layers, bytes: usize| if layers.contains(on) { bytes } else { 0 };
        Self::BYTES_PER_PIXEL
            + optional(Layers::HIT_POSITION, size_of::<[f32; 3]>())
            + optional(Layers::NORMAL, size_of::<[f32; 3]>())
            + optional(Layers::DEPTHS, size_of::<[f32; DEPTH_LAYERS]>())
    }

    /// The bytes the buffers of a `[width, height]` frame with `layers` take
    /// ([`Frame::bytes_per_pixel`] each), or `None` when the count overflows: what a caller
    /// checks against its memory limit before asking for such a frame.
    pub fn bytes_for([width, height]: [usize; 2], layers: Layers) -> Option<u64> {
        (width as u64)
            .checked_mul(height as u64)?
            .checked_mul(Self::bytes_per_pixel(layers) as u64)
    }

    /// Sizes the frame's buffers for `[width, height]` and `layers` (keeping their memory):
    /// the layers not asked for are emptied.
    pub(crate) fn resize(&mut self, [width, height]: [usize; 2], layers: Layers) {
        let n = width * height;
        (self.width, self.height) = (width, height);
        self.color.resize(n, Premultiplied::default());
        self.depth_mm.resize(n, f32::NAN);
        self.value.resize(n, f32::NAN);
        let size = |on: Layers| if layers.contains(on) { n } else { 0 };
        self.hit_mm
            .resize(size(Layers::HIT_POSITION), [f32::NAN; 3]);
        self.normal.resize(size(Layers::NORMAL), [f32::NAN; 3]);
        let depths = size(Layers::DEPTHS);
        self.layer_depths_mm
            .resize(depths, [f32::NAN; DEPTH_LAYERS]);
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

    #[test]
    fn bytes_for_counts_every_buffer_resize_makes() {
        let layers = Layers::NORMAL | Layers::DEPTHS;
        let mut frame = Frame::default();
        frame.resize([7, 5], layers);
        let held = frame.color.len() * size_of::<Premultiplied>()
            + (frame.depth_mm.len() + frame.value.len()) * 4
            + frame.normal.len() * 12
            + frame.layer_depths_mm.len() * 16;
        assert_eq!(Frame::bytes_for([7, 5], layers), Some(held as u64));
        assert_eq!(Frame::bytes_for([7, 5], Layers::NONE), Some(35 * 24));
        assert_eq!(Frame::bytes_for([usize::MAX, 3], Layers::ALL), None);
    }

    #[test]
    fn background_goes_under_last() {
        let mut frame = Frame::default();
        frame.resize([2, 1], Layers::NONE);
        frame.color[1] = Premultiplied {
            rgb: [0.5, 0.0, 0.25],
            transmittance: 0.5,
        };
        assert_eq!(frame.to_rgb8([1.0, 0.0, 0.0]), [255, 0, 0, 255, 0, 64]);
        assert_eq!(frame.to_rgba8([0.0; 3]), [0, 0, 0, 255, 128, 0, 64, 255]);
        assert_eq!(frame.alpha(1, 0), 0.5);
        assert_eq!(frame.layers(), Layers::NONE);
        frame.resize([2, 1], Layers::NORMAL | Layers::DEPTHS);
        assert_eq!(frame.layers(), Layers::NORMAL | Layers::DEPTHS);
        assert!(frame.layers().contains(Layers::DEPTHS));
        assert!(!frame.layers().contains(Layers::HIT_POSITION));
    }
}
