//! [`LumenSide`]: which side of a threshold a lumen lies on, shared by the lumen and the errors
//! that describe a seed on the wrong side.

use std::fmt;

/// Which side of the threshold the lumen lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LumenSide {
    /// The lumen is darker than the wall: air in CT, CSF in T1 MRI.
    Below,
    /// The lumen is brighter than the wall: contrast-filled vessels, CSF in T2 MRI.
    Above,
}

impl LumenSide {
    /// True when `value` lies strictly on this side of `threshold` (a voxel exactly at the
    /// threshold is wall, like the renderer's isosurface).
    #[inline]
    pub fn holds(self, value: f64, threshold: f64) -> bool {
        match self {
            Self::Below => value < threshold,
            Self::Above => value > threshold,
        }
    }
}

impl fmt::Display for LumenSide {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Below => "below",
            Self::Above => "above",
        })
    }
}
