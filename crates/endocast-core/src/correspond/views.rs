//! The synchronised pair: the first scan's view of a finding beside the second scan's view of
//! its counterpart, each in its own study's render settings, the finding marked in both.

use super::Counterpart;
use crate::camera::CameraError;
use crate::look::{still_view, LookError};
use crate::pose::Pose;
use crate::render::{Camera, Filter, RenderSettings, Renderer, SettingsError};
use crate::views::{Image, ViewError, CAMERA_COLOR};
use std::sync::Arc;
use thiserror::Error;

/// Pixels between the two views.
const GAP_PX: usize = 4;
/// Half the length of the cross marking the finding, pixels.
const MARK_PX: f64 = 6.0;

/// Why the pair cannot be rendered.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PairError {
    /// The camera cannot be made (size or field of view out of range).
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// The render settings are invalid.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The frame cannot be rendered.
    #[error(transparent)]
    Look(#[from] LookError),
    /// The image cannot be made.
    #[error(transparent)]
    View(#[from] ViewError),
}

/// One scan to render: its renderer and its study's settings.
pub type Scan<'a> = (&'a Arc<Renderer>, &'a RenderSettings);

/// The first scan's view of the finding (left) beside the second's view of its counterpart
/// (right), each `size` pixels with a vertical field of `fov_deg`, with a cross on the finding.
pub fn side_by_side(
    [first, second]: [Scan; 2],
    found: &Counterpart,
    fov_deg: f64,
    size: [usize; 2],
) -> Result<Image, PairError> {
    let left = view(first, &found.view_first, fov_deg, size)?;
    let right = view(second, &found.view, fov_deg, size)?;
    let mut pair = Image::new(2 * size[0] + GAP_PX, size[1], [0, 0, 0])?;
    pair.blit(&left, 0, 0);
    pair.blit(&right, (size[0] + GAP_PX) as i64, 0);
    Ok(pair)
}

/// One scan's view from `pose`, the point looked at marked with a cross.
fn view(
    (renderer, settings): Scan,
    pose: &Pose,
    fov_deg: f64,
    size: [usize; 2],
) -> Result<Image, PairError> {
    let camera = Camera::look_at(pose.eye_mm, pose.look_at_mm, pose.up, fov_deg, size)?;
    let prepared = renderer.prepare(settings)?;
    let frame = still_view(&prepared, None, &camera, 1, Filter::Trilinear)?;
    let mut image = Image::from_frame(&frame, settings.background)?;
    let (x, y) = (0.5 * size[0] as f64, 0.5 * size[1] as f64);
    image.line((x - MARK_PX, y), (x + MARK_PX, y), CAMERA_COLOR);
    image.line((x, y - MARK_PX), (x, y + MARK_PX), CAMERA_COLOR);
    Ok(image)
}
