//! Geometry in the volume: triangle meshes, a grid of lines, marker spheres and an endoscope's
//! instruments, each with a colour and an opacity, placed in world millimetres (LPS), and
//! traced per ray so that they work with every projection.
//!
//! A [`Scene`] holds the objects; [`Scene::placed`] fixes the camera-bound ones (the
//! instruments) for one camera, and [`PlacedScene::trace`] lists what a ray meets in depth
//! order: every translucent surface in front of the nearest opaque one, then that one. The
//! renderer ends the volume ray at the opaque hit (Scharsach et al. 2006, §3.4: the ray length
//! image) and composites the translucent ones between the volume samples in their true order.
//!
//! ```
//! use endocast_core::scene::{GridPlane, Material, Marker, Scene};
//! use endocast_core::camera::Ray;
//! use glam::DVec3;
//!
//! let mut scene = Scene::new();
//! scene.add_grid(GridPlane::new(DVec3::ZERO, DVec3::Z, 10.0).unwrap(), Material::GRID);
//! let glass = Material::new([0.2, 0.6, 1.0], 0.5).unwrap();
//! scene.add_marker(Marker::new(DVec3::new(0.0, 0.0, 20.0), 5.0).unwrap(), glass);
//! let ray = Ray { origin: DVec3::new(0.0, 0.0, 40.0), dir: -DVec3::Z };
//! let mut hits = Vec::new();
//! scene.trace(&ray, 0.0, f64::INFINITY, &mut hits);
//! // Into and out of the glass sphere, then the opaque grid line at z = 0.
//! let depths: Vec<f32> = hits.iter().map(|h| h.t_mm).collect();
//! assert_eq!(depths, [15.0, 25.0, 40.0]);
//! ```

mod aids;
pub mod bvh;
mod mesh;

pub use aids::{Capsule, CapsuleFrom, Endoscope, GridPlane, Marker, DEFAULT_INSTRUMENT_LENGTH_MM};
pub use mesh::{MeshError, TriangleMesh};

use crate::camera::{Camera, Ray};
use bvh::{Bvh, PacketRay, PACKET};
use glam::{DVec3, Vec3};
use std::cell::Cell;
use std::sync::Arc;
use thiserror::Error;

/// A scene object that cannot be made.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SceneError {
    /// A colour channel outside 0–1 or an opacity outside 0–1.
    #[error("colour {0:?} and opacity {1} must lie in 0–1")]
    BadMaterial([f32; 3], f32),
    /// A grid's origin, normal, spacing or line width is unusable.
    #[error("grid: {0}")]
    BadGrid(String),
    /// A marker's centre is not finite or its radius not positive.
    #[error("marker at {0:?} of radius {1} mm: the centre must be finite, the radius positive")]
    BadMarker([f64; 3], f64),
    /// An endoscope's diameter or length is not positive.
    #[error("endoscope of diameter {0} mm and length {1} mm: both must be positive")]
    BadEndoscope(f64, f64),
}

/// How a surface looks: its colour (before shading, linear 0–1) and opacity (1: opaque).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Colour, 0–1 per channel.
    pub color: [f32; 3],
    /// Opacity, 0–1.
    pub opacity: f32,
}

impl Material {
    /// Opaque white lines: the grid's default.
    pub const GRID: Self = Self {
        color: [1.0, 1.0, 1.0],
        opacity: 1.0,
    };
    /// Opaque yellow: a marker's default.
    pub const MARKER: Self = Self {
        color: [1.0, 0.85, 0.1],
        opacity: 1.0,
    };
    /// Opaque light blue: a mesh's default.
    pub const MESH: Self = Self {
        color: [0.55, 0.75, 1.0],
        opacity: 1.0,
    };
    /// Brushed steel: the instruments.
    pub const STEEL: Self = Self {
        color: [0.72, 0.74, 0.78],
        opacity: 1.0,
    };

