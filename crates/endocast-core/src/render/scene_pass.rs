//! Geometry in the volume, ray by ray (Scharsach et al. 2006, §3.4), after the volume pass of
//! a tile: each pixel's ray is traced against the [`Scene`] up to where the volume's result
//! became opaque, and what it meets joins the pixel in true depth order.
//!
//! - Opaque geometry ends the volume ray at its exact distance (the ray-length image of the
//!   paper: [`RayMarch::limit`], the path of the per-pixel maximum distances).
//! - Translucent geometry inside the part of the ray the volume samples splits the march: the
//!   volume is walked up to the surface, the surface composited, and the walk goes on behind
//!   it ([`RayMarch::part`]) — the exact order, not a two-pass approximation.
//! - Geometry in front of where the volume is sampled or behind it is composited around the
//!   volume's result without walking the ray again. So does any geometry in iso mode (the
//!   result is one surface at a known depth) and in MIP/MinIP, whose projections have no depth:
//!   there the geometry lies in front of the projection.
//!
//! Only rays that meet geometry inside the sampled part of the ray before it became opaque are
//! walked again; the others cost one trace against the scene, pruned at the volume's end. The
//! rays of each 8×8 block of pixels are traced as one packet: nearly square, it meets fewer
//! nodes of a mesh's hierarchy per ray than a row of pixels does.
//!
//! With an opaque mesh or the instruments in the scene, where the volume's result does not stop
//! at a surface (DVR, two isosurfaces, hybrid with a translucent surface), the tile's rays meet
//! the scene's opaque surfaces before the volume is walked instead —
//! the paper's order: each walk ends at its nearest opaque surface (a hybrid search one step
//! behind it, so that it still sees a crossing just in front of it, and the compositing behind
//! the hybrid surface at it), so no walk goes on behind geometry only to be walked again in
//! front of it, and the surfaces traced ahead serve the pass after the walk, cut at its bound.
//! The images are the same as in the volume-first order, but for a sample lying exactly at an
//! opaque surface's distance, which is now behind it, and a rounding (at most 2 of 255 in 196
//! renders compared) where translucent geometry lies in front of a hybrid surface.

use super::integrate::Integrator;
use super::march::{MarchStats, RayMarch};
use super::ray_task::{PixelOut, RayTask};
use super::sample::Accum;
use super::settings::Mode;
use super::tile_pass::{RowTasks, TileView};
use super::tiles::{Tile, TileRect};
use super::traverse::VoxelRay;
use super::{adjust, vignette, Prepared};
use crate::camera::Ray;
use crate::scene::bvh::PACKET;
use crate::scene::{Hit, PlacedScene, Scene, Traced};
use glam::{Vec3, Vec3A};
use std::cell::RefCell;
use std::ops::Range;
use std::sync::Arc;

/// Side of the square block of pixels whose rays meet the scene as one packet (their walks
/// through a mesh's hierarchy share most nodes).
const BLOCK: usize = 8;
const _: () = assert!(BLOCK * BLOCK == PACKET, "a block is one packet");

thread_local! {
    /// Each worker thread's buffers for the scene pass, kept from tile to tile.
    static SCRATCH: RefCell<SceneScratch> = RefCell::new(SceneScratch::default());
}

/// A tile's buffers for [`Prepared::add_scene`], kept from block to block.
#[derive(Default)]
struct SceneScratch {
    /// The block's rays and their intervals.
    rays: Vec<Traced>,
    /// Each ray's pixel and the index of its rendered task in the pixel's row (`None`: the
    /// ray misses the volume).
    pixels: Vec<(usize, usize, Option<usize>)>,
    /// Each ray's surfaces.
    hits: Vec<Vec<Hit>>,
    /// The surfaces of pixels whose ray misses the volume: `(column, row, result)`.
    others: Vec<(usize, usize, PixelOut)>,
    /// Each pixel's nearest opaque surface in the tile, traced before the volume walk
    /// ([`Prepared::end_at_geometry`]), while `ahead_traced`: its bound and the hit.
    ahead: Vec<Option<(f64, Hit)>>,
    ahead_traced: bool,
    /// The block's rays' entries of `ahead`.
    opaque: Vec<Option<(f64, Hit)>>,
}

impl SceneScratch {
    /// The entries of `ahead` for the block's rays, into `opaque`.
    fn opaque_ahead(&mut self, rect: TileRect) {
        self.opaque.clear();
        let ahead = &self.ahead;
        let pixels = self.pixels.iter();
        self.opaque
            .extend(pixels.map(|&(x, y, _)| ahead[rect.index(x, y)]));
    }
}

