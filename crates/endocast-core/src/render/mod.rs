//! The perspective ray caster of Scharsach et al., "Perspective Isosurface and Direct Volume
//! Rendering for Virtual Endoscopy Applications" (EuroVis 2006), on the CPU.
//!
//! Three objects with three lifetimes (as in Open VKL):
//! - [`Renderer`]: the volume, its [`BrickGrid`] (min/max per brick of `BRICK_VOX`³ voxels) and,
//!   for many frames, a copy of its voxels brick by brick for the sample batches
//!   ([`BrickedVoxels`]), built once;
//! - [`Prepared`]: what the settings imply — the transfer function's [`TfTable`] and the
//!   brick [`Activity`] — rebuilt in milliseconds whenever an isovalue or the TF changes
//!   ([`Prepared::update`]); it shares the renderer through an [`Arc`], so a worker thread can
//!   own it;
//! - [`Camera`]: one per frame.
//!
//! A frame holds float layers ([`Frame`]): the background and the 8-bit conversion come last.
//! [`Prepared::render_with`] renders at a [`Quality`] level, fills optional [`Layers`], ends
//! rays at a per-pixel maximum distance, and can be cancelled between tiles; [`Still`]
//! accumulates jittered frames and [`progressive`] runs quarter → half → full → still while the
//! view stands.
//!
//! Each pixel's ray is moved into voxel space, starts on the near plane (eye inside the volume)
//! or where it enters the volume, walks the brick grid ([`traverse`]), samples only in active
//! bricks on a fixed per-ray sample grid, and is integrated by its mode's small function
//! (`integrate`). Tiles of pixels are rendered in parallel; every pixel is a pure function of
//! its index, so the image does not depend on the thread count.
//!
//! ```
//! use endocast_core::phantom::{self, PhantomOptions};
//! use endocast_core::render::{Camera, Mode, RenderSettings, Renderer};
//! use glam::DVec3;
//! use std::sync::Arc;
//!
//! let (volume, shell) = phantom::sphere_shell(&PhantomOptions { size: 32, ..Default::default() });
//! let centre_mm = volume.geometry().world_of(shell.centre_vox);
//! let renderer = Arc::new(Renderer::new(volume));
//! let mut settings = RenderSettings::default();
//! settings.mode = Mode::Iso;
//! settings.iso_hu = -480.0; // the phantom's air/tissue mid-value lies on its surface
//! let prepared = renderer.prepare(&settings).unwrap();
//! let camera = Camera::look_at(centre_mm, centre_mm + DVec3::Z, DVec3::Y, 90.0, [16, 16]).unwrap();
//! let frame = prepared.render(&camera);
//! // From the centre every ray hits the inner wall at its radius (1 mm voxels).
//! assert!(frame.depth_mm.iter().all(|d| (d - shell.inner_radius_vox as f32).abs() < 0.05));
//! ```

mod bricks;

mod cell_mask;
mod cell_walk;
mod crossing;
mod frame;
mod integrate;
mod march;
mod options;
mod preintegrate;
pub mod progressive;
pub mod quality;
mod ray_task;
mod reuse;
mod sample;
mod scene_pass;
mod settings;
mod simd;
mod stereo;
mod still;
mod tile_pass;
mod tiles;
mod trace;
mod transfer;
pub mod traverse;
mod trilinear_root;
mod voxel_grid;

#[cfg(test)]
mod camera_tests;
#[cfg(test)]
mod exact_tests;
#[cfg(test)]
mod interactive_tests;
#[cfg(test)]
mod peel_tests;
#[cfg(test)]
mod preintegrate_tests;
#[cfg(test)]
mod scene_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod timing_tests;

pub use crate::camera::{Camera, CameraError, FOV_RANGE_DEG, MAX_IMAGE_EDGE};