    /// A material, every channel and the opacity in 0–1.
    pub fn new(color: [f32; 3], opacity: f32) -> Result<Self, SceneError> {
        let unit = |v: f32| (0.0..=1.0).contains(&v);
        if !color.iter().all(|&c| unit(c)) || !unit(opacity) {
            return Err(SceneError::BadMaterial(color, opacity));
        }
        Ok(Self { color, opacity })
    }

    /// Whether nothing behind it shows.
    pub fn is_opaque(&self) -> bool {
        self.opacity >= 1.0
    }
}

/// Where a ray meets a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance from the ray's start, mm.
    pub t_mm: f32,
    /// Unit world normal of the surface (either side).
    pub normal: Vec3,
    /// Colour before shading.
    pub color: Vec3,
    /// Opacity, 0–1.
    pub opacity: f32,
}

#[derive(Debug, Clone)]
enum Shape {
    /// A mesh's hierarchy (it keeps what tracing needs), shared between copies of a scene.
    Mesh(Arc<Bvh>),
    Grid(GridPlane),
    Marker(Marker),
}

#[derive(Debug, Clone)]
struct Object {
    shape: Shape,
    material: Material,
}

/// Geometry to draw in the volume (cheap to clone: meshes are shared).
#[derive(Debug, Clone, Default)]
pub struct Scene {
    objects: Vec<Object>,
    endoscope: Option<Endoscope>,
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether the scene draws nothing.
    pub fn is_empty(&self) -> bool {
        self.endoscope.is_none() && self.objects.iter().all(|o| o.material.opacity <= 0.0)
    }

    /// Adds a mesh (its hierarchy is built here: about a second per million triangles).
    pub fn add_mesh(&mut self, mesh: &TriangleMesh, material: Material) {
        let shape = Shape::Mesh(Arc::new(Bvh::new(mesh)));
        self.objects.push(Object { shape, material });
    }

    /// Adds a grid of lines.
    pub fn add_grid(&mut self, grid: GridPlane, material: Material) {
        let shape = Shape::Grid(grid);
        self.objects.push(Object { shape, material });
    }

    /// Adds a marker sphere.
    pub fn add_marker(&mut self, marker: Marker, material: Material) {
        let shape = Shape::Marker(marker);
        self.objects.push(Object { shape, material });
    }

    /// Shows the instruments of `endoscope` in front of every camera (`None`: no instruments).
    pub fn set_endoscope(&mut self, endoscope: Option<Endoscope>) {
        self.endoscope = endoscope;
    }

    /// The endoscope, if one is shown.
    pub fn endoscope(&self) -> Option<&Endoscope> {
        self.endoscope.as_ref()
    }

    /// The scene as `camera` sees it: the instruments placed in front of it.
    pub fn placed(&self, camera: &Camera) -> PlacedScene<'_> {
        let axes = [camera.forward(), camera.right(), camera.up()];
        let instruments = self
            .endoscope
            .map(|e| e.instruments(camera.eye_mm(), axes))
            .unwrap_or_default();
        PlacedScene {
            scene: self,
            instruments,
        }
    }

    /// The scene without the meshes that enclose `point_mm`, and those meshes' materials. A
    /// mesh encloses the point when rays from it cross the mesh an odd number of times (two of
    /// three rays in fixed directions, so a ray through an edge does not decide): closed
    /// meshes only, whatever the winding of their triangles.
    pub fn without_enclosing(&self, point_mm: DVec3) -> (Scene, Vec<Material>) {
        let mut outside = Scene {
            objects: Vec::new(),
            endoscope: self.endoscope,
        };
        let mut around = Vec::new();
        for object in &self.objects {
            match &object.shape {
                Shape::Mesh(bvh) if encloses(bvh, point_mm) => around.push(object.material),
                _ => outside.objects.push(object.clone()),
            }
        }
        (outside, around)
    }

    /// [`PlacedScene::trace`] for a scene without an endoscope (the instruments need a camera).
    pub fn trace(&self, ray: &Ray, t_min: f64, t_max: f64, hits: &mut Vec<Hit>) {
        let placed = PlacedScene {
            scene: self,
            instruments: Vec::new(),
        };
        placed.trace(ray, t_min, t_max, hits);
    }
}

