//! [`FlightError`]: why a flight frame (or the overview it shows) could not be made.

use crate::coverage::CoverageError;
use crate::look::LookError;
use crate::path::PathError;
use crate::render::{CameraError, SettingsError};
use crate::views::ViewError;
use crate::{GeometryError, VolumeError};
use thiserror::Error;

/// Why a flight frame could not be made.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FlightError {
    /// A shot's camera is invalid.
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// The render settings are invalid.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// A view could not be drawn.
    #[error(transparent)]
    View(#[from] ViewError),
    /// Coverage could not be tracked.
    #[error(transparent)]
    Coverage(#[from] CoverageError),
    /// The route could not be sampled.
    #[error(transparent)]
    Path(#[from] PathError),
    /// The overview volume could not be built.
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    /// The overview volume could not be built.
    #[error(transparent)]
    Volume(#[from] VolumeError),
    /// The clinical or realistic look is invalid.
    #[error(transparent)]
    Look(#[from] LookError),
}