impl Prepared {
    /// The scene drawn with the volume (none by default).
    pub fn scene(&self) -> Option<&Arc<Scene>> {
        self.scene.as_ref()
    }

    /// Draws `scene` with the volume in every later frame (`None`: the volume alone). Opaque
    /// surfaces end the rays; translucent ones are composited with the volume samples in depth
    /// order. The depth layer is then the nearest of the isosurface and the geometry.
    pub fn set_scene(&mut self, scene: Option<Arc<Scene>>) {
        self.scene = scene;
    }

    /// Adds `scene` to the rays of the tile `view.rect`: the rendered tasks of `rows` (one
    /// per row of the tile) in place, and the pixels of `tile` whose ray misses the volume
    /// from their surfaces alone. The rays of each square block of pixels are traced together.
    pub(super) fn add_scene(
        &self,
        integrator: &Integrator<'_>,
        scene: &PlacedScene<'_>,
        view: &TileView<'_>,
        rows: &mut [RowTasks],
        tile: &mut Tile,
    ) {
        SCRATCH.with_borrow_mut(|scratch| {
            scratch.others.clear();
            let rect = view.rect;
            for y0 in (rect.y0..rect.y1).step_by(BLOCK) {
                for x0 in (rect.x0..rect.x1).step_by(BLOCK) {
                    let xs = x0..(x0 + BLOCK).min(rect.x1);
                    let ys = y0..(y0 + BLOCK).min(rect.y1);
                    self.block_rays(view, (xs, ys), rows, scratch);
                    self.add_block_hits(integrator, scene, view, rows, scratch);
                }
            }
            scratch.ahead_traced = false;
            for (x, y, out) in &mut scratch.others {
                vignette(view.camera, *x, *y, out);
                tile.pixels[rect.index(*x, *y)] = self.pixel_of(out);
            }
        });
    }

    /// Whether opaque geometry should end the volume rays before they are walked: where the
    /// volume's result does not stop at a surface (DVR, two isosurfaces, hybrid with a
    /// translucent surface), a ray walked first would be walked again in front of the
    /// geometry ([`Self::split_task`]). The tile pass asks it only for scenes with an opaque
    /// mesh or the instruments ([`PlacedScene::has_opaque_cover`]).
    pub(super) fn geometry_first(&self) -> bool {
        let params = &self.params;
        match params.mode {
            Mode::Dvr | Mode::TwoIso => true,
            Mode::Hybrid => params.lower.opacity < params.early_termination,
            _ => false,
        }
    }

    /// Ends each not yet walked ray of `rows` (the tile `view.rect`) at the nearest opaque
    /// surface of `scene` inside its span — for the hybrid mode one sample step behind it, so
    /// that the search still sees a crossing just in front of it, while the compositing behind
    /// the surface stops at it. The scene pass after the walk reuses these surfaces (kept
    /// below its bound) and composites them as it would after a full walk.
    pub(super) fn end_at_geometry(
        &self,
        scene: &PlacedScene<'_>,
        view: &TileView<'_>,
        rows: &mut [RowTasks],
    ) {
        SCRATCH.with_borrow_mut(|scratch| {
            let rect = view.rect;
            let pixels = (rect.x1 - rect.x0) * (rect.y1 - rect.y0);
            scratch.ahead.clear();
            scratch.ahead.resize(pixels, None);
            for y0 in (rect.y0..rect.y1).step_by(BLOCK) {
                for x0 in (rect.x0..rect.x1).step_by(BLOCK) {
                    let xs = x0..(x0 + BLOCK).min(rect.x1);
                    let ys = y0..(y0 + BLOCK).min(rect.y1);
                    self.block_rays(view, (xs, ys), rows, scratch);
                    self.end_block(scene, view, rows, scratch);
                }
            }
            scratch.ahead_traced = true;
        });
    }

    /// [`Self::end_at_geometry`] for the block of rays in `scratch`.
    fn end_block(
        &self,
        scene: &PlacedScene<'_>,
        view: &TileView<'_>,
        rows: &mut [RowTasks],
        scratch: &mut SceneScratch,
    ) {
        scratch.opaque.clear();
        scratch.opaque.resize(scratch.rays.len(), None);
        scene.nearest_opaque_many(&scratch.rays, &mut scratch.opaque);
        let behind = match self.params.mode {
            Mode::Hybrid => 1.0,
            _ => 0.0,
        };
        for (&(x, y, task), &found) in scratch.pixels.iter().zip(&scratch.opaque) {
            scratch.ahead[view.rect.index(x, y)] = found;
            let (Some(i), Some((_, hit))) = (task, found) else {
                continue;
            };
            let row = &mut rows[y - view.rect.y0];
            let march = &mut row.tasks[i].march;
            let (t_start, t_end) = march.span();
            if hit.t_mm > t_start && hit.t_mm < t_end {
                march.limit(hit.t_mm + behind * march.grid().step);
                if row.composite_ends.len() < row.tasks.len() {
                    row.composite_ends.resize(row.tasks.len(), f32::INFINITY);
                }
                row.composite_ends[i] = hit.t_mm;
            }
        }
    }