/// A scene with its camera-bound objects placed for one camera.
#[derive(Debug, Clone)]
pub struct PlacedScene<'a> {
    scene: &'a Scene,
    instruments: Vec<Capsule>,
}

/// A ray and the open interval of distances traced along it, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Traced {
    /// The ray.
    pub ray: Ray,
    /// Surfaces count from above this distance.
    pub t_min: f64,
    /// Surfaces count below this distance.
    pub t_max: f64,
}

impl PlacedScene<'_> {
    /// The surfaces `ray` meets with `t_min < t < t_max` (mm), into `hits` (cleared first) in
    /// depth order: every translucent one in front of the nearest opaque one, then that one
    /// (where there is one: then it is the last hit). Surfaces of opacity 0 are left out.
    pub fn trace(&self, ray: &Ray, t_min: f64, t_max: f64, hits: &mut Vec<Hit>) {
        let traced = Traced {
            ray: *ray,
            t_min,
            t_max,
        };
        self.trace_many(&[traced], std::slice::from_mut(hits));
    }

    /// [`Self::trace`] for many rays, `rays[i]`'s surfaces into `hits[i]`: the same hits, but
    /// neighbouring rays (a block of pixels) walk a mesh's hierarchy together, for less than
    /// their walks one by one.
    ///
    /// # Panics
    ///
    /// When `hits` is shorter than `rays`.
    pub fn trace_many(&self, rays: &[Traced], hits: &mut [Vec<Hit>]) {
        assert!(hits.len() >= rays.len(), "one list of hits per ray");
        for (chunk, hits) in rays.chunks(PACKET).zip(hits.chunks_mut(PACKET)) {
            self.trace_packet(chunk, hits);
        }
    }

    /// [`Self::trace_many`] for at most [`PACKET`] rays.
    fn trace_packet(&self, rays: &[Traced], hits: &mut [Vec<Hit>]) {
        let n = rays.len();
        let (mut bound, mut opaque) = ([0.0; PACKET], [None; PACKET]);
        self.nearest_opaque_packet(rays, &mut bound[..n], &mut opaque[..n]);
        self.translucent_packet(rays, &bound[..n], &opaque[..n], hits);
    }

    /// Whether the scene holds opaque surfaces that may cover much of a view (a mesh or the
    /// instruments; not the grid's thin lines or markers).
    pub fn has_opaque_cover(&self) -> bool {
        let opaque_mesh = |o: &Object| matches!(o.shape, Shape::Mesh(_)) && o.material.is_opaque();
        !self.instruments.is_empty() || self.scene.objects.iter().any(opaque_mesh)
    }

    /// The nearest opaque surface along each of `rays` with `t_min < t < t_max`, into `opaque`
    /// (as long): its distance as the bound it sets (mm) and the hit; `None` where there is none.
    pub fn nearest_opaque_many(&self, rays: &[Traced], opaque: &mut [Option<(f64, Hit)>]) {
        for (chunk, opaque) in rays.chunks(PACKET).zip(opaque.chunks_mut(PACKET)) {
            let n = chunk.len();
            let (mut bound, mut found) = ([0.0; PACKET], [None; PACKET]);
            self.nearest_opaque_packet(chunk, &mut bound[..n], &mut found[..n]);
            for ((slot, found), bound) in opaque.iter_mut().zip(found).zip(bound) {
                *slot = found.map(|hit| (bound, hit));
            }
        }
    }

    /// [`Self::trace_many`] where each ray's nearest opaque surface below its `t_max` is known
    /// already: `opaque[i]` from [`Self::nearest_opaque_many`] over a longer interval (kept
    /// where it lies below the ray's `t_max`). The same hits as tracing anew.
    pub fn trace_many_after(
        &self,
        rays: &[Traced],
        opaque: &[Option<(f64, Hit)>],
        hits: &mut [Vec<Hit>],
    ) {
        let chunks = rays.chunks(PACKET).zip(opaque.chunks(PACKET));
        for ((chunk, opaque), hits) in chunks.zip(hits.chunks_mut(PACKET)) {
            let n = chunk.len();
            let (mut bound, mut found) = ([0.0; PACKET], [None; PACKET]);
            for (i, (traced, ahead)) in chunk.iter().zip(opaque).enumerate() {
                bound[i] = traced.t_max;
                if let Some((b, hit)) = ahead.filter(|(b, _)| *b < traced.t_max) {
                    (bound[i], found[i]) = (b, Some(hit));
                }
            }
            self.translucent_packet(chunk, &bound[..n], &found[..n], hits);
        }
    }

    /// The nearest opaque surface of each of at most [`PACKET`] rays into `opaque`, and the
    /// bound it sets (the ray's `t_max` where there is none) into `bound`.
    fn nearest_opaque_packet(
        &self,
        rays: &[Traced],
        bound: &mut [f64],
        opaque: &mut [Option<Hit>],
    ) {
        for (bound, traced) in bound.iter_mut().zip(rays) {
            *bound = traced.t_max;
        }
        for capsule in &self.instruments {
            // The rays of a packet mostly share their start.
            let mut seen: Option<(DVec3, CapsuleFrom)> = None;
            for (i, traced) in rays.iter().enumerate() {
                let origin = traced.ray.origin;
                if seen.as_ref().is_some_and(|(o, _)| *o != origin) {
                    seen = None;
                }
                let (_, from) = seen.get_or_insert_with(|| (origin, capsule.seen_from(origin)));
                if let Some(t) = from.hit(traced.ray.dir, traced.t_min, bound[i]) {
                    bound[i] = t;
                    let normal = capsule.normal(traced.ray.at(t));
                    opaque[i] = Some(hit(t as f32, normal.as_vec3(), &Material::STEEL));
                }
            }
        }
        let mut packet = [UNUSED_RAY; PACKET];
        for object in self.scene.objects.iter().filter(|o| o.material.is_opaque()) {
            let nearest = Nearest {
                bound: &mut *bound,
                opaque: &mut *opaque,
                packet: &mut packet[..rays.len()],
            };
            nearest.find(object, rays);
        }
    }

    /// Every translucent surface of at most [`PACKET`] rays below its `bound`, then its
    /// nearest opaque one `opaque` (if any): into `hits` (each cleared first), in depth order.
    fn translucent_packet(
        &self,
        rays: &[Traced],
        bound: &[f64],
        opaque: &[Option<Hit>],
        hits: &mut [Vec<Hit>],
    ) {
        let n = rays.len();
        for hits in hits[..n].iter_mut() {
            hits.clear();
        }
        let mut packet = [UNUSED_RAY; PACKET];
        for object in self
            .scene
            .objects
            .iter()
            .filter(|o| !o.material.is_opaque() && o.material.opacity > 0.0)
        {
            every_hit(object, rays, bound, &mut packet[..n], hits);
        }
        for (hits, opaque) in hits.iter_mut().zip(opaque) {
            if hits.len() > 1 {
                hits.sort_by(|a, b| a.t_mm.total_cmp(&b.t_mm));
            }
            hits.extend(*opaque);
        }
    }
}

