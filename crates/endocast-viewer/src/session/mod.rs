//! The viewer's state without a window: the scene, the flying camera, the controls, the key
//! frames and their playback, the annotations, and the render worker that draws the view.
//! Every user action is a method here; the UI ([`crate::app`]) only maps input to them, so
//! tests drive a session exactly as the window does.

use crate::controller::{FlyCamera, LocalMove};
mod key_frames;

pub use key_frames::{Playback, KEY_FRAME_UNDO};

use crate::geometry::{Geometry, SceneRef, Toggles};
use crate::jobs::{Job, Notify, Polled};
use crate::scene::{Navigation, Scene};
use crate::worker::{RenderWorker, View};
use endocast_core::animation::KeyFrame;
use endocast_core::annotate::{self, Annotation, Annotations, DrawOptions, Shape, SurfaceView};
use endocast_core::camera::{Camera, CameraError, Optics, Projection, StereoRig};
use endocast_core::look::{Lighting, Look, LookKind};
use endocast_core::navigate::{nearest_lumen_point, snap_radius_mm, LumenSide};
use endocast_core::pose::Pose;
use endocast_core::presets::{self, Preset};
use endocast_core::render::{Filter, Mode, PeelSettings, RenderSettings, TransferFunction};
use endocast_core::study::{Study, StudyRequest};
use endocast_core::views::slices::Window;
use endocast_core::views::{lens_marks, Image};
use glam::DVec3;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The default size of the endoscopic view, pixels.
pub const DEFAULT_VIEW_SIZE: [usize; 2] = [512, 512];

/// How long a moving view waits for the last one's first frame before superseding it anyway.
const MAX_WAIT_FOR_FRAME: Duration = Duration::from_millis(150);

/// Everything the control panel sets.
#[derive(Debug, Clone, PartialEq)]
pub struct Controls {
    /// The procedure preset whose defaults the rest started from; `None`: no procedure (the
    /// whole object framed, the wall between background and object).
    pub preset: Option<&'static Preset>,
    /// The settings the rest were resolved with: the preset's in the scan's units (its second
    /// surface, colours, peel); the controls below override them.
    pub base: RenderSettings,
    /// Render mode.
    pub mode: Mode,
    /// Wall isovalue, physical units.
    pub iso_hu: f64,
    /// Opacity of the wall, 0–1.
    pub iso_opacity: f32,
    /// The lens.
    pub projection: Projection,
    /// Field of view, degrees across the image height.
    pub fov_deg: f64,
    /// Red/cyan anaglyph stereo.
    pub stereo: bool,
    /// The camera slides along the wall instead of entering it.
    pub collision: bool,
    /// Flying speed, mm/s.
    pub speed_mm_s: f64,
    /// Window of the slices.
    pub window: Window,
    /// The transfer function (DVR, and behind a translucent wall).
    pub tf: TransferFunction,
    /// How `peel` mode peels.
    pub peel: PeelSettings,
    /// The geometry shown with the scan.
    pub geometry: Toggles,
    /// The endoscope's look: the renderer's own image (plain), or the clinical or realistic
    /// look of the preset.
    pub look: LookKind,
    /// How the clinical or realistic look lights the tissue: Phong or a lit sphere.
    pub lighting: Lighting,
    /// How the still of a standing view reconstructs the volume (trilinear, or B-splines:
    /// sharper, each frame about ten times slower).
    pub still_filter: Filter,
}

impl Controls {
    /// The defaults `study` resolved (its preset in the scan's units, or the view without one),
    /// collision on, 20 mm/s.
    pub fn of_study(study: &Study) -> Self {
        let base = study.settings().clone();
        let preset = study.request().preset;
        let (projection, fov_deg) = presets::lens_defaults(study.preset(), None, None, 0.0);
        Self {
            preset,
            mode: base.mode,
            iso_hu: base.iso_hu,
            iso_opacity: base.iso_opacity,
            projection,
            fov_deg,
            stereo: false,
            collision: true,
            speed_mm_s: 20.0,
            window: study.window(),
            tf: base.tf.clone(),
            peel: base.peel.clone(),
            geometry: Toggles::default(),
            look: study.look().kind,
            lighting: Lighting::Phong,
            still_filter: Filter::Trilinear,
            base,
        }
    }

    /// The render settings: the resolved ones with the mode and the wall as set here.
    pub fn settings(&self) -> RenderSettings {
        let mut settings = self.base.clone();
        settings.mode = self.mode;
        settings.iso_hu = self.iso_hu;
        settings.iso_opacity = self.iso_opacity;
        settings.tf.clone_from(&self.tf);
        settings.peel.clone_from(&self.peel);
        settings
    }

