//! The realistic endoscopic look of Krüger et al., "Sinus Endoscopy — Application of Advanced
//! GPU Volume Rendering for Virtual Endoscopy" (§4.3–4.4), in two stages with two lifetimes:
//!
//! 1. The **ray pass** ([`RayPass`], settings [`RayPassSettings`]) marches every pixel's ray
//!    once and writes a [`GBuffer`]: the tissue's depth, hit position and normal (central
//!    differences in the volume), the secretion in front of it, and whether the ray hit at all.
//!    Secretion lies between two thresholds (secretion and tissue); per ray the first secretion
//!    hit and the first tissue hit are found ([`SecretionMode::On`]: constant density between
//!    them) or the secretion is accumulated along the ray at a small step
//!    ([`SecretionMode::Accumulate`]). Rays start with interleaved offsets (§4.3), so sampling
//!    bands break up into a fine pattern that smoothing and still frames average away.
//! 2. The **deferred stage** ([`shade`], settings [`Shading`]) reads only the G-buffer:
//!    depth-aware image-space smoothing of depth, normals and secretion ([`smooth`]), Phong with
//!    the light at the endoscope's tip and its fall-off with distance, wetness (a low-power
//!    view-dependent darkening and highlights, strongest on the detail texture's darker texels:
//!    a specular map; raised by the secretion's density and nearness), a tri-planar detail
//!    texture ([`Texture`]) and the secretion as fog under a glossy film: its upper boundary,
//!    found by the ray pass with its own normal, lit and highlighted, fading in with the
//!    layer's thickness. Changing any of it never marches a ray again:
//!    [`shade`] takes a `&GBuffer` and no renderer.
//!
//! [`shade_with_scene`] composites scene geometry (meshes, overlays, markers, the grid, the
//! instruments) into the shaded frame by depth, as the paper's composition does its polygonal
//! data: solid in front of the tissue, through a stipple behind it, veiled only by the
//! secretion in front of it, a closed mesh around the eye as a tint; [`still()`] and the
//! flights take the scene.
//!
//! Below full quality, [`shade_reduced`] runs the deferred stage at the reduced size of a
//! G-buffer traced there and upsamples the shaded frame.
//!
//! [`LookKind`] names the three looks (`plain` is the renderer's own image; `clinical` and
//! `realistic` run both stages) and [`Look::of_kind`] builds one from a preset's
//! [`PresetLook`] (the presets table holds one per procedure). [`still()`] averages jittered
//! passes into a converged image.
//!
//! ```
//! use endocast_core::look::{self, Look, LookKind, RayPass};
//! use endocast_core::phantom::{layered, Layered, PhantomOptions};
//! use endocast_core::presets::Preset;
//! use endocast_core::render::{Camera, Quality, RenderSettings, Renderer};
//! use glam::DVec3;
//! use std::sync::Arc;
//!
//! let (volume, _) = layered(&PhantomOptions { size: 24, ..Default::default() });
//! let preset = Preset::find("sinus").unwrap();
//! let mut look = Look::of_kind(LookKind::Realistic, &preset.look).unwrap();
//! (look.ray.tissue_hu, look.ray.secretion_hu) =
//!     (Layered::tissue_threshold_hu(), Layered::secretion_threshold_hu());
//! let renderer = Arc::new(Renderer::new(volume));
//! let pass = RayPass::new(&renderer, &RenderSettings::default(), &look.ray).unwrap();
//! let camera = Camera::look_at(DVec3::new(0.0, 0.0, -11.0), DVec3::ZERO, DVec3::Y, 40.0, [16, 16])
//!     .unwrap();
//! let gbuffer = pass.trace(&camera, Quality::Full);
//! assert!(gbuffer.secretion_mm.iter().all(|s| *s > 2.5)); // the layer is 3 mm or more
//! let wet = look::shade(&gbuffer, &camera, &look.shading).unwrap();
//! look.shading.wetness = 0.0; // a new look: the same G-buffer, no ray marched
//! let dry = look::shade(&gbuffer, &camera, &look.shading).unwrap();
//! assert_ne!(wet.color, dry.color);
//! ```

mod deferred;
mod gbuffer;
mod geometry;
mod kind;
mod lanes;
mod reduced;
mod secretion;
mod settings;
mod shading;
pub mod smooth;
mod still;
mod texture;

#[cfg(test)]
mod deferred_tests;
#[cfg(test)]
mod geometry_tests;
#[cfg(test)]
mod tests;

pub use deferred::shade;
pub use gbuffer::{GBuffer, RayPass};
pub use geometry::shade_with_scene;
pub use kind::{Look, LookKind, PresetLook};
pub use reduced::{shade_reduced, shade_reduced_with_scene};
pub use settings::{RayPassSettings, SecretionMode};
pub use shading::Shading;
pub use still::{still, still_filter, still_frame, still_view, MAX_STILL_FRAMES};
pub use texture::{Texture, TextureError, BUILT_IN_TEXTURES, MAX_TEXELS};

use thiserror::Error;

/// Looks that cannot be rendered.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum LookError {
    /// A number is NaN, infinite or outside its range.
    #[error("{name} = {value} is outside {range}")]
    OutOfRange {
        /// The setting.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The accepted range, in words.
        range: &'static str,
    },
    /// The G-buffer was traced for a camera of another size.
    #[error("the G-buffer is {gbuffer:?} pixels but the camera {camera:?}")]
    SizeMismatch {
        /// The G-buffer's width and height.
        gbuffer: [usize; 2],
        /// The camera's width and height.
        camera: [usize; 2],
    },
    /// The renderer's settings cannot be rendered.
    #[error(transparent)]
    Settings(#[from] crate::render::SettingsError),
}

/// `Ok` when `value` is finite and `ok`, else [`LookError::OutOfRange`].
pub(crate) fn check(
    name: &'static str,
    value: f64,
    ok: bool,
    range: &'static str,
) -> Result<(), LookError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(LookError::OutOfRange { name, value, range })
    }
}