/// Whether the mesh of `bvh` encloses `point_mm`: an odd number of crossings along two of
/// three rays from it (directions along no axis or diagonal of a voxel grid).
fn encloses(bvh: &Bvh, point_mm: DVec3) -> bool {
    const DIRECTIONS: [Vec3; 3] = [
        Vec3::new(0.31, 0.52, 0.79),
        Vec3::new(-0.67, 0.21, -0.71),
        Vec3::new(0.11, -0.88, 0.46),
    ];
    let origin = point_mm.as_vec3();
    let odd = DIRECTIONS.iter().filter(|&&dir| {
        let mut crossings = 0usize;
        bvh.traverse(origin, dir, 0.0, f32::INFINITY, |_, _| {
            crossings += 1;
            f32::INFINITY
        });
        crossings % 2 == 1
    });
    odd.count() >= 2
}

thread_local! {
    /// Each thread's list of a translucent mesh's hits in a packet: ray, distance, triangle.
    static FOUND: Cell<Vec<(usize, f32, u32)>> = const { Cell::new(Vec::new()) };
}

/// A packet's lane that holds no ray yet.
const UNUSED_RAY: PacketRay = PacketRay {
    origin: Vec3::ZERO,
    dir: Vec3::X,
    t_min: 0.0,
    t_max: 0.0,
};