    /// The optics: projection, field of view and the look's lens (the realistic look's rigid
    /// endoscope, [`LookKind::default_lens`], as `endocast render` gives it).
    pub fn optics(&self) -> Optics {
        Optics {
            projection: self.projection,
            field: self.fov_deg,
            lens: self.look.default_lens(self.projection),
            ..Optics::default()
        }
    }

    /// The preset's name, `none` without one (as cases store it).
    pub fn preset_name(&self) -> &'static str {
        self.preset.map_or(NO_PRESET, |p| p.name)
    }
}

/// The name cases and the panel give the absence of a preset.
pub const NO_PRESET: &str = "none";

/// One open scan and everything done to it.
#[derive(Debug)]
pub struct Session {
    scene: Arc<Scene>,
    /// The scan understood for the preset: what the controls started from.
    study: Arc<Study>,
    navigation: Option<Navigation>,
    /// The lumen being found around a new eye position.
    finding: Option<Job<Option<Navigation>>>,
    camera: FlyCamera,
    home: FlyCamera,
    /// The control panel's values.
    pub controls: Controls,
    view_size: [usize; 2],
    worker: RenderWorker,
    last_view: Option<View>,
    /// The stereo focus and the pose it was measured at (see [`Session::focus_mm`]).
    stereo_focus: Option<(FlyCamera, f64)>,
    last_submit: Option<(u64, Instant)>,
    key_frames: Vec<KeyFrame>,
    /// The key frames before each of the last changes, oldest first.
    key_frame_history: Vec<Vec<KeyFrame>>,
    playback: Option<Playback>,
    marks: Annotations,
    /// The stroke being drawn, surface points so far.
    stroke: Vec<DVec3>,
    /// Grows with every change of the annotations, the stroke being drawn or the target.
    marks_revision: u64,
    /// A target ringed in the view (a bronchoscopy route's, read with its path), world mm.
    target_mm: Option<DVec3>,
    geometry: Geometry,
    /// Called from the render thread after each delivered frame.
    on_frame: OnFrame,
}

/// What the render thread calls after each delivered frame (kept to start another worker).
#[derive(Clone)]
struct OnFrame(Notify);

impl std::fmt::Debug for OnFrame {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("OnFrame")
    }
}

impl Session {
    /// A session on `scene` for `preset` (none: the whole object framed), as the study of the
    /// scan resolves it ([`Study::resolve`], as every command does): its values in the scan's
    /// units, starting at `pose` or, without one, inside the structure the preset means
    /// looking along its path; `on_frame` is called from the render thread after each
    /// delivered frame.
    pub fn new(
        scene: Arc<Scene>,
        preset: Option<&'static Preset>,
        pose: Option<Pose>,
        on_frame: impl Fn() + Send + Sync + 'static,
    ) -> Self {
        let request = StudyRequest {
            preset,
            pose,
            ..StudyRequest::default()
        };
        let study = Arc::new(Study::resolve(scene.volume(), &request));
        let controls = Controls::of_study(&study);
        let pose = study.start_pose();
        let camera = FlyCamera::from_pose(&pose)
            .or_else(|| FlyCamera::new(pose.eye_mm, DVec3::Z, DVec3::NEG_Y))
            .unwrap_or_else(|| {
                FlyCamera::new(DVec3::ZERO, DVec3::Z, DVec3::NEG_Y).expect("a valid frame")
            });
        let on_frame = OnFrame(Arc::new(on_frame));
        let worker = start_worker(&scene, &on_frame);
        let mut session = Self {
            scene,
            study,
            navigation: None,
            finding: None,
            camera,
            home: camera,
            controls,
            view_size: DEFAULT_VIEW_SIZE,
            worker,
            last_view: None,
            stereo_focus: None,
            last_submit: None,
            key_frames: Vec::new(),
            key_frame_history: Vec::new(),
            playback: None,
            marks: Annotations::default(),
            stroke: Vec::new(),
            marks_revision: 0,
            target_mm: None,
            geometry: Geometry::default(),
            on_frame,
        };
        // The first lumen is found here, on the loading thread; later ones off the UI thread.
        session.navigation = session.lumen_search().and_then(|search| search());
        session
    }

