//! One ray's work and result as the integrators and the SIMD packet search share them:
//! [`RayTask`] (march, direction, what its phases hand on) and [`PixelOut`] (what it produced).

use super::march::RayMarch;
use super::sample::Accum;
use glam::Vec3;

/// The samples `(t, value)` just before and just after an isosurface crossing, and its side.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bracket {
    pub before: (f32, f32),
    pub after: (f32, f32),
    pub rising: bool,
}

/// What a ray produced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PixelOut {
    /// Premultiplied colour and opacity.
    pub accum: Accum,
    /// Distance to the first isosurface hit, mm (NaN where none).
    pub depth_mm: f32,
    /// Extreme stored value of MIP/MinIP (NaN otherwise or where no sample was taken).
    pub value: f32,
    /// Whether early termination stopped the ray.
    pub terminated: bool,
}

impl Default for PixelOut {
    fn default() -> Self {
        Self {
            accum: Accum::default(),
            depth_mm: f32::NAN,
            value: f32::NAN,
            terminated: false,
        }
    }
}

/// One ray of a group rendered phase by phase
/// ([`super::integrate::Integrator::run_group`]): its march, unit world direction and result,
/// and what its phases hand on.
#[derive(Debug, Clone)]
pub(crate) struct RayTask {
    pub march: RayMarch,
    pub dir_world: Vec3,
    pub out: PixelOut,
    pub(crate) bracket: Option<Bracket>,
}

impl RayTask {
    /// A ray not yet rendered.
    pub fn new(march: RayMarch, dir_world: Vec3) -> Self {
        Self {
            march,
            dir_world,
            out: PixelOut::default(),
            bracket: None,
        }
    }
}
