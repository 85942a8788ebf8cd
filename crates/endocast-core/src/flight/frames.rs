//! The frames of a flight: render each shot, track the wall seen, and lay out the dashboard.

use super::overview::Overview;
use super::Shot;
use crate::coverage::{Coverage, CoverageError};
use crate::path::PathError;
use crate::render::SettingsError;
use crate::render::{Camera, CameraError, Frame, Prepared, RenderSettings, RenderStats, Renderer};
use crate::views::dashboard::{Dashboard, DashboardInfo, DashboardLayout};
use crate::views::slices::{camera_cross_section, camera_slices, SliceOptions, Window};
use crate::views::{Image, Rgb, ViewError};
use crate::{GeometryError, VolumeError};
use glam::DVec3;
use std::sync::Arc;
use thiserror::Error;

/// Colour and strength of the tint on wall not seen yet, in the dashboard's overview.
const UNSEEN_TINT: (Rgb, f32) = ([230, 40, 40], 0.55);

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
}

/// What each frame shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// The endoscopic view alone.
    Endoscope,
    /// The endoscopic view beside the axial, coronal and sagittal slices through the camera and
    /// an overview of the lumen with the route and the camera.
    Dashboard,
}

/// How a flight is filmed.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightOptions {
    /// Endoscope image size, pixels.
    pub size: [usize; 2],
    /// Vertical field of view, degrees (a key frame's overrides it).
    pub fov_deg: f64,
    /// What each frame shows.
    pub layout: Layout,
    /// Display window of the slices.
    pub window: Window,
}

/// The dashboard's fixed parts.
#[derive(Debug)]
struct DashboardParts {
    layout: DashboardLayout,
    overview: Overview,
    route_mm: Vec<DVec3>,
}

/// Renders the frames of a flight, one shot at a time (memory does not grow with the length).
#[derive(Debug)]
pub struct Flight {
    renderer: Arc<Renderer>,
    options: FlightOptions,
    dashboard: Option<DashboardParts>,
    coverage: Option<Coverage>,
    prepared: Option<Prepared>,
    /// The frame rendered into, its buffers reused from shot to shot.
    frame: Frame,
}

impl Flight {
    /// A flight over `renderer`'s volume. With [`Layout::Dashboard`], call
    /// [`Flight::with_overview`] before the first frame.
    pub fn new(renderer: Arc<Renderer>, options: FlightOptions) -> Self {
        Self {
            renderer,
            options,
            dashboard: None,
            coverage: None,
            prepared: None,
            frame: Frame::default(),
        }
    }

    /// The dashboard's overview (rendered at [`Flight::overview_size`]) and the route drawn on it.
    pub fn with_overview(
        mut self,
        overview: Overview,
        route_mm: Vec<DVec3>,
    ) -> Result<Self, FlightError> {
        let [w, h] = self.options.size;
        let layout = DashboardLayout::for_endoscope(w, h)?;
        self.dashboard = Some(DashboardParts {
            layout,
            overview,
            route_mm,
        });
        Ok(self)
    }

    /// The size the dashboard's overview should be rendered at.
    pub fn overview_size(&self) -> Result<[usize; 2], FlightError> {
        let [w, h] = self.options.size;
        let r = DashboardLayout::for_endoscope(w, h)?.overview;
        Ok([r.width, r.height])
    }

    /// Tracks which wall voxels the primary rays hit.
    pub fn with_coverage(mut self, coverage: Coverage) -> Self {
        self.coverage = Some(coverage);
        self
    }

    /// The coverage so far, when tracked.
    pub fn coverage(&self) -> Option<&Coverage> {
        self.coverage.as_ref()
    }

    /// The coverage, when tracked, ending the flight.
    pub fn into_coverage(self) -> Option<Coverage> {
        self.coverage
    }

    /// Frame number `index` for `shot`, rendered with `settings`, and the render's statistics.
    pub fn frame(
        &mut self,
        index: usize,
        shot: &Shot,
        settings: &RenderSettings,
    ) -> Result<(Image, RenderStats), FlightError> {
        let pose = &shot.pose;
        let fov = shot.fov_deg.unwrap_or(self.options.fov_deg);
        let camera = Camera::look_at(
            pose.eye_mm,
            pose.look_at_mm,
            pose.up,
            fov,
            self.options.size,
        )?;
        prepared(&mut self.prepared, &self.renderer, settings)?
            .render_into(&camera, &mut self.frame);
        let frame = &self.frame;
        if let Some(coverage) = &mut self.coverage {
            coverage.record(&camera, frame)?;
        }
        let endoscope = Image::from_frame(frame, settings.background)?;
        let stats = frame.stats;
        let image = match self.options.layout {
            Layout::Endoscope => endoscope,
            Layout::Dashboard => self.dashboard_frame(index, shot, &camera, &endoscope)?,
        };
        Ok((image, stats))
    }

    fn dashboard_frame(
        &self,
        index: usize,
        shot: &Shot,
        camera: &Camera,
        endoscope: &Image,
    ) -> Result<Image, FlightError> {
        let Some(parts) = &self.dashboard else {
            return Ok(endoscope.clone());
        };
        let options = SliceOptions {
            size_px: parts.layout.slices[0].width,
            window: self.options.window,
            ..SliceOptions::default()
        };
        let volume = self.renderer.volume();
        let slices = camera_slices(volume, camera, &options)?;
        let cross = camera_cross_section(volume, camera, shot.tangent, &cross_options(&options))?;
        let mut overview = parts.overview.image.clone();
        if let Some(coverage) = &self.coverage {
            let (color, amount) = UNSEEN_TINT;
            let ov = &parts.overview;
            coverage.tint_unseen(&mut overview, &ov.camera, &ov.depth_mm, color, amount)?;
        }
        let dashboard = Dashboard {
            endoscope,
            slices: [
                slices[0].image(),
                slices[1].image(),
                slices[2].image(),
                cross.image(),
            ],
            overview: &overview,
            overview_camera: &parts.overview.camera,
            path_mm: &parts.route_mm,
            camera,
        };
        let info = DashboardInfo {
            frame: index,
            arc_mm: shot.arc_mm,
            coverage: self.coverage.as_ref().map(Coverage::seen_fraction),
        };
        Ok(dashboard.compose(&parts.layout, &info)?)
    }
}

/// The cross-section shows the lumen around the camera: a field of this many mm.
const CROSS_SECTION_FIELD_MM: f64 = 80.0;

/// Slice options for the cross-section: the slices' window and size, a close field of view.
fn cross_options(slices: &SliceOptions) -> SliceOptions {
    SliceOptions {
        field_mm: Some(CROSS_SECTION_FIELD_MM),
        ..slices.clone()
    }
}

/// The prepared renderer in `slot` for `settings`, updated only when they change.
fn prepared<'s>(
    slot: &'s mut Option<Prepared>,
    renderer: &Arc<Renderer>,
    settings: &RenderSettings,
) -> Result<&'s Prepared, FlightError> {
    let prepared = match slot.take() {
        Some(mut p) => {
            if p.settings() != settings {
                p.update(settings)?;
            }
            p
        }
        None => renderer.prepare(settings)?,
    };
    Ok(slot.insert(prepared))
}