    /// The rays of the pixels `xs × ys` into `scratch` (cleared first), each traced from the
    /// camera's near plane to where its volume result became opaque.
    fn block_rays(
        &self,
        view: &TileView<'_>,
        (xs, ys): (Range<usize>, Range<usize>),
        rows: &[RowTasks],
        scratch: &mut SceneScratch,
    ) {
        scratch.rays.clear();
        scratch.pixels.clear();
        let (camera, width) = (view.camera, view.camera.size()[0]);
        let origin = camera.shared_origin();
        for y in ys {
            let row = &rows[y - view.rect.y0];
            // The row's rendered columns ascend: the next one to match.
            let mut next = row.columns.partition_point(|&c| c < xs.start);
            for x in xs.clone() {
                let task = (row.columns.get(next) == Some(&x)).then_some(next);
                next += usize::from(task.is_some());
                // A rendered ray's direction is the camera's, rounded to `f32` (as a mesh's
                // hierarchy takes it): no second set-up of the ray.
                let ray = match (task, origin) {
                    (Some(i), Some(origin)) => Some(Ray {
                        origin,
                        dir: row.tasks[i].dir_world.as_dvec3(),
                    }),
                    _ => camera.pixel_ray(x, y),
                };
                let Some(ray) = ray else {
                    continue;
                };
                let near = camera.near_distance_along(ray.dir);
                let mut bound = task.map_or(f64::INFINITY, |i| self.volume_bound(&row.tasks[i]));
                if let Some(max) = view.options.max_distance_mm {
                    let limit = f64::from(max[x + width * y]);
                    bound = if limit < bound { limit } else { bound };
                }
                scratch.rays.push(Traced {
                    ray,
                    t_min: near,
                    t_max: bound,
                });
                scratch.pixels.push((x, y, task));
            }
        }
    }

    /// Traces the block of rays in `scratch` against `scene` and joins their hits to the
    /// pixels' results.
    fn add_block_hits(
        &self,
        integrator: &Integrator<'_>,
        scene: &PlacedScene<'_>,
        view: &TileView<'_>,
        rows: &mut [RowTasks],
        scratch: &mut SceneScratch,
    ) {
        let n = scratch.rays.len();
        if scratch.hits.len() < n {
            scratch.hits.resize_with(n, Vec::new);
        }
        if scratch.ahead_traced {
            scratch.opaque_ahead(view.rect);
            scene.trace_many_after(&scratch.rays, &scratch.opaque, &mut scratch.hits);
        } else {
            scene.trace_many(&scratch.rays, &mut scratch.hits);
        }
        for ((&(x, y, task), traced), hits) in
            scratch.pixels.iter().zip(&scratch.rays).zip(&scratch.hits)
        {
            if hits.is_empty() {
                continue;
            }
            match task {
                Some(i) => {
                    let row = &mut rows[y - view.rect.y0];
                    let end = row.composite_ends.get(i).copied();
                    let task = &mut row.tasks[i];
                    let composited = (task, end.unwrap_or(f32::INFINITY));
                    self.with_hits(integrator, view, (x, y), hits, composited);
                }
                None => {
                    let mut out = PixelOut::default();
                    for hit in hits {
                        add_hit(integrator, &mut out.accum, hit, traced.ray.dir.as_vec3());
                    }
                    out.depth_mm = hits[0].t_mm;
                    scratch.others.push((x, y, out));
                }
            }
        }
    }

    /// Where the volume's result along `task`'s ray became opaque (geometry behind it cannot
    /// show), mm; infinity where it did not.
    fn volume_bound(&self, task: &RayTask) -> f64 {
        let (out, params) = (&task.out, &self.params);
        let stop = params.early_termination;
        let surface_stops = params.lower.opacity >= stop && !out.depth_mm.is_nan();
        let bound = match params.mode {
            Mode::Iso | Mode::Hybrid | Mode::Peel if surface_stops => Some(out.depth_mm),
            Mode::Mip | Mode::Minip | Mode::Iso => None,
            _ if out.terminated => task.march.last_sample_t(),
            _ => None,
        };
        bound.map_or(f64::INFINITY, f64::from)
    }