use crate::camera::Ray;
pub use bricks::{Activity, BitSet, BrickGrid, BRICK_VOX};
use cell_mask::CellMask;
pub use frame::{Frame, Layers, Premultiplied, RenderStats, DEPTH_LAYERS};
pub use options::{Cancelled, Filter, Progress, Quality, RenderOptions};
pub use progressive::{progressive, PreviewPlanner};
pub use reuse::FrameReuse;
pub use sample::{
    Accum, BSplineCoefficients, BrickedVoxels, Lanes, Lighting, SampleGrid, Sampler, Shader,
};
pub use settings::{
    Crossing, Mode, PeelLayer, PeelSettings, RenderSettings, SettingsError, Unpeeled,
};
pub use stereo::StereoFrames;
pub use still::{Jitter, Still};
pub use trace::{PixelTrace, TraceSample};
pub use transfer::{TfTable, TransferError, TransferFunction, OPACITY_UNIT_MM};

use frame::to_u8;
use glam::{DAffine3, DVec3, Vec3};
use integrate::{Classified, Integrator, Params, PeelParams, Probe, Surface};
use march::RayMarch;
use ray_task::{PixelOut, RayTask};
use simd::rays4::RaySetup;
#[cfg(target_arch = "x86_64")]
pub(crate) use simd::with_avx2;
use std::sync::{Arc, OnceLock};
use std::time::Instant;
use stereo::SearchStarts;
use tiles::{Control, Pixel, Tiling};
use traverse::{BrickDda, VoxelRay};

use crate::scene::Scene;
use crate::Volume;

/// A volume ready for rendering: the volume and its brick grid (built once), for sessions
/// of many frames its voxels brick by brick, and for B-spline stills its spline's coefficients
/// (built by the first frame that asks).
#[derive(Debug, Clone)]
pub struct Renderer {
    volume: Volume,
    grid: BrickGrid,
    bricked: Option<BrickedVoxels>,
    spline: OnceLock<BSplineCoefficients>,
    /// Whether the AVX2 paths run where the CPU has them (tests turn them off to check the
    /// paths other CPUs take against them).
    simd: bool,
}

impl Renderer {
    /// Builds the brick grid of `volume` (one parallel pass over the voxels).
    pub fn new(volume: Volume) -> Self {
        let grid = BrickGrid::new(&volume);
        Self {
            volume,
            grid,
            bricked: None,
            spline: OnceLock::new(),
            simd: true,
        }
    }

    /// The same renderer on the paths for CPUs without AVX2.
    #[cfg(test)]
    pub(crate) fn without_simd(self) -> Self {
        Self {
            simd: false,
            ..self
        }
    }

    /// [`Self::new`], plus a copy of the voxels brick by brick for the sample batches (1.2× the
    /// volume's memory, a parallel copy; none where the batches could not use it): a few per
    /// cent faster frames, for sessions that render many (fly-throughs, benchmarks) rather
    /// than one.
    pub fn for_many_frames(volume: Volume) -> Self {
        let bricked = BrickedVoxels::new(&volume);
        Self {
            bricked,
            ..Self::new(volume)
        }
    }

    /// The sampler of the voxels for the integrators.
    pub(crate) fn sampler(&self) -> Sampler<'_> {
        let sampler = match &self.bricked {
            Some(bricked) => Sampler::with_bricks(&self.volume, bricked),
            None => Sampler::new(&self.volume),
        };
        if self.simd {
            sampler
        } else {
            sampler.scalar()
        }
    }

    /// The sampler of the voxels reconstructing as `filter` says (the B-spline's coefficients
    /// built on first use: 4 bytes a voxel, a parallel pass).
    pub(crate) fn sampler_for(&self, filter: Filter) -> Sampler<'_> {
        match filter {
            Filter::Trilinear => self.sampler(),
            Filter::BSpline => Sampler::with_spline(&self.volume, self.spline_coefficients()),
        }
    }

    /// The coefficients of the volume's B-spline, built on the first call.
    pub fn spline_coefficients(&self) -> &BSplineCoefficients {
        self.spline
            .get_or_init(|| BSplineCoefficients::new(&self.volume))
    }

    /// The volume.
    pub fn volume(&self) -> &Volume {
        &self.volume
    }

    /// The brick grid.
    pub fn grid(&self) -> &BrickGrid {
        &self.grid
    }

    /// Gives the volume back.
    pub fn into_volume(self) -> Volume {
        self.volume
    }

    /// Classifies the bricks and tabulates the transfer function for `settings` (cheap: about a
    /// millisecond for a 512³ volume): [`Prepared::new`] on a share of this renderer. Fails
    /// when a setting is out of range.
    pub fn prepare(self: &Arc<Self>, settings: &RenderSettings) -> Result<Prepared, SettingsError> {
        Prepared::new(Arc::clone(self), settings)
    }
}

