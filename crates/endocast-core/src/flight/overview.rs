//! An outside view of the whole lumen, for the dashboard: the lumen's mask rendered as an
//! isosurface from the patient's front, so the path and the camera can be drawn on it and the
//! unseen wall tinted.

use super::error::FlightError;
use crate::navigate::Lumen;
use crate::render::{Camera, Mode, RenderSettings, Renderer};
use crate::views::Image;
use crate::{Geometry, Modality, ValueMap, Volume};
use glam::DVec3;
use std::sync::Arc;

/// Voxels of empty margin around the lumen's box, so its surface closes at the box's faces.
const MARGIN: usize = 2;
/// Stored value of lumen voxels in the mask volume (outside: 0); the surface is at half of it.
const INSIDE: u16 = 1000;

/// A rendered outside view and the camera it was rendered with.
#[derive(Debug, Clone)]
pub struct Overview {
    /// The image.
    pub image: Image,
    /// The camera (for projecting world points onto the image).
    pub camera: Camera,
    /// Distance from the eye to the lumen's surface per pixel, mm (NaN where none).
    pub depth_mm: Vec<f32>,
}

/// The lumen seen from the patient's front (anterior, −y in LPS), superior up, framed to fill
/// `size` pixels. Only the lumen's bounding box (plus a margin) is built and rendered.
pub fn lumen_overview(
    lumen: &Lumen,
    geometry: &Geometry,
    size: [usize; 2],
) -> Result<Overview, FlightError> {
    let mask = mask_volume(lumen, geometry)?;
    let (lo, hi) = mask.geometry().world_bounds();
    let centre = (lo + hi) / 2.0;
    let radius = ((hi - lo).length() / 2.0).max(1.0);
    let fov_deg = 30.0_f64;
    let distance = radius / (fov_deg / 2.0).to_radians().sin();
    let camera = Camera::look_at(
        centre - DVec3::Y * distance,
        centre,
        DVec3::Z,
        fov_deg,
        size,
    )?;
    let settings = RenderSettings {
        mode: Mode::Iso,
        iso_hu: f64::from(INSIDE) / 2.0,
        iso_color: [0.8, 0.75, 0.65],
        ..RenderSettings::default()
    };
    let renderer = Arc::new(Renderer::new(mask));
    let frame = renderer.prepare(&settings)?.render(&camera);
    Ok(Overview {
        image: Image::from_frame(&frame, settings.background)?,
        camera,
        depth_mm: frame.depth_mm,
    })
}

/// The lumen's box plus [`MARGIN`] as a volume: [`INSIDE`] in the lumen, 0 elsewhere.
fn mask_volume(lumen: &Lumen, geometry: &Geometry) -> Result<Volume, FlightError> {
    let (lo, hi) = lumen.bounds();
    let dims = [0, 1, 2].map(|a| hi[a] - lo[a] + 1 + 2 * MARGIN);
    let corner = DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64) - MARGIN as f64;
    let box_geometry = Geometry::new(
        dims,
        geometry.spacing_mm(),
        geometry.world_of(corner),
        geometry.direction(),
    )?;
    let mut voxels = vec![0u16; dims[0] * dims[1] * dims[2]];
    for v in lumen.voxels() {
        let [i, j, k] = [0, 1, 2].map(|a| v[a] - lo[a] + MARGIN);
        voxels[i + dims[0] * (j + dims[1] * k)] = INSIDE;
    }
    let map = ValueMap::new(1.0, 0.0)?;
    Ok(Volume::new(box_geometry, voxels, map, Modality::Unknown)?)
}