    /// Joins `hits` (in depth order) to the rendered ray `task` of pixel `(x, y)`, whose
    /// compositing behind a hybrid surface ended at `composite_end` mm.
    fn with_hits(
        &self,
        integrator: &Integrator<'_>,
        view: &TileView<'_>,
        (x, y): (usize, usize),
        hits: &[Hit],
        (task, composite_end): (&mut RayTask, f32),
    ) {
        let dir = task.dir_world;
        let (t_start, t_end) = task.march.span();
        let out = &mut task.out;
        let opaque_surface = self.params.lower.opacity >= self.params.early_termination;
        match self.params.mode {
            // Peel: hits join around the shown surface (what the peel keeps in front of it is
            // not split at hits inside it).
            Mode::Iso | Mode::Peel => {
                let depth = out.depth_mm;
                // Every hit where there is no surface (NaN depth).
                let in_front = hits.partition_point(|h| h.t_mm < depth || depth.is_nan());
                *out = around(integrator, out, hits, in_front, dir);
            }
            Mode::Mip | Mode::Minip => *out = around(integrator, out, hits, hits.len(), dir),
            // Hybrid draws nothing in front of its surface: hits there, and any hit when the
            // surface is opaque, join around it — so do hits at or behind where the walk's
            // compositing behind the surface already stopped (opaque geometry traced ahead).
            Mode::Hybrid
                if !out.depth_mm.is_nan()
                    && (opaque_surface
                        || hits
                            .iter()
                            .all(|h| h.t_mm < out.depth_mm || h.t_mm >= composite_end)) =>
            {
                let in_front = hits.partition_point(|h| h.t_mm < out.depth_mm);
                *out = around(integrator, out, hits, in_front, dir);
            }
            // No surface in front of an opaque hit that the walk reached: hybrid draws nothing
            // there, so the hits alone (what walking the ray again would give).
            Mode::Hybrid
                if out.depth_mm.is_nan()
                    && hits
                        .last()
                        .is_some_and(|h| h.opacity >= 1.0 && h.t_mm <= t_end) =>
            {
                *out = around(integrator, out, hits, hits.len(), dir);
            }
            _ if hits.iter().all(|h| h.t_mm <= t_start || h.t_mm >= t_end) => {
                let in_front = hits.partition_point(|h| h.t_mm <= t_start);
                *out = around(integrator, out, hits, in_front, dir);
            }
            _ => {
                let surface = out.depth_mm;
                if let Some(split) = self.split_task(integrator, view, (x, y), hits, surface) {
                    *task = split;
                }
            }
        }
    }

    /// Pixel `(x, y)`'s ray walked again, ended at the opaque hit and split at the
    /// translucent ones. `surface` is where the ray walked without geometry met the hybrid
    /// mode's isosurface (NaN: nowhere).
    fn split_task(
        &self,
        integrator: &Integrator<'_>,
        view: &TileView<'_>,
        (x, y): (usize, usize),
        hits: &[Hit],
        surface: f32,
    ) -> Option<RayTask> {
        let ray = self.ray(view.camera, x, y)?;
        let mut task = self.task_of(&ray, x, y)?;
        adjust(&mut task.march, view.options, x + view.camera.size()[0] * y);
        let (translucent, opaque) = match hits.split_last() {
            Some((last, rest)) if last.opacity >= 1.0 => (rest, Some(last)),
            _ => (hits, None),
        };
        let end_mm = opaque.map_or(f32::INFINITY, |hit| hit.t_mm);
        if opaque.is_some() {
            // A surface crossed within a step in front of the opaque hit is found only with the
            // sample behind the crossing: the search may look that far, the compositing
            // stops at the hit (`Split::end_mm`).
            let search_end = if surface < end_mm && self.params.mode == Mode::Hybrid {
                end_mm.max(surface + task.march.grid().step)
            } else {
                end_mm
            };
            task.march.limit(search_end);
        }
        let split = Split {
            ray: &ray.voxel,
            bricks: self.renderer.grid.bricks(),
            dir: task.dir_world,
            end_mm,
        };
        task.out = integrator.run_split(&mut task.march, &split, translucent);
        if let (Some(hit), false) = (opaque, task.out.terminated) {
            add_hit(integrator, &mut task.out.accum, hit, task.dir_world);
        }
        task.out.depth_mm = nearest(task.out.depth_mm, hits[0].t_mm);
        Some(task)
    }
}