/// `rays` into `packet` (as long) for a mesh's hierarchy, each up to its `bound`.
fn fill_packet(rays: &[Traced], bound: &[f64], packet: &mut [PacketRay]) {
    for ((p, traced), &t_max) in packet.iter_mut().zip(rays).zip(bound) {
        *p = PacketRay {
            origin: traced.ray.origin.as_vec3(),
            dir: traced.ray.dir.as_vec3(),
            t_min: traced.t_min as f32,
            t_max: t_max as f32,
        };
    }
}

/// A hit at `t_mm` with unit `normal` on a surface of material `m`.
fn hit(t_mm: f32, normal: Vec3, m: &Material) -> Hit {
    Hit {
        t_mm,
        normal,
        color: Vec3::from(m.color),
        opacity: m.opacity,
    }
}

/// The nearest opaque hit so far along each ray of a packet: its distance bound (mm) and the
/// hit; with a packet buffer for a mesh's hierarchy.
struct Nearest<'a> {
    bound: &'a mut [f64],
    opaque: &'a mut [Option<Hit>],
    packet: &'a mut [PacketRay],
}

impl Nearest<'_> {
    /// Lowers each ray's bound to `object`'s nearest hit between the ray's `t_min` and its
    /// bound, where there is one, and makes that hit the ray's opaque one.
    fn find(self, object: &Object, rays: &[Traced]) {
        let material = &object.material;
        if let Shape::Mesh(m) = &object.shape {
            fill_packet(rays, self.bound, self.packet);
            let mut best = [None; PACKET];
            let best = &mut best[..rays.len()];
            m.nearest_each(self.packet, best);
            let found = self.bound.iter_mut().zip(self.opaque.iter_mut()).zip(best);
            for ((bound, opaque), best) in found {
                if let Some((t, tri)) = *best {
                    *bound = f64::from(t);
                    *opaque = Some(hit(t, m.normal(tri), material));
                }
            }
            return;
        }
        for (i, traced) in rays.iter().enumerate() {
            let (ray, t_min) = (&traced.ray, traced.t_min);
            if let Some((t, normal)) = nearest_aid(&object.shape, ray, t_min, self.bound[i]) {
                self.bound[i] = t;
                self.opaque[i] = Some(hit(t as f32, normal.as_vec3(), material));
            }
        }
    }
}

/// The nearest hit of a procedural aid (not a mesh) in `(t_min, t_max)`: distance and unit
/// normal.
fn nearest_aid(shape: &Shape, ray: &Ray, t_min: f64, t_max: f64) -> Option<(f64, DVec3)> {
    let (o, d) = (ray.origin, ray.dir);
    match shape {
        Shape::Mesh(_) => None,
        Shape::Grid(g) => g.hit(o, d, t_min, t_max).map(|t| (t, g.normal())),
        Shape::Marker(s) => {
            let (t0, t1) = s.crossings(o, d)?;
            let t = [t0, t1].into_iter().find(|&t| t > t_min && t < t_max)?;
            Some((t, (ray.at(t) - s.centre_mm) / s.radius_mm))
        }
    }
}