    /// The scene.
    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// Shows `scene` from now on, understood as `study` says (the same scan cleansed, or as
    /// acquired again): a render worker of its own, the lumen around the eye found in it; the
    /// camera, the controls, the key frames and the marks stay.
    pub fn show_scene(&mut self, scene: Arc<Scene>, study: Arc<Study>) {
        self.worker = start_worker(&scene, &self.on_frame);
        self.scene = scene;
        self.study = study;
        self.last_view = None;
        self.last_submit = None;
        self.stereo_focus = None;
        self.navigation = None;
        self.find_lumen();
    }

    /// The flying camera.
    pub fn fly_camera(&self) -> &FlyCamera {
        &self.camera
    }

    /// The render worker.
    pub fn worker(&self) -> &RenderWorker {
        &self.worker
    }

    /// The lumen the camera is in, if it is in one of the preset's.
    pub fn navigation(&self) -> Option<&Navigation> {
        self.navigation.as_ref()
    }

    /// The size of the endoscopic view, pixels.
    pub fn view_size(&self) -> [usize; 2] {
        self.view_size
    }

    /// Renders the view at `size` pixels from now on (clamped to 16–4096).
    pub fn set_view_size(&mut self, size: [usize; 2]) {
        self.view_size = size.map(|n| n.clamp(16, 4096));
    }

    /// The endoscope camera now.
    pub fn camera(&self) -> Result<Camera, CameraError> {
        let c = &self.camera;
        self.controls
            .optics()
            .camera(c.eye_mm(), c.eye_mm() + c.forward(), c.up(), self.view_size)
    }

    /// The view to render now; `None` when the controls make no camera.
    fn view(&mut self, moving: bool) -> Option<View> {
        let camera = self.camera().ok()?;
        let stereo = if self.controls.stereo {
            Some(StereoRig::focused_at(self.focus_mm()))
        } else {
            None
        };
        let scene = self.drawn_scene();
        let look = self.look();
        Some(View {
            camera,
            settings: self.controls.settings(),
            stereo,
            moving,
            scene,
            look,
            still_filter: self.controls.still_filter,
        })
    }

    /// The clinical or realistic look as set (`None`: plain), the preset's in the scan's units;
    /// its tissue follows the wall once the wall is moved off the preset's.
    fn look(&self) -> Option<Look> {
        let mut look = Look::of_kind(self.controls.look, &self.study.look())?;
        if !self.wall_is_the_studys() {
            look.ray.tissue_hu = self.controls.iso_hu;
        }
        look.shading.lighting.clone_from(&self.controls.lighting);
        Some(look)
    }

    /// The geometry the view draws now (the toggles' grid, instrument, mark spheres, meshes).
    pub fn drawn_scene(&mut self) -> SceneRef {
        let marks = self.marks.items().iter().filter_map(|a| match a.shape {
            Shape::Point(p) => Some(p),
            _ => None,
        });
        let marks = marks.collect();
        let (lo, hi) = self.scene.volume().geometry().world_bounds();
        self.geometry
            .scene(self.controls.geometry, marks, (lo + hi) / 2.0)
    }

    /// The meshes read and the scene last built from the geometry toggles.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The meshes read and the scene built from the geometry toggles.
    pub fn geometry_mut(&mut self) -> &mut Geometry {
        &mut self.geometry
    }

    /// Whether the view (camera, settings or geometry) differs from the last one sent to the
    /// worker, so that the window renders it at moving quality first.
    pub fn view_changed(&mut self) -> bool {
        match (self.view(false), &self.last_view) {
            (Some(now), Some(last)) => {
                View {
                    moving: last.moving,
                    ..now
                } != *last
            }
            (now, last) => now.is_some() != last.is_some(),
        }
    }

    /// Sends the current view to the worker when it differs from the last one sent (or when the
    /// camera has just stopped, so the view refines); returns the new request's generation.
    pub fn sync(&mut self, moving: bool) -> Option<u64> {
        self.poll_lumen();
        let view = self.view(moving)?;
        if self.last_view.as_ref() == Some(&view) {
            return None;
        }
        // While moving, a new view waits until the last one has shown a frame (or is overdue):
        // superseding every frame before it finishes would show none at all.
        if moving && self.awaiting_first_frame() {
            return None;
        }
        self.last_view = Some(view.clone());
        let generation = self.worker.submit(view);
        self.last_submit = Some((generation, Instant::now()));
        Some(generation)
    }

