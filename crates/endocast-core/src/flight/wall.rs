//! How much of a lumen's wall a flight showed: the wall's [`Coverage`] recorded flying the route
//! forward (the video's own frames), then flying it back with the endoscope alone
//! ([`BackwardPass`]), and the two passes together ([`WallSeen`]): the figures, the mask volume
//! and an overview with the unseen wall tinted.

use super::error::FlightError;
use super::frames::{Flight, FlightOptions, Layout};
use super::overview::{lumen_overview, Overview};
use super::{Route, Shot};
use crate::coverage::{Coverage, CoverageError};
use crate::navigate::Lumen;
use crate::path::PathError;
use crate::render::{RenderSettings, Renderer};
use crate::views::slices::Window;
use crate::views::Rgb;
use crate::Geometry;
use std::sync::Arc;

/// Sample step of the spline through the reversed route's samples, mm.
const REVERSE_STEP_MM: f64 = 0.5;

/// Colour and strength of the tint on wall never seen in the coverage report's overview
/// ([`WallSeen::overview`]; the dashboard tints more lightly, over its live overview).
pub const REPORT_TINT: (Rgb, f32) = ([230, 40, 40], 0.8);

/// The wall voxels around `lumen` (its bounding box grown by one voxel, where the wall is, and
/// clipped to `geometry`'s grid), none seen yet.
pub fn wall_coverage(lumen: &Lumen, geometry: &Geometry) -> Result<Coverage, CoverageError> {
    let (lo, hi) = lumen.bounds();
    let dims = geometry.dims();
    let bbox = [0, 1, 2].map(|a| lo[a].saturating_sub(1)..(hi[a] + 2).min(dims[a]));
    Coverage::new(geometry, |v| lumen.is_wall(v), &bbox)
}

/// The backward pass of a coverage measurement: the route flown the other way, with the
/// endoscope view alone at the forward flight's image size and field of view, recording into a
/// coverage of its own.
#[derive(Debug)]
pub struct BackwardPass {
    flight: Flight,
    shots: Vec<Shot>,
}

impl BackwardPass {
    /// The pass back along `route`, filmed like the `forward` flight (its image size and field
    /// of view), shots every `step_mm` looking `look_ahead_mm` ahead, recording into a fresh
    /// coverage of the wall `forward_seen` covers. `Ok(None)` for key frames, whose views have
    /// no natural reverse.
    pub fn new(
        renderer: Arc<Renderer>,
        route: &Route,
        forward: &FlightOptions,
        step_mm: f64,
        look_ahead_mm: f64,
        forward_seen: &Coverage,
    ) -> Result<Option<Self>, PathError> {
        let Some(back) = route.reversed(REVERSE_STEP_MM) else {
            return Ok(None);
        };
        let shots = back?.shots(step_mm, look_ahead_mm)?;
        let options = FlightOptions {
            size: forward.size,
            optics: forward.optics,
            stereo: None,
            layout: Layout::Endoscope,
            window: Window::AIR_TISSUE,
        };
        let flight = Flight::new(renderer, options).with_coverage(forward_seen.cleared());
        Ok(Some(Self { flight, shots }))
    }

    /// The shots of the pass, in the order they are flown.
    pub fn shots(&self) -> &[Shot] {
        &self.shots
    }

    /// Flies the pass with `settings`, calling `after_frame` after each frame (for progress);
    /// returns the wall it saw.
    pub fn fly(
        mut self,
        settings: &RenderSettings,
        mut after_frame: impl FnMut(),
    ) -> Result<Coverage, FlightError> {
        for (n, shot) in self.shots.iter().enumerate() {
            self.flight.frame(n, shot, settings)?;
            after_frame();
        }
        Ok(self
            .flight
            .into_coverage()
            .expect("the backward flight was made with a coverage"))
    }
}

/// What a coverage measurement found: the wall seen flying forward, and forward plus backward.
#[derive(Debug, Clone, PartialEq)]
pub struct WallSeen {
    forward: Coverage,
    both: Coverage,
}

impl WallSeen {
    /// The forward pass alone (key frames, which are not flown back): forward plus backward is
    /// the forward pass.
    pub fn forward_only(forward: Coverage) -> Self {
        Self {
            both: forward.clone(),
            forward,
        }
    }

    /// The forward pass and the backward one, merged. Both must cover the same wall.
    pub fn with_backward(forward: Coverage, backward: &Coverage) -> Result<Self, CoverageError> {
        let mut both = forward.clone();
        both.merge(backward)?;
        Ok(Self { forward, both })
    }

    /// The forward pass.
    pub fn forward(&self) -> &Coverage {
        &self.forward
    }

    /// Forward plus backward.
    pub fn both(&self) -> &Coverage {
        &self.both
    }

    /// Number of wall voxels.
    pub fn wall_voxels(&self) -> usize {
        self.forward.total()
    }

    /// Wall voxels seen flying forward.
    pub fn seen_forward(&self) -> usize {
        self.forward.seen_count()
    }

    /// Wall voxels seen flying forward or backward.
    pub fn seen_forward_backward(&self) -> usize {
        self.both.seen_count()
    }

    /// Fraction of the wall seen flying forward, 0–1.
    pub fn fraction_forward(&self) -> f64 {
        self.forward.seen_fraction()
    }

    /// Fraction of the wall seen flying forward or backward, 0–1.
    pub fn fraction_forward_backward(&self) -> f64 {
        self.both.seen_fraction()
    }

    /// The forward pass's label volume on the scan's grid (see [`Coverage::mask_volume`]).
    pub fn mask_volume(&self) -> Result<crate::Volume, crate::VolumeError> {
        self.forward.mask_volume()
    }

    /// The lumen seen from the front ([`lumen_overview`], `size` pixels) with the wall the
    /// forward pass never saw tinted in [`REPORT_TINT`].
    pub fn overview(
        &self,
        lumen: &Lumen,
        geometry: &Geometry,
        size: [usize; 2],
    ) -> Result<Overview, FlightError> {
        let mut overview = lumen_overview(lumen, geometry, size)?;
        let (color, amount) = REPORT_TINT;
        self.forward.tint_unseen(
            &mut overview.image,
            &overview.camera,
            &overview.depth_mm,
            color,
            amount,
        )?;
        Ok(overview)
    }
}
