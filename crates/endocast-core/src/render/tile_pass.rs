//! One tile of a frame: each row's rays through the volume as one group, then — with a scene —
//! the whole tile's rays against the geometry in square packets, then the pixels, counters and
//! optional layers. The rows' buffers are kept per worker thread from tile to tile.

use super::frame::{Layers, RenderStats};
use super::integrate::Integrator;
use super::options::RenderOptions;
use super::ray_task::{PixelOut, RayTask};
use super::tiles::{Extra, Tile, TileRect};
use super::{adjust, count_ray, vignette, Camera, Prepared};
use crate::scene::PlacedScene;
use std::cell::RefCell;

impl Prepared {
    /// Renders the pixels of `rect`, each row's rays as one group; with a scene, the whole
    /// tile's rays then meet it in square packets ([`Prepared::add_scene`]).
    pub(super) fn tile(
        &self,
        integrator: &Integrator<'_>,
        camera: &Camera,
        options: &RenderOptions<'_>,
        scene: Option<&PlacedScene<'_>>,
        rect: TileRect,
    ) -> Tile {
        let pixels = (rect.x1 - rect.x0) * (rect.y1 - rect.y0);
        let mut tile = Tile {
            pixels: vec![self.pixel_of(&PixelOut::default()); pixels],
            extras: Vec::new(),
            stats: RenderStats::default(),
        };
        if !options.layers.is_empty() {
            tile.extras = vec![Extra::default(); pixels];
        }
        let view = TileView {
            camera,
            options,
            rect,
        };
        // Without a scene each row is finished at once and its buffers reused.
        let height = if scene.is_some() {
            rect.y1 - rect.y0
        } else {
            1
        };
        let mut rows = ROWS.take();
        if rows.len() < height {
            rows.resize_with(height, RowTasks::default);
        }
        let rows_used = &mut rows[..height];
        if let Some(scene) = scene.filter(|s| self.geometry_first() && s.has_opaque_cover()) {
            // The ray-length image first (Scharsach et al. 2006, §3.4): no volume walk goes on
            // behind opaque geometry only to be walked again in front of it.
            for (row, y) in rows_used.iter_mut().zip(rect.y0..rect.y1) {
                row.y = y;
                self.row_rays(integrator, &view, row);
            }
            self.end_at_geometry(scene, &view, rows_used);
            for row in rows_used.iter_mut() {
                integrator.run_group(&mut row.tasks, !options.unlit, &row.composite_ends);
            }
        } else {
            for y in rect.y0..rect.y1 {
                let row = &mut rows_used[(y - rect.y0) % height];
                row.y = y;
                self.row_rays(integrator, &view, row);
                integrator.run_group(&mut row.tasks, !options.unlit, &[]);
                if scene.is_none() {
                    self.finish_row(integrator, &view, row, &mut tile);
                }
            }
        }
        if let Some(scene) = scene {
            self.add_scene(integrator, scene, &view, rows_used, &mut tile);
            for row in rows_used {
                self.finish_row(integrator, &view, row, &mut tile);
            }
        }
        ROWS.set(rows);
        tile
    }

    /// Sets up row `row.y`'s rays of the tile through the volume in `row` (cleared first),
    /// not yet walked.
    fn row_rays(&self, integrator: &Integrator<'_>, view: &TileView<'_>, row: &mut RowTasks) {
        let (options, rect, y) = (view.options, view.rect, row.y);
        let width = view.camera.size()[0];
        row.columns.clear();
        row.tasks.clear();
        row.composite_ends.clear();
        // A still frame's shifted grid is not the one the starts were checked on.
        let late = options.starts.filter(|_| options.grid_shift == 0.0);
        let late = late.map(|starts| (integrator, starts));
        let (columns, tasks) = (&mut row.columns, &mut row.tasks);
        self.row_tasks(view.camera, y, rect.x0..rect.x1, late, columns, tasks);
        if options.grid_shift != 0.0 || options.max_distance_mm.is_some() {
            for (&x, task) in columns.iter().zip(tasks.iter_mut()) {
                adjust(&mut task.march, options, x + width * y);
            }
        }
    }

    /// Writes row `row`'s rendered rays into `tile`: pixels, counters and optional layers.
    fn finish_row(
        &self,
        integrator: &Integrator<'_>,
        view: &TileView<'_>,
        row: &mut RowTasks,
        tile: &mut Tile,
    ) {
        let (camera, y) = (view.camera, row.y);
        for (&x, task) in row.columns.iter().zip(&mut row.tasks) {
            vignette(camera, x, y, &mut task.out);
            let task = &*task;
            let i = view.rect.index(x, y);
            tile.pixels[i] = self.pixel_of(&task.out);
            count_ray(&mut tile.stats, task);
            if !view.options.layers.is_empty() {
                let extra = &mut tile.extras[i];
                self.extra(integrator, camera, view.options, (x, y), task, extra);
            }
        }
    }

    /// The optional layers of pixel `(x, y)`, whose ray `task` has been rendered.
    fn extra(
        &self,
        integrator: &Integrator<'_>,
        camera: &Camera,
        options: &RenderOptions<'_>,
        (x, y): (usize, usize),
        task: &RayTask,
        extra: &mut Extra,
    ) {
        let layers = options.layers;
        let depth = task.out.depth_mm;
        if !depth.is_nan() {
            if layers.contains(Layers::HIT_POSITION) {
                if let Some(hit) = camera.point_at(x, y, f64::from(depth)) {
                    extra.hit_mm = hit.as_vec3().to_array();
                }
            }
            if layers.contains(Layers::NORMAL) {
                extra.normal = integrator.normal_at(&task.march, depth).to_array();
            }
        }
        if layers.contains(Layers::DEPTHS) {
            if let Some(mut fresh) = self.task(camera, x, y) {
                adjust(&mut fresh.march, options, x + camera.size()[0] * y);
                integrator.crossings(&mut fresh.march, &mut extra.depths_mm);
            }
        }
    }
}

thread_local! {
    /// Each worker thread's row buffers, kept from tile to tile.
    static ROWS: RefCell<Vec<RowTasks>> = RefCell::default();
}

/// What every row of one tile shares: the frame's camera and options, and the tile.
#[derive(Clone, Copy)]
pub(super) struct TileView<'r> {
    pub camera: &'r Camera,
    pub options: &'r RenderOptions<'r>,
    pub rect: TileRect,
}

/// One row of a tile: the columns whose rays meet the volume (ascending) and their tasks.
#[derive(Default)]
pub(super) struct RowTasks {
    pub y: usize,
    pub columns: Vec<usize>,
    pub tasks: Vec<RayTask>,
    /// Empty, or where each task's compositing behind a hybrid surface ends, mm (opaque
    /// geometry traced before the walk; infinity: the march's end).
    pub composite_ends: Vec<f32>,
}
