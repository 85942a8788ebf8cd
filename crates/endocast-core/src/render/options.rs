//! What one render call asks for beyond the camera: the optional layers, a per-pixel maximum
//! distance, the quality level, and the means to interrupt it and follow its progress.

use super::frame::Layers;
use super::stereo::SearchStarts;
use std::fmt;
use std::sync::atomic::AtomicBool;
use thiserror::Error;

/// A render stopped by its cancel flag before every tile was done.
#[derive(Debug, Error, Clone, Copy, PartialEq, Eq)]
#[error("render cancelled")]
pub struct Cancelled;

/// How far a render has come, in tiles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// Tiles finished (in no particular order).
    pub done: usize,
    /// Tiles of the whole frame.
    pub total: usize,
}

/// The resolution rays are cast at. Below full, the image is rendered with a camera of the
/// same pose and field of view at a fraction of the size and upsampled to the full frame,
/// edge-aware (see [`super::quality`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum Quality {
    /// One ray per pixel.
    #[default]
    Full,
    /// Half the width and height (a quarter of the rays).
    Half,
    /// A quarter of the width and height (a sixteenth of the rays).
    Quarter,
    /// An eighth of the width and height (a sixty-fourth of the rays): the first preview of
    /// an expensive view while the camera moves.
    Eighth,
}

impl Quality {
    /// Every level, coarsest first.
    pub const ALL: [Quality; 4] = [Self::Eighth, Self::Quarter, Self::Half, Self::Full];

    /// How many full-resolution pixels one ray stands for along each edge: 1, 2, 4 or 8.
    pub fn factor(self) -> usize {
        match self {
            Self::Full => 1,
            Self::Half => 2,
            Self::Quarter => 4,
            Self::Eighth => 8,
        }
    }

    /// The size rays are cast at for a frame of `size` (rounded up, at least one pixel).
    pub fn reduced_size(self, [width, height]: [usize; 2]) -> [usize; 2] {
        let f = self.factor();
        [width.div_ceil(f).max(1), height.div_ceil(f).max(1)]
    }

    /// The name the CLI uses: `full`, `half`, `quarter`, `eighth`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Full => "full",
            Self::Half => "half",
            Self::Quarter => "quarter",
            Self::Eighth => "eighth",
        }
    }

    /// The level called `name` (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|q| q.name().eq_ignore_ascii_case(name.trim()))
    }
}

/// How a frame reconstructs the volume between its voxels.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    /// Trilinear values and central-difference gradients: every interactive frame.
    #[default]
    Trilinear,
    /// Tricubic B-splines (Krüger et al. §4.3): surfaces exact at the voxels, smooth normals,
    /// many times slower per frame — for stills (see [`super::BSplineCoefficients`]).
    BSpline,
}

impl Filter {
    /// Both filters.
    pub const ALL: [Filter; 2] = [Self::Trilinear, Self::BSpline];

    /// The name the front ends use: `trilinear`, `bspline`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Trilinear => "trilinear",
            Self::BSpline => "bspline",
        }
    }

    /// The filter called `name` (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(name.trim()))
    }
}

/// Options of one render call (see [`super::Prepared::render_with`]), built from
/// [`RenderOptions::new`] (a plain full-quality frame, no optional layer, not interruptible).
#[derive(Clone, Copy, Default)]
pub struct RenderOptions<'a> {
    pub(crate) layers: Layers,
    pub(crate) quality: Quality,
    pub(crate) max_distance_mm: Option<&'a [f32]>,
    pub(crate) cancel: Option<&'a AtomicBool>,
    pub(crate) progress: Option<&'a (dyn Fn(Progress) + Sync)>,
    /// Added to every ray's sample-grid offset (in steps, wrapped to 0–1): a still frame's
    /// per-frame jitter. 0 leaves the grid as the settings place it.
    pub(crate) grid_shift: f32,
    /// Where the isosurface searches may start (the second eye of a stereo pair).
    pub(crate) starts: Option<&'a SearchStarts>,
    /// Iso mode: find the surfaces (depths and the optional layers) but do not shade them; the
    /// colour stays transparent. For passes that use only the geometry, like a look's ray pass.
    pub(crate) unlit: bool,
    /// How samples reconstruct the volume.
    pub(crate) filter: Filter,
}

impl fmt::Debug for RenderOptions<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RenderOptions")
            .field("layers", &self.layers)
            .field("quality", &self.quality)
            .field("max_distance_mm", &self.max_distance_mm.map(<[f32]>::len))
            .field("cancel", &self.cancel)
            .field("progress", &self.progress.is_some())
            .field("grid_shift", &self.grid_shift)
            .field("starts", &self.starts.is_some())
            .field("unlit", &self.unlit)
            .field("filter", &self.filter)
            .finish()
    }
}

impl<'a> RenderOptions<'a> {
    /// Start the isosurface searches at `starts` (a stereo pair's second eye).
    pub(crate) fn search_starts(self, starts: &'a SearchStarts) -> Self {
        Self {
            starts: Some(starts),
            ..self
        }
    }

    /// Iso mode: surfaces found, not shaded (see the field).
    pub(crate) fn unlit(self) -> Self {
        Self {
            unlit: true,
            ..self
        }
    }

    /// A plain full-quality frame, no optional layer, not interruptible.
    pub fn new() -> Self {
        Self::default()
    }

    /// Also fill the optional `layers` (none by default).
    pub fn layers(self, layers: Layers) -> Self {
        Self { layers, ..self }
    }

    /// Cast rays at `quality` (full by default).
    pub fn quality(self, quality: Quality) -> Self {
        Self { quality, ..self }
    }

    /// End each pixel's ray at a distance from the eye, mm, one value per pixel of the camera,
    /// row by row (e.g. the depth of opaque geometry in front of the volume; infinity or NaN
    /// for none). Nothing beyond it is sampled: the ray's range ends there. Not limited by
    /// default. At reduced quality a ray takes the limit of the full-size pixel it falls in.
    pub fn max_distance_mm(self, max_distance_mm: &'a [f32]) -> Self {
        Self {
            max_distance_mm: Some(max_distance_mm),
            ..self
        }
    }

    /// Stop when `cancel` becomes true: it is read before each tile, tiles not yet started
    /// return at once, and the call returns [`Cancelled`].
    pub fn cancel(self, cancel: &'a AtomicBool) -> Self {
        Self {
            cancel: Some(cancel),
            ..self
        }
    }

    /// Call `progress` after each finished tile (from the thread that rendered it).
    pub fn progress(self, progress: &'a (dyn Fn(Progress) + Sync)) -> Self {
        Self {
            progress: Some(progress),
            ..self
        }
    }

    /// Reconstruct the volume with `filter` (trilinear by default; B-splines build their
    /// coefficients once per renderer, on the first frame that asks).
    pub fn filter(self, filter: Filter) -> Self {
        Self { filter, ..self }
    }

    /// The optional layers asked for.
    pub fn requested_layers(&self) -> Layers {
        self.layers
    }

    /// The quality asked for.
    pub fn requested_quality(&self) -> Quality {
        self.quality
    }
}