/// A split ray's voxel-space ray, brick counts, unit world direction and where its opaque hit
/// ends it, mm (infinity: none).
pub(super) struct Split<'a> {
    ray: &'a VoxelRay,
    bricks: [usize; 3],
    dir: Vec3,
    end_mm: f32,
}

impl Integrator<'_> {
    /// Renders `march` (ended at any opaque hit) in the configured mode with the translucent
    /// `hits` (depth order) composited between its samples where they lie.
    fn run_split(&self, march: &mut RayMarch, split: &Split<'_>, hits: &[Hit]) -> PixelOut {
        let mut out = PixelOut::default();
        let dir = split.dir;
        let span = march.span();
        match self.params.mode {
            Mode::Hybrid => {
                let depth = self
                    .first_hit(march, &mut ())
                    .filter(|&depth| depth < split.end_mm);
                let Some(depth) = depth else {
                    for hit in hits {
                        add_hit(self, &mut out.accum, hit, dir);
                    }
                    return out;
                };
                let behind = hits.partition_point(|h| h.t_mm < depth);
                for hit in &hits[..behind] {
                    add_hit(self, &mut out.accum, hit, dir);
                }
                out.depth_mm = depth;
                self.lit_surface(march, dir, &mut out);
                let from = (depth, span.1.min(split.end_mm));
                self.parts(march, split, from, &hits[behind..], &mut out, |m, out| {
                    self.composite(m, out, dir, false, &mut ());
                });
            }
            Mode::TwoIso => {
                let mut previous = (0.0, 0.0);
                self.parts(march, split, span, hits, &mut out, |m, out| {
                    self.two_iso_part(m, dir, out, &mut previous, &mut ());
                });
            }
            _ => {
                let shade = self.params.shade_dvr;
                self.parts(march, split, span, hits, &mut out, |m, out| {
                    self.composite(m, out, dir, shade, &mut ());
                });
            }
        }
        out
    }

    /// Walks `march` over `(from, to)` mm in parts split at `hits` (inside it, depth order):
    /// `walk` each part onto `out`, then the hit's surface, until the ray is opaque.
    fn parts(
        &self,
        march: &mut RayMarch,
        split: &Split<'_>,
        (from, to): (f32, f32),
        hits: &[Hit],
        out: &mut PixelOut,
        mut walk: impl FnMut(&mut RayMarch, &mut PixelOut),
    ) {
        let mut previous = march.clone();
        let mut start = from;
        let ends = hits.iter().map(|h| (h.t_mm, Some(h))).chain([(to, None)]);
        for (end, hit) in ends {
            let end = end.clamp(start, to);
            let mut part = previous.part(split.ray, (start, end), split.bricks);
            walk(&mut part, out);
            add_stats(&mut march.stats, &part.stats);
            if out.terminated {
                return;
            }
            if let Some(hit) = hit {
                add_hit(self, &mut out.accum, hit, split.dir);
            }
            previous = part;
            start = end;
        }
    }
}

/// `hits[..in_front]`, then the volume's result `out`, then the rest of `hits`; the depth the
/// nearest of the volume's and the first hit's.
fn around(
    integrator: &Integrator<'_>,
    out: &PixelOut,
    hits: &[Hit],
    in_front: usize,
    dir: Vec3,
) -> PixelOut {
    let mut joined = PixelOut {
        accum: Accum::default(),
        ..*out
    };
    for hit in &hits[..in_front] {
        add_hit(integrator, &mut joined.accum, hit, dir);
    }
    let volume = out.accum;
    joined.accum.under(volume.rgb, 0.0);
    joined.accum.transmittance *= volume.transmittance;
    for hit in &hits[in_front..] {
        add_hit(integrator, &mut joined.accum, hit, dir);
    }
    joined.depth_mm = nearest(out.depth_mm, hits[0].t_mm);
    joined
}

/// The nearer of a volume depth (NaN: none) and a hit's distance.
fn nearest(depth_mm: f32, hit_mm: f32) -> f32 {
    if depth_mm <= hit_mm {
        depth_mm
    } else {
        hit_mm
    }
}

/// Composites the shaded surface of `hit`, seen along unit world `dir`, under `accum`.
fn add_hit(integrator: &Integrator<'_>, accum: &mut Accum, hit: &Hit, dir: Vec3) {
    let lit = integrator.shader.shade(hit.color, hit.normal, dir);
    accum.under(Vec3A::from(lit) * hit.opacity, hit.opacity);
}

/// Adds a part's counters to the ray's.
fn add_stats(total: &mut MarchStats, part: &MarchStats) {
    total.samples += part.samples;
    total.bricks_visited += part.bricks_visited;
    total.bricks_skipped += part.bricks_skipped;
}