    fn awaiting_first_frame(&self) -> bool {
        let Some((generation, at)) = self.last_submit else {
            return false;
        };
        let shown = self.worker.with_latest(|f| f.map_or(0, |f| f.generation));
        shown < generation && at.elapsed() < MAX_WAIT_FOR_FRAME
    }

    /// The stereo focus: the distance to the wall ahead (the last frame's centre pixel, else
    /// 10 mm), measured once per pose and kept while the camera stays, so that the frames
    /// delivered at a pose (preview, full, still) do not move the focus and the view settles.
    fn focus_mm(&mut self) -> f64 {
        match self.stereo_focus {
            Some((pose, focus)) if pose == self.camera => focus,
            _ => {
                let focus = self.last_centre_depth_mm().unwrap_or(10.0);
                self.stereo_focus = Some((self.camera, focus));
                focus
            }
        }
    }

    /// The depth of the last frame's centre pixel, when it saw a wall more than 1 mm away.
    fn last_centre_depth_mm(&self) -> Option<f64> {
        self.worker.with_latest(|f| {
            f.and_then(|f| {
                let [w, h] = f.camera.size();
                let d = *f.depth_mm.get(w / 2 + w * (h / 2))?;
                (d.is_finite() && d > 1.0).then_some(f64::from(d))
            })
        })
    }

    /// Flies by `step` (sliding along the wall when collision is on); returns the distance
    /// travelled, mm.
    /// While the lumen around a new position is being found, collision holds the camera.
    pub fn fly(&mut self, step: LocalMove) -> f64 {
        self.poll_lumen();
        if self.controls.collision && self.finding.is_some() {
            return 0.0;
        }
        let eye = self.camera.eye_mm();
        let collider = self
            .navigation
            .as_ref()
            .filter(|_| self.controls.collision)
            .and_then(|n| n.collider_at(eye));
        self.camera.translate(step, collider.as_ref())
    }

    /// Mouse-look: turns right by `yaw_rad` and up by `pitch_rad`.
    pub fn turn(&mut self, yaw_rad: f64, pitch_rad: f64) {
        self.camera.turn(yaw_rad, pitch_rad);
    }

    /// Rolls the image clockwise by `rad`.
    pub fn roll(&mut self, rad: f64) {
        self.camera.roll(rad);
    }

    /// Turns toward the surface seen at pixel `(x, y)` of the shown frame; false when that
    /// pixel shows no surface.
    pub fn look_at_pixel(&mut self, x: usize, y: usize) -> bool {
        match self.surface_point(x, y) {
            Some(p) => {
                self.camera.look_toward(p);
                true
            }
            None => false,
        }
    }

    /// The surface point seen at pixel `(x, y)` of the last delivered frame, world mm.
    pub fn surface_point(&self, x: usize, y: usize) -> Option<DVec3> {
        self.worker.with_latest(|f| {
            let f = f?;
            let [w, h] = f.camera.size();
            if x >= w || y >= h {
                return None;
            }
            let depth = f.depth_mm[x + w * y];
            depth
                .is_finite()
                .then(|| f.camera.point_at(x, y, f64::from(depth)))
                .flatten()
        })
    }

    /// Jumps the eye to `p_mm` (a click in a slice), keeping the view direction, moved to the
    /// nearest voxel of the lumen within the planner's snap radius (the study's structure
    /// while the wall is the study's), and finds the lumen there for collision. Returns what
    /// happened in words when the point was moved, or when no lumen lies that near.
    pub fn jump_to(&mut self, p_mm: DVec3) -> Option<String> {
        let volume = self.scene.volume();
        let radius = snap_radius_mm(volume.geometry().spacing_mm());
        let structure = self.study.structure().filter(|_| self.wall_is_the_studys());
        let snapped = self
            .lumen_threshold()
            .and_then(|lumen| nearest_lumen_point(volume, p_mm, lumen, structure, radius));
        let half_voxel = 0.5 * volume.geometry().spacing_mm().max_element();
        let said = match snapped {
            Some(q) if q.distance(p_mm) > half_voxel => Some(format!(
                "moved {:.1} mm from the click into the lumen",
                q.distance(p_mm)
            )),
            Some(_) => None,
            None => Some(format!(
                "not in a lumen: none within {radius:.0} mm of the click"
            )),
        };
        self.camera.jump_to(snapped.unwrap_or(p_mm));
        self.find_lumen();
        said
    }

    /// Moves the eye, within the plane across the view, to the middle of the lumen around it
    /// (the view direction stays); false outside a lumen.
    pub fn centre_in_lumen(&mut self) -> bool {
        let Some(nav) = &self.navigation else {
            return false;
        };
        let c = &self.camera;
        let centre = nav.centred(c.eye_mm(), c.forward());
        self.camera.jump_to(centre);
        true
    }

