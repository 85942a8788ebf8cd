//! [`NavError`]: why a lumen, a distance field or a path could not be made.

use super::side::LumenSide;
use thiserror::Error;

/// A navigation request that cannot be served: each variant says what was expected and what
/// was found.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum NavError {
    /// A threshold, radius or coordinate is NaN or infinite (or a radius not positive).
    #[error("{what} must be a finite number{extra}, found {value}")]
    BadNumber {
        /// What the number is (e.g. `"threshold (HU)"`).
        what: &'static str,
        /// Further requirement, e.g. `" greater than 0"`, or empty.
        extra: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A seed voxel index lies outside the volume.
    #[error("seed voxel {seed:?} lies outside the volume of {dims:?} voxels")]
    SeedOutside {
        /// The seed, voxel index.
        seed: [usize; 3],
        /// The volume's dimensions.
        dims: [usize; 3],
    },
    /// A seed voxel is not on the lumen side of the threshold.
    #[error(
        "seed voxel {seed:?} is in the wall: its value {value:.1} is not {side} the threshold \
         {threshold:.1}"
    )]
    SeedInWall {
        /// The seed, voxel index.
        seed: [usize; 3],
        /// The seed's physical value (HU for CT).
        value: f64,
        /// Which side of the threshold the lumen lies on.
        side: LumenSide,
        /// The threshold, physical units.
        threshold: f64,
    },
    /// The lumen around the start runs out of the structure: it reaches several faces of the
    /// volume or fills much of it (the air around a head through the nostrils, the background
    /// of an MRI). Reported before any search, which would wander through it.
    #[error(
        "the lumen {side} {threshold:.1} around the start leaks out: it reaches {faces} of the \
         volume's 6 faces and holds {percent:.0} % of it (the air or background outside the \
         body?); start inside the structure, or move the threshold (--lumen-threshold) so its wall \
         closes; with a --preset and no start, the structure is found for you"
    )]
    LumenLeaks {
        /// The region-growing threshold, physical units.
        threshold: f64,
        /// Which side of it the lumen lies on.
        side: LumenSide,
        /// How many faces of the volume the lumen touches.
        faces: usize,
        /// Percentage of the volume's voxels in the lumen.
        percent: f64,
    },
    /// A point (world mm) lies outside the volume.
    #[error("point {point_mm:?} mm lies outside the volume")]
    PointOutside {
        /// The point, world mm (LPS).
        point_mm: [f64; 3],
    },
    /// A point lies in the wall (or right against it) and no lumen voxel clear of the wall is
    /// near enough to snap to.
    #[error(
        "point {point_mm:?} mm is in the wall: no lumen voxel at least one voxel from the wall \
         lies within {radius_mm} mm of it"
    )]
    PointInWall {
        /// The point, world mm (LPS).
        point_mm: [f64; 3],
        /// How far the snap looked, mm.
        radius_mm: f64,
    },
    /// The start and end of a path lie in lumens that are not connected.
    #[error("the start {start_mm:?} mm and the end {end_mm:?} mm lie in disconnected lumens")]
    Disconnected {
        /// The start, world mm (LPS).
        start_mm: [f64; 3],
        /// The end, world mm (LPS).
        end_mm: [f64; 3],
    },
    /// The centreline could not be made into a smooth path that stays in the lumen.
    #[error("cannot smooth the centreline: {0}")]
    Path(crate::path::PathError),
}

impl From<crate::path::PathError> for NavError {
    fn from(error: crate::path::PathError) -> Self {
        Self::Path(error)
    }
}

/// `Ok(value)` when finite (and, with `positive`, greater than 0), else [`NavError::BadNumber`].
pub(crate) fn check_finite(
    what: &'static str,
    value: f64,
    positive: bool,
) -> Result<f64, NavError> {
    // Written so that NaN fails both tests.
    if value.is_finite() && (!positive || value > 0.0) {
        Ok(value)
    } else {
        Err(NavError::BadNumber {
            what,
            extra: if positive { " greater than 0" } else { "" },
            value,
        })
    }
}