/// What the settings imply for one renderer: the lookup table, the brick classification and
/// the integrators' numbers.
#[derive(Debug)]
struct Derived {
    settings: RenderSettings,
    table: TfTable,
    activity: Activity,
    /// The cells that can hold the isosurface of the exact search (iso and hybrid only).
    cells: CellMask,
    /// The transfer function behind a peel and its active bricks ([`Mode::Peel`] only).
    after: Option<(TfTable, BitSet)>,
    params: Params,
    shader: Shader,
    step_mm: f64,
}

impl Derived {
    fn new(renderer: &Renderer, settings: &RenderSettings) -> Result<Self, SettingsError> {
        settings.validate()?;
        let volume = &renderer.volume;
        let geometry = volume.geometry();
        let map = volume.value_map();
        let step_mm = settings.step_mm(geometry.spacing_mm().min_element());
        let mut table = TfTable::new(&settings.tf, map, volume.stored_range(), step_mm);
        let stored = |hu: f64| map.stored_from_physical(hu) as f32;
        // A negative scale turns the order of stored values around; keep "lower" lower.
        let (lower_hu, upper_hu) = if map.scale() > 0.0 {
            (settings.iso_hu, settings.iso2_hu)
        } else {
            (settings.iso2_hu, settings.iso_hu)
        };
        let peel = settings.mode == Mode::Peel;
        // A peel's surface is its threshold's.
        let wall_hu = if peel {
            settings.peel_threshold_hu()
        } else {
            settings.iso_hu
        };
        let mut isovalues = vec![stored(wall_hu)];
        if settings.mode == Mode::TwoIso {
            table.make_transparent_between(stored(lower_hu), stored(upper_hu));
            isovalues.push(stored(settings.iso2_hu));
        }
        let activity = Activity::classify(&renderer.grid, &isovalues, &table);
        let exact = settings.exact_hits && matches!(settings.mode, Mode::Iso | Mode::Hybrid);
        let cells = if exact {
            CellMask::new(volume, &renderer.grid, &activity, isovalues[0])
        } else {
            CellMask::default()
        };
        let after = peel.then(|| {
            let tf = settings.peel.tf_after.as_ref().unwrap_or(&settings.tf);
            let after = TfTable::new(tf, map, volume.stored_range(), step_mm);
            let active = Activity::classify(&renderer.grid, &[], &after).tf;
            (after, active)
        });
        let surface = |iso_hu: f64, opacity: f32, color: [f32; 3]| Surface {
            iso: stored(iso_hu),
            opacity,
            color: Vec3::from(color),
        };
        let params = Params {
            mode: settings.mode,
            lower: surface(wall_hu, settings.iso_opacity, settings.iso_color),
            upper: surface(settings.iso2_hu, settings.iso2_opacity, settings.iso2_color),
            crossing: settings.crossing,
            early_termination: settings.early_termination,
            refine_steps: settings.refine_steps,
            exact_hits: settings.exact_hits,
            shade_dvr: settings.shade_dvr,
            dvr_stride: settings.preintegrated.then_some(settings.dvr_stride),
            skip_empty: settings.skip_empty,
            peel: PeelParams {
                nth: match settings.peel.layer {
                    PeelLayer::Nth(n) => Some(n),
                    PeelLayer::Last => None,
                },
                // Into the brighter material is up the stored values unless the map turns
                // their order around.
                rising: settings.peel.falling == (map.scale() < 0.0),
                keep: settings.peel.keep,
                context: settings.peel.unpeeled == Unpeeled::Context,
            },
        };
        let shader = Shader::new(geometry.world_from_voxel().matrix3, settings.lighting);
        Ok(Self {
            settings: settings.clone(),
            table,
            activity,
            cells,
            after,
            params,
            shader,
            step_mm,
        })
    }
}