    /// Back to the starting view.
    pub fn reset(&mut self) {
        self.camera = self.home;
        self.find_lumen();
    }

    /// Moves the camera to `camera` (a reopened case), finding its lumen.
    pub fn set_camera(&mut self, camera: FlyCamera) {
        self.camera = camera;
        self.find_lumen();
    }

    /// Applies `preset`'s clinical defaults (mode, wall, lens, window), keeping the pose.
    pub fn apply_preset(&mut self, preset: Option<&'static Preset>) {
        let kept = (self.controls.collision, self.controls.speed_mm_s);
        self.study = Arc::new(self.study_here(preset));
        self.controls = Controls::of_study(&self.study);
        (self.controls.collision, self.controls.speed_mm_s) = kept;
        self.find_lumen();
    }

    /// The study of the scan for `preset` from the camera where it is (no structure searched).
    pub fn study_here(&self, preset: Option<&'static Preset>) -> Study {
        let request = StudyRequest {
            preset,
            pose: Some(self.camera.pose()),
            ..StudyRequest::default()
        };
        Study::resolve(self.scene.volume(), &request)
    }

    /// The scan understood for the preset (its values, structure and start).
    pub fn study(&self) -> &Study {
        &self.study
    }

    /// Whether the wall is where the study put it (not moved in the panel): the study's
    /// structure and plan then hold for it.
    pub fn wall_is_the_studys(&self) -> bool {
        self.controls.iso_hu == self.study.settings().iso_hu
    }

    /// The study, shared (for work off the UI thread).
    pub fn shared_study(&self) -> Arc<Study> {
        Arc::clone(&self.study)
    }

    /// Finds the lumen around the eye for the preset's lumen threshold (the wall isovalue for a
    /// preset without one); none when the eye is in the wall or outside.
    ///
    /// A new lumen is found on a thread of its own (a flood fill and a distance field: up to
    /// a second on a large scan); meanwhile there is none, see [`Session::finding_lumen`].
    pub fn find_lumen(&mut self) {
        let eye = self.camera.eye_mm();
        if let Some(nav) = &self.navigation {
            if nav.distance_mm(eye) > 0.0 {
                self.finding = None;
                return;
            }
        }
        self.navigation = None;
        self.finding = self
            .lumen_search()
            .map(|search| Job::spawn("lumen", self.worker.notifier(), search));
    }

