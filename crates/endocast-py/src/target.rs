//! `target=(x, y, z)` of `render` and `fly`: a bronchoscopy target ringed in the endoscope
//! view, as `endocast render/fly --target` draw it (the core's
//! [`draw_target`](endocast_core::annotate::draw_target)).

use crate::errors::error;
use crate::kwargs::Kwargs;
use endocast_core::annotate::{draw_target, SurfaceView};
use endocast_core::camera::Camera;
use endocast_core::views::Image;
use glam::DVec3;
use pyo3::prelude::*;

/// Takes `target` (LPS mm): three finite numbers, or an error naming it.
pub fn take(kw: &Kwargs<'_>) -> PyResult<Option<DVec3>> {
    match kw.take::<[f64; 3]>("target")? {
        Some(t) if !t.iter().all(|x| x.is_finite()) => Err(error(format!(
            "target must be three finite numbers (mm), not {t:?}"
        ))),
        t => Ok(t.map(DVec3::from)),
    }
}

/// Rings `target_mm` on `rgba`, the picture of `camera` with `depth_mm` of a scan of
/// `spacing_mm` voxels.
pub fn ring(
    rgba: &mut [u8],
    camera: &Camera,
    depth_mm: &[f32],
    spacing_mm: DVec3,
    target_mm: DVec3,
) {
    let view = SurfaceView::new(camera, depth_mm, spacing_mm);
    Image::draw_on_rgba(rgba, camera.size(), |image| {
        draw_target(image, &view, target_mm);
    });
}