/// A renderer with its settings applied: renders frames for any camera. It holds a share of
/// its [`Renderer`], so it can be moved to and owned by a worker thread (it is `Send + Sync`),
/// and [`Prepared::update`] applies new settings in place.
#[derive(Debug)]
pub struct Prepared {
    renderer: Arc<Renderer>,
    settings: RenderSettings,
    table: TfTable,
    activity: Activity,
    cells: CellMask,
    after: Option<(TfTable, BitSet)>,
    params: Params,
    shader: Shader,
    step_mm: f64,
    voxel_from_world: DAffine3,
    /// Geometry drawn with the volume ([`Self::set_scene`]).
    scene: Option<Arc<Scene>>,
    /// The brick classification (and the peel's transfer function's active bricks) for the
    /// B-spline's wider footprint ([`Activity::dilated`]), made by the first frame that asks.
    spline_activity: OnceLock<(Activity, Option<BitSet>)>,
}

/// A pixel's ray in the world and in voxel space, and its part inside the volume (mm).
#[derive(Debug, Clone, Copy)]
struct PixelRay {
    world: Ray,
    voxel: VoxelRay,
    range: Option<(f64, f64)>,
}

impl Prepared {
    /// `renderer` with `settings` applied: classifies the bricks and tabulates the transfer
    /// function (about a millisecond for a 512³ volume). Fails when a setting is out of range.
    pub fn new(renderer: Arc<Renderer>, settings: &RenderSettings) -> Result<Self, SettingsError> {
        let d = Derived::new(&renderer, settings)?;
        let voxel_from_world = renderer.volume.geometry().voxel_from_world();
        Ok(Self {
            renderer,
            settings: d.settings,
            table: d.table,
            activity: d.activity,
            cells: d.cells,
            after: d.after,
            params: d.params,
            shader: d.shader,
            step_mm: d.step_mm,
            voxel_from_world,
            scene: None,
            spline_activity: OnceLock::new(),
        })
    }

    /// Applies new `settings` in place (re-classifies the bricks and re-tabulates the transfer
    /// function: milliseconds). On an out-of-range setting the old ones stay in force.
    pub fn update(&mut self, settings: &RenderSettings) -> Result<(), SettingsError> {
        let d = Derived::new(&self.renderer, settings)?;
        self.settings = d.settings;
        self.table = d.table;
        self.activity = d.activity;
        self.cells = d.cells;
        self.after = d.after;
        self.params = d.params;
        self.shader = d.shader;
        self.step_mm = d.step_mm;
        self.spline_activity = OnceLock::new();
        Ok(())
    }

    /// The renderer.
    pub fn renderer(&self) -> &Arc<Renderer> {
        &self.renderer
    }

    /// The settings in force.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// The brick classification in force.
    pub fn activity(&self) -> &Activity {
        &self.activity
    }

    /// The transfer function's lookup table in force.
    pub fn table(&self) -> &TfTable {
        &self.table
    }

    /// Distance between samples, mm.
    pub fn step_mm(&self) -> f64 {
        self.step_mm
    }

