//! The frames of a flight: render each shot, track the wall seen, and lay out the dashboard.

use super::error::FlightError;
use super::overview::Overview;
use super::Shot;
use crate::annotate::{self, Annotations, DrawOptions, SurfaceView};
use crate::camera::{Optics, StereoRig};
use crate::coverage::Coverage;
use crate::look::{shade_with_scene, stereo_frame, Look, RayPass};
use crate::render::{
    Camera, Filter, Frame, Prepared, Quality, RenderSettings, RenderStats, Renderer, StereoFrames,
};
use crate::scene::Scene;
use crate::views::dashboard::{Dashboard, DashboardInfo, DashboardLayout};
use crate::views::slices::{camera_cross_section, camera_slices, SliceOptions, Window};
use crate::views::stereo::{self, StereoOutput};
use crate::views::{lens_marks, Image, Rgb};
use glam::DVec3;
use std::sync::Arc;

/// Colour and strength of the tint on wall not seen yet, in the dashboard's overview.
const UNSEEN_TINT: (Rgb, f32) = ([230, 40, 40], 0.55);

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
    /// The camera's projection, field, lens and near distance (a key frame's field of view
    /// overrides the field).
    pub optics: Optics,
    /// Stereo: both eyes rendered and combined into each frame; `None` for one eye.
    pub stereo: Option<FlightStereo>,
    /// What each frame shows.
    pub layout: Layout,
    /// Display window of the slices.
    pub window: Window,
}