/// Every hit of `object` along each of `rays` (at most [`PACKET`]) between its `t_min` and its
/// `bound`, appended to its list in `hits`: a mesh's in the order of distance, then triangle.
fn every_hit(
    object: &Object,
    rays: &[Traced],
    bound: &[f64],
    packet: &mut [PacketRay],
    hits: &mut [Vec<Hit>],
) {
    let material = &object.material;
    match &object.shape {
        Shape::Mesh(m) => {
            fill_packet(rays, bound, packet);
            // The thread's list from packet to packet (no allocation per packet).
            let mut found = FOUND.take();
            found.clear();
            m.traverse_packet(packet, |ray, t, tri| {
                found.push((ray, t, tri));
                bound[ray] as f32
            });
            // No two entries are equal: a ray meets a triangle once.
            found.sort_unstable_by(|a, b| {
                a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2))
            });
            for &(ray, t, tri) in &found {
                hits[ray].push(hit(t, m.normal(tri), material));
            }
            FOUND.set(found);
        }
        Shape::Grid(_) => {
            for (i, traced) in rays.iter().enumerate() {
                let (ray, t_min) = (&traced.ray, traced.t_min);
                if let Some((t, normal)) = nearest_aid(&object.shape, ray, t_min, bound[i]) {
                    hits[i].push(hit(t as f32, normal.as_vec3(), material));
                }
            }
        }
        Shape::Marker(s) => {
            for (i, traced) in rays.iter().enumerate() {
                let (ray, t_min) = (&traced.ray, traced.t_min);
                if let Some((t0, t1)) = s.crossings(ray.origin, ray.dir) {
                    for t in [t0, t1].into_iter().filter(|&t| t > t_min && t < bound[i]) {
                        let normal = (ray.at(t) - s.centre_mm) / s.radius_mm;
                        hits[i].push(hit(t as f32, normal.as_vec3(), material));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;

    /// Small triangles scattered in a 40 mm cube.
    fn scattered(s: &mut Rng, count: u32) -> TriangleMesh {
        let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
        for k in 0..count {
            let c = s.vec() * 40.0;
            for _ in 0..3 {
                vertices.push(c + (s.vec() - 0.5) * 6.0);
            }
            triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
        }
        TriangleMesh::new(vertices, triangles).unwrap()
    }

    #[test]
    fn tracing_after_the_opaque_surfaces_finds_what_tracing_anew_finds() {
        let mut s = Rng::new(3);
        let mut scene = Scene::new();
        scene.add_mesh(&scattered(&mut s, 300), Material::MESH);
        let glass = Material::new([0.2, 0.6, 1.0], 0.5).unwrap();
        scene.add_mesh(&scattered(&mut s, 300), glass);
        let grid = GridPlane::new(DVec3::splat(20.0), DVec3::new(0.2, 0.1, 1.0), 4.0).unwrap();
        scene.add_grid(grid, Material::GRID);
        scene.add_marker(Marker::new(DVec3::splat(25.0), 5.0).unwrap(), glass);
        let eye = DVec3::new(-20.0, 18.0, 22.0);
        let camera = Camera::look_at(eye, DVec3::splat(20.0), DVec3::Z, 60.0, [8, 8]).unwrap();
        let placed = scene.placed(&camera);
        // Rays from one eye, each with a bound somewhere along the cube or none.
        let rays: Vec<Traced> = (0..200)
            .map(|_| {
                let dir = (DVec3::splat(20.0) + (s.vec() - 0.5) * 40.0 - eye).normalize();
                let t_max = if s.unit() < 0.2 {
                    f64::INFINITY
                } else {
                    20.0 + 60.0 * s.unit()
                };
                Traced {
                    ray: Ray { origin: eye, dir },
                    t_min: 0.5,
                    t_max,
                }
            })
            .collect();
        let unbounded: Vec<Traced> = rays
            .iter()
            .map(|r| Traced {
                t_max: f64::INFINITY,
                ..*r
            })
            .collect();
        let mut opaque = vec![None; rays.len()];
        placed.nearest_opaque_many(&unbounded, &mut opaque);
        let (mut anew, mut after) = (vec![Vec::new(); rays.len()], vec![Vec::new(); rays.len()]);
        placed.trace_many(&rays, &mut anew);
        placed.trace_many_after(&rays, &opaque, &mut after);
        assert_eq!(after, anew);
        let cut = opaque
            .iter()
            .zip(&rays)
            .filter(|(o, r)| o.is_some_and(|(b, _)| b >= r.t_max));
        assert!(
            cut.count() > 10,
            "some opaque surfaces lie beyond the bound"
        );
        assert!(
            anew.iter().filter(|h| h.len() > 1).count() > 10,
            "translucent hits"
        );
    }
}