    /// The integrators for frames of `camera` reconstructing as `filter` says (B-splines: the
    /// wider footprint's brick classification, and surfaces found by their samples).
    fn integrator(&self, camera: &Camera, filter: Filter) -> Integrator<'_> {
        let (activity, after_active) = match filter {
            Filter::Trilinear => (&self.activity, self.after.as_ref().map(|(_, a)| a)),
            Filter::BSpline => {
                let (activity, after) = self.spline_activity.get_or_init(|| {
                    let grid = &self.renderer.grid;
                    let after = self.after.as_ref().map(|(_, a)| a.dilated(grid.bricks()));
                    (self.activity.dilated(grid), after)
                });
                (activity, after.as_ref())
            }
        };
        let table = self.after.as_ref().map_or(&self.table, |(table, _)| table);
        let mut params = self.params;
        // The exact search solves the trilinear cell's cubic.
        params.exact_hits &= filter == Filter::Trilinear;
        let mut integrator = Integrator {
            sampler: self.renderer.sampler_for(filter),
            grid: &self.renderer.grid,
            activity,
            cells: &self.cells,
            table: &self.table,
            after: Classified {
                table,
                active: after_active.unwrap_or(&activity.tf),
            },
            shader: self.shader,
            params,
            eye_side: None,
        };
        // Every ray starting at the eye (t = 0) shares its crossing side: decided once.
        // (The origin every ray's `VoxelRay::new` computes, in the sample grid's f32.)
        integrator.eye_side = camera.shared_origin().map(|origin| {
            let eye = self.voxel_from_world.transform_point3(origin).as_vec3();
            (eye, integrator.rising_at(eye, self.params.lower.iso))
        });
        integrator
    }

    /// Renders one frame, tiles in parallel on the current rayon pool.
    pub fn render(&self, camera: &Camera) -> Frame {
        let mut frame = Frame::default();
        self.render_into(camera, &mut frame);
        frame
    }

    /// [`Self::render`] into `frame`, reusing its buffers (a loop over many frames of one size
    /// then allocates none: fresh buffers cost about 2 ms a frame in page faults).
    pub fn render_into(&self, camera: &Camera, frame: &mut Frame) {
        // Without a cancel flag nothing can cancel it.
        let _ = self.render_with(camera, &RenderOptions::new(), frame);
    }

    /// Renders into `frame` as `options` ask: at their quality, with their optional layers and
    /// maximum distances, stopping between tiles when their cancel flag is set (then `frame`'s
    /// content is unspecified and the call returns [`Cancelled`]). `frame.stats.time` is the
    /// whole call's time, upsampling included.
    ///
    /// # Panics
    ///
    /// When the options' maximum distances are not one per pixel of `camera`.
    pub fn render_with(
        &self,
        camera: &Camera,
        options: &RenderOptions<'_>,
        frame: &mut Frame,
    ) -> Result<(), Cancelled> {
        let start = Instant::now();
        match options.quality {
            Quality::Full => self.render_tiles(camera, options, frame)?,
            reduced => quality::render_reduced(self, camera, reduced, options, frame)?,
        }
        frame.stats.time = start.elapsed();
        Ok(())
    }

    /// Renders every pixel of `camera` into `frame` (full quality for this camera).
    fn render_tiles(
        &self,
        camera: &Camera,
        options: &RenderOptions<'_>,
        frame: &mut Frame,
    ) -> Result<(), Cancelled> {
        let [w, h] = camera.size();
        if let Some(max) = options.max_distance_mm {
            assert_eq!(max.len(), w * h, "one maximum distance per pixel");
        }
        let integrator = self.integrator(camera, options.filter);
        let scene = self.scene.as_ref().filter(|s| !s.is_empty());
        let placed = scene.map(|s| s.placed(camera));
        let tile = |rect| self.tile(&integrator, camera, options, placed.as_ref(), rect);
        let control = Control {
            cancel: options.cancel,
            progress: options.progress,
        };
        Tiling::new(camera.size()).render_into(tile, frame, options.layers, control)
    }

    /// The ray of pixel `(x, y)`, in the world and in voxel space, and its part inside the
    /// volume; `None` where the camera forms no ray.
    fn ray(&self, camera: &Camera, x: usize, y: usize) -> Option<PixelRay> {
        let world = camera.pixel_ray(x, y)?;
        let voxel = VoxelRay::new(&self.voxel_from_world, world.origin, world.dir);
        let dims = self.renderer.volume.dims();
        let extent = DVec3::from(dims.map(|n| (n - 1) as f64));
        let range = voxel.clip(extent, camera.near_distance_along(world.dir));
        Some(PixelRay {
            world,
            voxel,
            range,
        })
    }

    /// The sample grid's offset for pixel `(x, y)`: mid-step, the pixel's place in the 4×4
    /// interleaving pattern, or a per-pixel hash with jitter.
    fn offset(&self, x: usize, y: usize) -> f32 {
        if self.settings.interleave {
            interleaved_offset(x, y)
        } else if self.settings.jitter {
            pixel_hash(x, y)
        } else {
            0.5
        }
    }

    fn pixel(
        &self,
        integrator: &Integrator<'_>,
        camera: &Camera,
        x: usize,
        y: usize,
        stats: &mut RenderStats,
        probe: &mut impl Probe,
    ) -> PixelOut {
        let Some(mut task) = self.task(camera, x, y) else {
            return PixelOut::default();
        };
        task.out = integrator.run(&mut task.march, task.dir_world, probe);
        count_ray(stats, &task);
        task.out
    }

    /// The ray of pixel `(x, y)` ready to render, or `None` where it misses the volume.
    fn task(&self, camera: &Camera, x: usize, y: usize) -> Option<RayTask> {
        self.task_of(&self.ray(camera, x, y)?, x, y)
    }

    /// Pixel `(x, y)`'s `ray` ready to render, or `None` where it misses the volume.
    fn task_of(&self, ray: &PixelRay, x: usize, y: usize) -> Option<RayTask> {
        let (bricks, step) = (self.renderer.grid.bricks(), self.step_mm as f32);
        let march = RayMarch::new(&ray.voxel, ray.range?, bricks, step, self.offset(x, y));
        Some(RayTask::new(march, ray.world.dir.as_vec3()))
    }

    /// The rays of pixels `xs` of row `y` that meet the volume, and their columns: four at a
    /// time on AVX2 ([`RaySetup::rays4`], the same rays bit for bit), else one by one.
    fn row_tasks(
        &self,
        camera: &Camera,
        y: usize,
        xs: std::ops::Range<usize>,
        late: Option<(&Integrator<'_>, &SearchStarts)>,
        columns: &mut Vec<usize>,
        tasks: &mut Vec<RayTask>,
    ) {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = simd::Avx2::detect() {
            let dims = self.renderer.volume.dims();
            let bricks = self.renderer.grid.bricks();
            let setup = RaySetup::new(camera, &self.voxel_from_world, dims, bricks);
            let starts = late.map(|(_, starts)| starts);
            for x0 in xs.clone().step_by(4) {
                let late_starts = starts.map(|s| s.lanes(x0, y, self.step_mm as f32));
                let lanes = avx2.rays4(&setup, x0, y, late_starts.as_ref());
                for (x, lane) in (x0..xs.end).zip(lanes) {
                    let Some(lane) = lane else { continue };
                    let (step, offset) = (self.step_mm as f32, self.offset(x, y));
                    let mut march =
                        RayMarch::with_walk(lane.dda, &lane.ray, lane.range, step, offset);
                    if let (Some((integrator, starts)), false) = (late, lane.late) {
                        let (ray, range) = (&lane.ray, lane.range);
                        self.start_late(integrator, starts, [x, y], ray, range, &mut march);
                    }
                    columns.push(x);
                    tasks.push(RayTask::new(march, lane.dir_world.as_vec3()));
                }
            }
            return;
        }
        for x in xs {
            let Some(ray) = self.ray(camera, x, y) else {
                continue;
            };
            let Some(mut task) = self.task_of(&ray, x, y) else {
                continue;
            };
            if let (Some((integrator, starts)), Some(range)) = (late, ray.range) {
                self.start_late(
                    integrator,
                    starts,
                    [x, y],
                    &ray.voxel,
                    range,
                    &mut task.march,
                );
            }
            columns.push(x);
            tasks.push(task);
        }
    }

    /// Moves the search of pixel `[x, y]`'s `march` (along `ray` over `range`) to its start
    /// in `starts`, where the samples before the region known to be empty (up to the check
    /// distance) all lie on the eye's side of the isovalue; the sample grid stays the ray's.
    fn start_late(
        &self,
        integrator: &Integrator<'_>,
        starts: &SearchStarts,
        [x, y]: [usize; 2],
        ray: &VoxelRay,
        (t0, t1): (f64, f64),
        march: &mut RayMarch,
    ) {
        let Some((check, start)) = starts.at(x, y) else {
            return;
        };
        let grid = march.grid();
        if start <= grid.t_start {
            return;
        }
        let (eye, clear) = starts.clear;
        let empty = (grid.at(check + grid.step) - eye).length() < clear
            || self.on_eye_side_until(integrator, march, check);
        if empty {
            let t_start = f64::from(start).min(t1);
            let dda = BrickDda::new(ray, (t_start, t1), self.renderer.grid.bricks());
            let (step, offset) = (self.step_mm as f32, self.offset(x, y));
            *march = RayMarch::with_walk(dda, ray, (t0, t1), step, offset);
        }
    }

    /// Whether `march`'s samples up to the first one past `check` (mm) all lie on its eye's
    /// side of the isovalue: the first alone (where the eye is all but on the wall, it fails
    /// already), the others eight at a time.
    fn on_eye_side_until(&self, integrator: &Integrator<'_>, march: &RayMarch, check: f32) -> bool {
        let (grid, end) = (march.grid(), march.parts().2);
        let iso = self.params.lower.iso;
        let rising = integrator.rising(march, iso);
        let on_side = |v: f32| (v < iso) == rising;
        if end == 0 || !on_side(integrator.sampler.value(grid.at(grid.t_of(0)))) {
            return end == 0;
        }
        let prefix = (1..end).take_while(|&n| grid.t_of(n - 1) <= check);
        let last = 1 + prefix.count() as i32;
        (1..last).step_by(8).all(|n| {
            let taken = (last - n).min(8) as usize;
            let values = integrator.sampler.grid8(&grid, n, taken);
            values[..taken].iter().all(|&v| on_side(v))
        })
    }

    /// A composited pixel over the background, as 8-bit colour.
    fn display(&self, accum: &Accum) -> [u8; 3] {
        let background = Vec3::from(self.settings.background);
        let c = Vec3::from(accum.rgb) + background * accum.transmittance;
        [to_u8(c.x), to_u8(c.y), to_u8(c.z)]
    }

    /// A ray's result as the frame stores it.
    fn pixel_of(&self, out: &PixelOut) -> Pixel {
        let map = self.renderer.volume.value_map();
        Pixel {
            color: Premultiplied {
                rgb: out.accum.rgb.to_array(),
                transmittance: out.accum.transmittance,
            },
            depth_mm: out.depth_mm,
            value: (f64::from(out.value) * map.scale() + map.offset()) as f32,
        }
    }
}