/// How a flight is filmed in stereo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightStereo {
    /// How the eyes are combined (a pair: see [`Flight::stereo_frame`]).
    pub output: StereoOutput,
    /// Distance between the eyes, mm; `None`: the focus distance / 30 (see
    /// [`StereoRig::for_view`]).
    pub eye_separation_mm: Option<f64>,
    /// Distance of the zero-parallax plane, mm; `None`: the nearest surface in each frame's
    /// view.
    pub focus_mm: Option<f64>,
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
    /// Geometry drawn in every endoscope frame.
    scene: Option<Arc<Scene>>,
    /// Annotations drawn as decals on every endoscope frame.
    marks: Option<Annotations>,
    /// A target ringed on every endoscope frame (world mm).
    target_mm: Option<DVec3>,
    /// The frames rendered into (the second for a stereo pair's right eye), their buffers
    /// reused from shot to shot.
    frames: StereoFrames,
    /// The clinical or realistic look of the endoscope frames, if any.
    look: Option<Look>,
    /// The look's ray pass and the settings it was made for.
    look_pass: Option<(RenderSettings, RayPass)>,
    /// The camera of the last frame rendered (the left eye's for a pair).
    last_camera: Option<Camera>,
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
            scene: None,
            marks: None,
            target_mm: None,
            frames: StereoFrames::default(),
            look: None,
            look_pass: None,
            last_camera: None,
        }
    }

    /// Shows the endoscope frames in `look` (clinical or realistic; `None`: the renderer's own
    /// image) from now on, the scene composited into them by depth (in each eye of a stereo
    /// pair).
    pub fn set_look(&mut self, look: Option<Look>) {
        self.look = look;
        self.look_pass = None;
    }

    /// Draws `scene` (meshes, grid, markers, the endoscope's instruments) in every endoscope
    /// frame from now on.
    pub fn set_scene(&mut self, scene: Option<Arc<Scene>>) {
        if let Some(prepared) = &mut self.prepared {
            prepared.set_scene(scene.clone());
        }
        self.scene = scene;
    }

    /// Draws `marks` on every endoscope frame from now on, where the view sees the tissue they
    /// were put on.
    pub fn set_annotations(&mut self, marks: Option<Annotations>) {
        self.marks = marks;
    }

    /// Rings `target_mm` (world mm; a bronchoscopy target) on every endoscope frame from now
    /// on: solid where the frame sees it, dashed where it lies behind the wall.
    pub fn set_target(&mut self, target_mm: Option<DVec3>) {
        self.target_mm = target_mm;
    }

    /// `image`, the picture of `frame` taken by `camera`, with the annotations, the target and
    /// the lens's marks (the cube's faces, the panorama's directions) drawn on it.
    fn with_marks(&self, mut image: Image, camera: &Camera, frame: &Frame) -> Image {
        let spacing = self.renderer.volume().geometry().spacing_mm();
        let view = SurfaceView::new(camera, &frame.depth_mm, spacing);
        if let Some(marks) = &self.marks {
            annotate::draw(&mut image, &view, marks.items(), &DrawOptions::default());
        }
        if let Some(target) = self.target_mm {
            annotate::draw_target(&mut image, &view, target);
        }
        lens_marks::draw(&mut image, camera);
        image
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

    /// Tracks the wall seen into `coverage` from now on (`None`: stops tracking); returns the
    /// coverage tracked so far.
    pub fn set_coverage(&mut self, coverage: Option<Coverage>) -> Option<Coverage> {
        std::mem::replace(&mut self.coverage, coverage)
    }

    /// The camera of the last frame rendered (the left eye's for a stereo pair) and that
    /// frame's depth, mm along each ray (NaN where none); `None` before the first frame.
    pub fn last_view(&self) -> Option<(Camera, &[f32])> {
        let depth = self.frames.eyes[0].depth_mm.as_slice();
        self.last_camera.map(|camera| (camera, depth))
    }

    /// The coverage, when tracked, ending the flight.
    pub fn into_coverage(self) -> Option<Coverage> {
        self.coverage
    }

    /// Frame number `index` for `shot`, rendered with `settings`, and the render's statistics.
    /// A stereo flight's frame combines both eyes as its output says (a pair's frame is the
    /// left eye; [`Flight::stereo_frame`] gives both).
    pub fn frame(
        &mut self,
        index: usize,
        shot: &Shot,
        settings: &RenderSettings,
    ) -> Result<(Image, RenderStats), FlightError> {
        let (camera, eyes, stats) = self.render_shot(shot, settings)?;
        let endoscope = match (self.options.stereo, eyes) {
            (Some(stereo), Some([left, right])) => stereo::combine(&left, &right, stereo.output)?,
            _ => {
                let image = Image::from_frame(&self.frames.eyes[0], settings.background)?;
                self.with_marks(image, &camera, &self.frames.eyes[0])
            }
        };
        let image = match self.options.layout {
            Layout::Endoscope => endoscope,
            Layout::Dashboard => self.dashboard_frame(index, shot, &camera, &endoscope)?,
        };
        Ok((image, stats))
    }

    /// The left and right views of `shot` in a stereo flight (the endoscopic view alone, for
    /// writing as two films); a flight without stereo gives its one view twice.
    pub fn stereo_frame(
        &mut self,
        shot: &Shot,
        settings: &RenderSettings,
    ) -> Result<([Image; 2], RenderStats), FlightError> {
        let (_, eyes, stats) = self.render_shot(shot, settings)?;
        let eyes = match eyes {
            Some(eyes) => eyes,
            None => {
                let view = Image::from_frame(&self.frames.eyes[0], settings.background)?;
                [view.clone(), view]
            }
        };
        Ok((eyes, stats))
    }

    /// Renders `shot` — one eye into `frames[0]`, or a stereo pair into both — and records the
    /// wall it saw (the left eye's, for a pair). Returns the camera, the two eyes' images for
    /// a pair, and the statistics of everything rendered.
    fn render_shot(
        &mut self,
        shot: &Shot,
        settings: &RenderSettings,
    ) -> Result<(Camera, Option<[Image; 2]>, RenderStats), FlightError> {
        let pose = &shot.pose;
        let optics = match shot.fov_deg {
            Some(fov) => self.options.optics.with_fov(fov),
            None => self.options.optics,
        };
        let camera = optics.camera(pose.eye_mm, pose.look_at_mm, pose.up, self.options.size)?;
        let prepared = prepared(&mut self.prepared, &self.renderer, settings, &self.scene)?;
        let (seen_by, eyes) = match self.options.stereo {
            None => {
                match &self.look {
                    Some(look) => {
                        let slot = &mut self.look_pass;
                        let pass = look_pass(slot, &self.renderer, settings, look)?;
                        let gbuffer = pass.trace(&camera, Quality::Full);
                        let scene = self.scene.as_deref();
                        self.frames.eyes[0] =
                            shade_with_scene(&gbuffer, &camera, &look.shading, scene)?;
                    }
                    None => prepared.render_into(&camera, &mut self.frames.eyes[0]),
                }
                (camera, None)
            }
            Some(stereo) => {
                let rig = StereoRig::for_view(stereo.eye_separation_mm, stereo.focus_mm, || {
                    prepared.nearest_surface_mm(&camera)
                })?;
                match &self.look {
                    Some(look) => {
                        let slot = &mut self.look_pass;
                        let pass = look_pass(slot, &self.renderer, settings, look)?;
                        let (scene, pair) = (self.scene.as_deref(), &mut self.frames);
                        let eyes = stereo_frame(
                            pass,
                            (&camera, &rig),
                            &look.shading,
                            scene,
                            (0, Filter::Trilinear),
                            pair,
                        );
                        pair.eyes = eyes?;
                    }
                    None => prepared.render_stereo_into(&camera, &rig, &mut self.frames)?,
                }
                let [left, right] = &self.frames.eyes;
                let background = settings.background;
                let cameras = rig.eyes(&camera)?;
                let eyes = [
                    self.with_marks(Image::from_frame(left, background)?, &cameras[0], left),
                    self.with_marks(Image::from_frame(right, background)?, &cameras[1], right),
                ];
                (cameras[0], Some(eyes))
            }
        };
        let mut stats = self.frames.eyes[0].stats;
        if eyes.is_some() {
            stats.add(&self.frames.eyes[1].stats);
        }
        if let Some(coverage) = &mut self.coverage {
            coverage.record(&seen_by, &self.frames.eyes[0])?;
        }
        self.last_camera = Some(seen_by);
        Ok((camera, eyes, stats))
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

/// The ray pass of `look` in `slot` for `settings`, made again only when they change.
fn look_pass<'s>(
    slot: &'s mut Option<(RenderSettings, RayPass)>,
    renderer: &Arc<Renderer>,
    settings: &RenderSettings,
    look: &Look,
) -> Result<&'s RayPass, FlightError> {
    let (_, pass) = match slot.take() {
        Some((s, pass)) if s == *settings => slot.insert((s, pass)),
        _ => {
            let pass = RayPass::new(renderer, settings, &look.ray)?;
            slot.insert((settings.clone(), pass))
        }
    };
    Ok(pass)
}

/// The prepared renderer in `slot` for `settings`, updated only when they change.
fn prepared<'s>(
    slot: &'s mut Option<Prepared>,
    renderer: &Arc<Renderer>,
    settings: &RenderSettings,
    scene: &Option<Arc<Scene>>,
) -> Result<&'s Prepared, FlightError> {
    let prepared = match slot.take() {
        Some(mut p) => {
            if p.settings() != settings {
                p.update(settings)?;
            }
            p
        }
        None => {
            let mut p = renderer.prepare(settings)?;
            p.set_scene(scene.clone());
            p
        }
    };
    Ok(slot.insert(prepared))
}