    /// The search for the lumen around the eye, to run anywhere; `None` without a threshold.
    fn lumen_search(&self) -> Option<impl FnOnce() -> Option<Navigation> + Send + 'static> {
        let (threshold, side) = self.lumen_threshold()?;
        let renderer = Arc::clone(&self.scene.renderer);
        let eye = self.camera.eye_mm();
        Some(move || Navigation::around(renderer.volume(), eye, threshold, side))
    }

    /// Whether the lumen around the eye is being found.
    pub fn finding_lumen(&self) -> bool {
        self.finding.is_some()
    }

    /// Takes the lumen found, when the search has finished.
    pub fn poll_lumen(&mut self) {
        let Some(job) = &self.finding else {
            return;
        };
        match job.poll() {
            Polled::Running => {}
            Polled::Done(navigation) => {
                self.navigation = navigation;
                self.finding = None;
            }
            Polled::Lost => self.finding = None,
        }
    }

    /// The threshold and side the lumen is grown at for the wall as set now, by the study's
    /// rule ([`Study::lumen_at`]): the preset's lumen threshold moved with the wall but never
    /// past halfway to the lumen's own value, else the wall isovalue (lumen darker than the
    /// wall).
    pub fn lumen_threshold(&self) -> Option<(f64, LumenSide)> {
        self.study.lumen_at(self.controls.iso_hu).ok()
    }

    /// Labels the surface point seen at pixel `(x, y)`; false when no surface is seen there
    /// (or no annotation id is left).
    pub fn annotate_pixel(&mut self, x: usize, y: usize, label: &str) -> bool {
        self.surface_point(x, y)
            .and_then(|p| {
                let mark = Annotation::new(Shape::Point(p)).labelled(label);
                self.add_mark(mark)
            })
            .is_some()
    }

    /// Measures between the surface points seen at pixels `a` and `b`: adds the measurement
    /// and returns its length, mm; `None` when either pixel shows no surface (or no annotation
    /// id is left).
    pub fn measure_pixels(&mut self, a: [usize; 2], b: [usize; 2]) -> Option<f64> {
        let p = self.surface_point(a[0], a[1])?;
        let q = self.surface_point(b[0], b[1])?;
        self.add_mark(Annotation::new(Shape::Distance(p, q)))?;
        Some(p.distance(q))
    }

    /// Continues the stroke being drawn (or starts one) at the surface seen at pixel
    /// `(x, y)`; false when no surface is seen there.
    pub fn stroke_to_pixel(&mut self, x: usize, y: usize) -> bool {
        let Some(p) = self.surface_point(x, y) else {
            return false;
        };
        if self.stroke.last() != Some(&p) {
            self.stroke.push(p);
            self.marks_revision += 1;
        }
        true
    }

    /// The stroke being drawn, surface points so far.
    pub fn stroke_in_progress(&self) -> &[DVec3] {
        &self.stroke
    }

    /// Ends the stroke being drawn, adding it (labelled `label`) when it has a point; returns
    /// its id (`None` when it has none, or no annotation id is left).
    pub fn finish_stroke(&mut self, label: &str) -> Option<u32> {
        let points = std::mem::take(&mut self.stroke);
        if points.is_empty() {
            return None;
        }
        self.add_mark(Annotation::new(Shape::Stroke(points)).labelled(label))
    }

    /// The annotations, oldest first.
    pub fn annotations(&self) -> &[Annotation] {
        self.marks.items()
    }

    /// The annotations as a set.
    pub fn marks(&self) -> &Annotations {
        &self.marks
    }

    /// Replaces the annotations (a reopened case).
    pub fn set_marks(&mut self, marks: Annotations) {
        self.marks = marks;
        self.stroke.clear();
        self.marks_revision += 1;
    }

    /// Adds `mark`; `None` when no annotation id is left.
    fn add_mark(&mut self, mark: Annotation) -> Option<u32> {
        let id = self.marks.add(mark).ok()?;
        self.marks_revision += 1;
        Some(id)
    }

    /// A number that grows with every change of the annotations or the stroke being drawn
    /// (the view redraws its decals when it changes).
    pub fn marks_revision(&self) -> u64 {
        self.marks_revision
    }

    /// Rings `target_mm` (world mm; a bronchoscopy target) in the view from now on: solid
    /// where the view sees it, dashed where it lies behind the wall; `None`: no target.
    pub fn set_target(&mut self, target_mm: Option<DVec3>) {
        self.target_mm = target_mm;
        self.marks_revision += 1;
    }

    /// The target ringed in the view, world mm.
    pub fn target(&self) -> Option<DVec3> {
        self.target_mm
    }

    /// Deletes annotation `id`.
    pub fn delete_annotation(&mut self, id: u32) {
        self.marks.remove(id);
        self.marks_revision += 1;
    }

    /// The current view rendered at full quality, with the annotations drawn where it sees
    /// their tissue, and the target.
    pub fn screenshot(&self) -> Result<Image, String> {
        self.screenshot_work()()
    }

    /// The work of [`Session::screenshot`], holding what it needs, to run off the UI thread.
    pub fn screenshot_work(&self) -> impl FnOnce() -> Result<Image, String> + Send + 'static {
        let renderer = Arc::clone(&self.scene.renderer);
        let settings = self.controls.settings();
        let camera = self.camera().map_err(|e| e.to_string());
        let marks = self.marks.clone();
        let target = self.target_mm;
        move || {
            let camera = camera?;
            let prepared = renderer.prepare(&settings).map_err(|e| e.to_string())?;
            let frame = prepared.render(&camera);
            let mut image =
                Image::from_frame(&frame, settings.background).map_err(|e| e.to_string())?;
            let spacing = renderer.volume().geometry().spacing_mm();
            let view = SurfaceView::new(&camera, &frame.depth_mm, spacing);
            annotate::draw(&mut image, &view, marks.items(), &DrawOptions::default());
            if let Some(target) = target {
                annotate::draw_target(&mut image, &view, target);
            }
            lens_marks::draw(&mut image, &camera);
            Ok(image)
        }
    }
}

/// A render worker on `scene`'s renderer, calling `on_frame` after each delivered frame.
fn start_worker(scene: &Scene, on_frame: &OnFrame) -> RenderWorker {
    let on_frame = Arc::clone(&on_frame.0);
    RenderWorker::start(Arc::clone(&scene.renderer), move || on_frame())
}