/// Darkens a ray's colour by the camera lens's vignetting (and field stop) at pixel `(x, y)`.
fn vignette(camera: &Camera, x: usize, y: usize, out: &mut PixelOut) {
    if camera.lens().darkens() {
        let f = camera.vignetting(x as f64 + 0.5, y as f64 + 0.5) as f32;
        out.accum.rgb *= f;
    }
}

/// Applies a render's per-frame grid shift and the pixel's maximum distance (pixel index `i`)
/// to a march not yet walked.
fn adjust(march: &mut RayMarch, options: &RenderOptions<'_>, i: usize) {
    if options.grid_shift != 0.0 {
        march.shift_grid(options.grid_shift);
    }
    if let Some(max) = options.max_distance_mm {
        march.limit(max[i]);
    }
}

/// Adds a rendered ray's counters to `stats`.
fn count_ray(stats: &mut RenderStats, task: &RayTask) {
    let (march, out) = (&task.march.stats, &task.out);
    stats.rays += 1;
    stats.samples += march.samples;
    stats.bricks_visited += march.bricks_visited;
    stats.bricks_skipped += march.bricks_skipped;
    stats.terminated_early += u64::from(out.terminated);
    stats.iso_hits += u64::from(!out.depth_mm.is_nan());
}

/// The sample-grid offset of pixel `(x, y)` with interleaved sampling, in steps: the 4×4 Bayer
/// matrix's rank of the pixel's place in its tile, centred in its sixteenth of a step. Every
/// 4×4 tile (and every 2×2 quarter of one, in quarters of a step) holds each offset once.
pub(crate) fn interleaved_offset(x: usize, y: usize) -> f32 {
    const BAYER: [[u8; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];
    (f32::from(BAYER[y % 4][x % 4]) + 0.5) / 16.0
}

/// A deterministic value in [0, 1) per pixel (a 32-bit integer hash), the sample-grid offset
/// with jitter: the same on every run and thread count.
fn pixel_hash(x: usize, y: usize) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x9E37_79B1) ^ (y as u32).wrapping_mul(0x85EB_CA77);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7FEB_352D);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846C_A68B);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}
