//! Planar reformats of a [`Volume`] in the patient frame: the axial, coronal and sagittal slices
//! through the camera, and the cross-section perpendicular to the path (§5.4 of Scharsach et
//! al.: the orthographic views that tell where in the patient the endoscope is).
//!
//! The planes are fixed in the LPS patient frame, not in the voxel grid, so an oblique or sheared
//! scan still gives true axial, coronal and sagittal images: every pixel centre is a world point
//! (mm) taken to a continuous voxel index by [`Geometry::voxel_from_world`](crate::Geometry) and
//! sampled trilinearly. Pixels are square, `mm_per_px` on both axes. Display conventions (those
//! of radiology workstations):
//!
//! - **axial**: seen from the feet; the patient's left on the image right, anterior at the top;
//! - **coronal**: seen from the front; the patient's left on the image right, superior at the top;
//! - **sagittal**: seen from the patient's left; anterior on the image left, superior at the top.
//!
//! Border letters (A/P, L/R, S/I) name the patient direction each image edge points to, computed
//! from the plane's axes (so an oblique cross-section gets the nearest letters too).

use super::{patient_letter, Image, Rgb, ViewError, CAMERA_COLOR};
use crate::render::Camera;
use crate::Volume;
use glam::DVec3;
use rayon::prelude::*;

/// Colour of pixels outside the volume (darker than air, and bluish, to tell them apart).
const OUTSIDE_COLOR: Rgb = [16, 16, 40];
/// Colour of the border letters.
const LABEL_COLOR: Rgb = [255, 150, 40];
/// Largest field of view accepted, mm (ten metres: anything larger is a unit mistake).
const MAX_FIELD_MM: f64 = 10_000.0;

/// The three standard planes of the patient frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plane {
    /// Transverse: perpendicular to the head–feet axis.
    Axial,
    /// Frontal: perpendicular to the front–back axis.
    Coronal,
    /// Lateral: perpendicular to the left–right axis.
    Sagittal,
}

impl Plane {
    /// All three, in the order the dashboard stacks them.
    pub const ALL: [Plane; 3] = [Plane::Axial, Plane::Coronal, Plane::Sagittal];

    /// The lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Plane::Axial => "axial",
            Plane::Coronal => "coronal",
            Plane::Sagittal => "sagittal",
        }
    }

    /// The unit world (LPS) directions of increasing column and increasing row (see the module
    /// doc for the conventions).
    pub fn axes(self) -> (DVec3, DVec3) {
        match self {
            Plane::Axial => (DVec3::X, DVec3::Y),
            Plane::Coronal => (DVec3::X, -DVec3::Z),
            Plane::Sagittal => (DVec3::Y, -DVec3::Z),
        }
    }
}

/// A display window in physical units (HU for CT): values from `level − width/2` (black) to
/// `level + width/2` (white).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Centre of the window, physical units.
    pub level_hu: f64,
    /// Width of the window, physical units (positive).
    pub width_hu: f64,
}

impl Window {
    /// Air black, soft tissue light grey, contrast and bone white: for the air-filled lumens.
    pub const AIR_TISSUE: Window = Window {
        level_hu: -300.0,
        width_hu: 1400.0,
    };
    /// The usual soft-tissue window (level 40, width 400).
    pub const SOFT_TISSUE: Window = Window {
        level_hu: 40.0,
        width_hu: 400.0,
    };

    /// A window; the level must be finite and the width finite and positive.
    pub fn new(level_hu: f64, width_hu: f64) -> Result<Self, ViewError> {
        let window = Self { level_hu, width_hu };
        window.validate()?;
        Ok(window)
    }

    fn validate(&self) -> Result<(), ViewError> {
        if !self.level_hu.is_finite() {
            return Err(out_of_range("window level", self.level_hu, "finite"));
        }
        if !(self.width_hu.is_finite() && self.width_hu > 0.0) {
            return Err(out_of_range(
                "window width",
                self.width_hu,
                "finite and positive",
            ));
        }
        Ok(())
    }

    /// The grey level of a physical value (clamped; NaN is black).
    pub fn grey(&self, value: f64) -> u8 {
        let t = (value - self.level_hu) / self.width_hu + 0.5;
        if t.is_nan() {
            0
        } else {
            (t.clamp(0.0, 1.0) * 255.0).round() as u8
        }
    }
}

fn out_of_range(name: &'static str, value: f64, range: &'static str) -> ViewError {
    ViewError::OutOfRange { name, value, range }
}

/// How to draw a slice.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct SliceOptions {
    /// Edge of the square image, pixels. Default 256.
    pub size_px: usize,
    /// Edge of the square field of view, mm, centred on the slice's point; `None` (the default)
    /// frames the whole volume as it projects onto the plane.
    pub field_mm: Option<f64>,
    /// Display window. Default [`Window::AIR_TISSUE`].
    pub window: Window,
    /// Draw the orientation letters on the borders. Enabled by default.
    pub labels: bool,
}

impl Default for SliceOptions {
    fn default() -> Self {
        Self {
            size_px: 256,
            field_mm: None,
            window: Window::AIR_TISSUE,
            labels: true,
        }
    }
}

/// A plane through a world point with two orthonormal in-plane axes (world, LPS).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlicePlane {
    point_mm: DVec3,
    right: DVec3,
    down: DVec3,
}

impl SlicePlane {
    /// The standard `plane` through `point_mm`.
    pub fn standard(plane: Plane, point_mm: DVec3) -> Result<Self, ViewError> {
        check_finite("slice point", point_mm)?;
        let (right, down) = plane.axes();
        Ok(Self {
            point_mm,
            right,
            down,
        })
    }

    /// The plane through `point_mm` perpendicular to `tangent`, seen looking along `tangent`
    /// with `up` (its part perpendicular to the tangent) towards the top of the image, as the
    /// endoscope sees it: the image right is `tangent × up`, as for [`Camera`].
    pub fn cross_section(point_mm: DVec3, tangent: DVec3, up: DVec3) -> Result<Self, ViewError> {
        check_finite("slice point", point_mm)?;
        check_finite("tangent", tangent)?;
        check_finite("up vector", up)?;
        let forward = tangent
            .try_normalize()
            .ok_or(ViewError::Degenerate("tangent", tangent.to_array()))?;
        let right = forward
            .cross(up)
            .try_normalize()
            .filter(|r| r.cross(forward).dot(up.normalize_or_zero()) > 1e-6)
            .ok_or(ViewError::Degenerate("up vector", up.to_array()))?;
        Ok(Self {
            point_mm,
            right,
            down: forward.cross(right),
        })
    }

    /// The point the plane passes through, world mm.
    pub fn point_mm(&self) -> DVec3 {
        self.point_mm
    }

    /// Unit world direction of increasing column.
    pub fn right(&self) -> DVec3 {
        self.right
    }

    /// Unit world direction of increasing row.
    pub fn down(&self) -> DVec3 {
        self.down
    }

    /// The patient directions of the image's left, right, top and bottom edges.
    pub fn border_labels(&self) -> [char; 4] {
        [-self.right, self.right, -self.down, self.down].map(patient_letter)
    }
}

fn check_finite(what: &'static str, v: DVec3) -> Result<(), ViewError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ViewError::NotFinite(what, v.to_array()))
    }
}

/// A reformatted slice: the windowed image, the sampled values and the map between its pixels
/// and the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Slice {
    image: Image,
    values: Vec<f32>,
    plane: SlicePlane,
    top_left_mm: DVec3,
    mm_per_px: f64,
}

impl Slice {
    /// The windowed image with its labels and markers.
    pub fn image(&self) -> &Image {
        &self.image
    }

    /// The image, to draw on.
    pub(crate) fn image_mut(&mut self) -> &mut Image {
        &mut self.image
    }

    /// Gives the image back.
    pub fn into_image(self) -> Image {
        self.image
    }

    /// The sampled physical value at each pixel centre (row 0 at the top), NaN outside the volume.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The plane.
    pub fn plane(&self) -> &SlicePlane {
        &self.plane
    }

    /// Size of a (square) pixel, mm.
    pub fn mm_per_px(&self) -> f64 {
        self.mm_per_px
    }

    /// The world point (mm) at continuous image position `(x, y)`; pixel centres are at
    /// half-integers.
    pub fn world_at(&self, x: f64, y: f64) -> DVec3 {
        self.top_left_mm + (self.plane.right * x + self.plane.down * y) * self.mm_per_px
    }

    /// The image position of the orthogonal projection of `p_mm` onto the plane.
    pub fn pixel_of(&self, p_mm: DVec3) -> (f64, f64) {
        let d = p_mm - self.top_left_mm;
        (
            d.dot(self.plane.right) / self.mm_per_px,
            d.dot(self.plane.down) / self.mm_per_px,
        )
    }

    /// Draws the camera: a dot at the eye's projection and an arrow along the view direction's
    /// projection, as long as a tenth of the image when the view lies in the plane and shorter
    /// as it turns out of it.
    pub fn draw_camera(&mut self, eye_mm: DVec3, forward: DVec3) {
        let size = self.image.width().max(self.image.height()) as f64;
        let at = self.pixel_of(eye_mm);
        let reach = 0.1 * size;
        let (dx, dy) = (forward.dot(self.plane.right), forward.dot(self.plane.down));
        let tip = (at.0 + dx * reach, at.1 + dy * reach);
        self.image
            .arrow(at, tip, (0.04 * size).max(3.0), CAMERA_COLOR);
        self.image.disc(at, (size / 100.0).max(2.0), CAMERA_COLOR);
    }

    /// Writes the border letters.
    fn draw_labels(&mut self) {
        let (w, h) = (self.image.width() as i64, self.image.height() as i64);
        let scale = (w.min(h) / 128).max(1);
        let (gw, gh) = (5 * scale, 7 * scale);
        let [left, right, top, bottom] = self.plane.border_labels();
        let spots = [
            (left, 2, (h - gh) / 2),
            (right, w - 2 - gw, (h - gh) / 2),
            (top, (w - gw) / 2, 2),
            (bottom, (w - gw) / 2, h - 2 - gh),
        ];
        for (letter, x, y) in spots {
            self.image.text_shadowed(
                x,
                y,
                letter.encode_utf8(&mut [0; 4]),
                scale as usize,
                LABEL_COLOR,
            );
        }
    }
}

/// Reformats `volume` on `plane` (trilinear samples at the pixel centres, rows in parallel).
pub fn reformat(
    volume: &Volume,
    plane: &SlicePlane,
    options: &SliceOptions,
) -> Result<Slice, ViewError> {
    options.window.validate()?;
    let size = options.size_px;
    let (centre_mm, edge_mm) = field(volume, plane, options.field_mm)?;
    let mm_per_px = edge_mm / size as f64;
    let mut slice = Slice {
        image: Image::new(size, size, OUTSIDE_COLOR)?,
        values: Vec::new(),
        plane: *plane,
        top_left_mm: centre_mm - (plane.right + plane.down) * (edge_mm / 2.0),
        mm_per_px,
    };
    slice.values = sample_pixels(volume, &slice);
    for (n, v) in slice.values.iter().enumerate() {
        if !v.is_nan() {
            let g = options.window.grey(f64::from(*v));
            slice
                .image
                .put((n % size) as i64, (n / size) as i64, [g; 3]);
        }
    }
    if options.labels {
        slice.draw_labels();
    }
    Ok(slice)
}

/// The physical value at every pixel centre of `slice` (NaN outside the volume), rows in
/// parallel.
fn sample_pixels(volume: &Volume, slice: &Slice) -> Vec<f32> {
    let width = slice.image.width();
    let voxel_from_world = volume.geometry().voxel_from_world();
    let mut values = vec![f32::NAN; width * slice.image.height()];
    values
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, value) in row.iter_mut().enumerate() {
                let p_mm = slice.world_at(x as f64 + 0.5, y as f64 + 0.5);
                let voxel = voxel_from_world.transform_point3(p_mm);
                *value = volume.sample_physical(voxel).map_or(f32::NAN, |v| v as f32);
            }
        });
    values
}

/// The centre (mm) and edge (mm) of the square field of view that frames `volume` on `plane`
/// (its grid corners as they project onto the plane, 2 % margin): what [`reformat`] shows
/// when [`SliceOptions::field_mm`] is `None`. A viewer zooms and pans from it.
pub fn framing(volume: &Volume, plane: &SlicePlane) -> (DVec3, f64) {
    let geometry = volume.geometry();
    let last = geometry.dims().map(|n| (n - 1) as f64);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for corner in 0..8 {
        let pick = |axis: usize| {
            if corner >> axis & 1 == 1 {
                last[axis]
            } else {
                0.0
            }
        };
        let d = geometry.world_of(DVec3::new(pick(0), pick(1), pick(2))) - plane.point_mm;
        for (axis, along) in [d.dot(plane.right), d.dot(plane.down)]
            .into_iter()
            .enumerate()
        {
            lo[axis] = lo[axis].min(along);
            hi[axis] = hi[axis].max(along);
        }
    }
    let edge = ((hi[0] - lo[0]).max(hi[1] - lo[1]) * 1.02).max(1.0);
    let mid = |axis: usize| (lo[axis] + hi[axis]) / 2.0;
    (
        plane.point_mm + plane.right * mid(0) + plane.down * mid(1),
        edge,
    )
}

/// The centre (mm) and edge (mm) of the square field of view: around the plane's point with the
/// given edge, or the volume's [`framing`].
fn field(
    volume: &Volume,
    plane: &SlicePlane,
    field_mm: Option<f64>,
) -> Result<(DVec3, f64), ViewError> {
    match field_mm {
        Some(edge) if !(edge.is_finite() && edge > 0.0 && edge <= MAX_FIELD_MM) => {
            Err(out_of_range("field of view (mm)", edge, "in (0, 10000]"))
        }
        Some(edge) => Ok((plane.point_mm, edge)),
        None => Ok(framing(volume, plane)),
    }
}

/// The axial, coronal and sagittal slices through the camera's eye, with the camera drawn;
/// where the eye lies outside the scan, a slice that would miss it passes through the scan's
/// middle instead.
pub fn camera_slices(
    volume: &Volume,
    camera: &Camera,
    options: &SliceOptions,
) -> Result<[Slice; 3], ViewError> {
    let centre = inside_or_middle(volume, camera.eye_mm());
    let one = |plane: Plane| {
        let plane = SlicePlane::standard(plane, centre)?;
        let mut slice = reformat(volume, &plane, options)?;
        slice.draw_camera(camera.eye_mm(), camera.forward());
        Ok(slice)
    };
    Ok([
        one(Plane::Axial)?,
        one(Plane::Coronal)?,
        one(Plane::Sagittal)?,
    ])
}

/// `point_mm`, with each voxel coordinate that lies outside the scan's grid moved to the grid's
/// middle (a slice through the scan's middle rather than one past its edge or along its rim).
fn inside_or_middle(volume: &Volume, point_mm: DVec3) -> DVec3 {
    let g = volume.geometry();
    let voxel = g.voxel_from_world().transform_point3(point_mm);
    let last = DVec3::from_array(g.dims().map(|d| d.saturating_sub(1) as f64));
    let moved = DVec3::select(
        voxel.cmpge(DVec3::ZERO) & voxel.cmple(last),
        voxel,
        0.5 * last,
    );
    if moved == voxel || !voxel.is_finite() {
        point_mm
    } else {
        g.world_of(moved)
    }
}

/// The cross-section through the camera's eye perpendicular to `tangent` (the path's direction
/// there), oriented by the camera's up vector, with the camera drawn.
pub fn camera_cross_section(
    volume: &Volume,
    camera: &Camera,
    tangent: DVec3,
    options: &SliceOptions,
) -> Result<Slice, ViewError> {
    let plane = SlicePlane::cross_section(camera.eye_mm(), tangent, camera.up())?;
    let mut slice = reformat(volume, &plane, options)?;
    slice.draw_camera(camera.eye_mm(), camera.forward());
    Ok(slice)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};
    use crate::{Geometry, Modality, ValueMap};
    use glam::{DMat3, DQuat};

    fn options(size_px: usize, field_mm: Option<f64>, labels: bool) -> SliceOptions {
        SliceOptions {
            size_px,
            field_mm,
            labels,
            ..SliceOptions::default()
        }
    }

    #[test]
    fn pixels_sample_the_volume_at_their_world_points() {
        let (volume, colon) = phantom::colon(&PhantomOptions {
            size: 64,
            ..Default::default()
        });
        let g = volume.geometry();
        let p = g.world_of(colon.centreline.point_at(40.0));
        let to_vox = g.voxel_from_world();
        // A 40 mm field in 80 px: 0.5 mm pixels, the top-left corner 20 mm up-left of `p`.
        for plane in Plane::ALL {
            let sp = SlicePlane::standard(plane, p).unwrap();
            let slice = reformat(&volume, &sp, &options(80, Some(40.0), false)).unwrap();
            let (right, down) = plane.axes();
            let mut air = 0;
            for (x, y) in [(0, 0), (40, 40), (17, 63), (79, 5), (55, 21), (39, 40)] {
                let world = p
                    + right * (-20.0 + 0.5 * (x as f64 + 0.5))
                    + down * (-20.0 + 0.5 * (y as f64 + 0.5));
                let expected = volume.sample_physical(to_vox.transform_point3(world));
                let found = slice.values()[x + 80 * y];
                assert_eq!(found, expected.map_or(f32::NAN, |v| v as f32), "{plane:?}");
                let grey = Window::AIR_TISSUE.grey(f64::from(found));
                assert_eq!(slice.image().pixel(x, y), Some([grey; 3]));
                air += usize::from(found < -900.0);
            }
            // The middle pixels straddle the centreline: air.
            assert!(air >= 2, "{plane:?}");
        }
    }

    /// A 40³ volume of 1.5 mm voxels with direction `direction`, centred on the world origin,
    /// holding a bright ball of radius 5 mm at `ball_mm` in air.
    fn ball_volume(direction: DMat3, ball_mm: DVec3) -> Volume {
        let n = 40;
        let spacing = DVec3::splat(1.5);
        let half = direction * (spacing * (n as f64 - 1.0) / 2.0);
        let g = Geometry::new([n; 3], spacing, -half, direction).unwrap();
        let mut voxels = vec![0u16; n * n * n];
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let w = g.world_of(DVec3::new(i as f64, j as f64, k as f64));
                    let hu: f64 = if w.distance(ball_mm) < 5.0 {
                        1000.0
                    } else {
                        -1000.0
                    };
                    voxels[i + n * (j + n * k)] = (hu + 1024.0) as u16;
                }
            }
        }
        Volume::new(
            g,
            voxels,
            ValueMap::new(1.0, -1024.0).unwrap(),
            Modality::Ct,
        )
        .unwrap()
    }

    #[test]
    fn patient_directions_land_on_their_labels_whatever_the_grid() {
        // The ball lies to the patient's left, anterior and superior of the origin.
        let ball = DVec3::new(12.0, -12.0, 12.0);
        let oblique = DMat3::from_quat(DQuat::from_rotation_z(0.5) * DQuat::from_rotation_x(-0.3));
        let directions = [
            Geometry::direction_from_code("LPS").unwrap(),
            Geometry::direction_from_code("RAI").unwrap(),
            Geometry::direction_from_code("SLA").unwrap(),
            oblique,
        ];
        // Expected side of the image centre for the ball, per plane: (x > centre, y > centre).
        let expected = [
            (Plane::Axial, ['R', 'L', 'A', 'P'], (true, false)), // left → right, anterior → top
            (Plane::Coronal, ['R', 'L', 'S', 'I'], (true, false)), // superior → top
            (Plane::Sagittal, ['A', 'P', 'S', 'I'], (false, false)), // anterior → left
        ];
        for direction in directions {
            let volume = ball_volume(direction, ball);
            for (plane, labels, (right_half, bottom_half)) in expected {
                let sp = SlicePlane::standard(plane, ball).unwrap();
                assert_eq!(sp.border_labels(), labels);
                let slice = reformat(&volume, &sp, &options(64, Some(80.0), true)).unwrap();
                let bright: Vec<usize> = (0..64 * 64)
                    .filter(|&n| slice.values()[n] > 500.0)
                    .collect();
                assert!(!bright.is_empty(), "{plane:?} {direction:?}");
                let mean = |f: fn(usize) -> usize| {
                    bright.iter().map(|&n| f(n) as f64).sum::<f64>() / bright.len() as f64
                };
                // The slice passes through the ball, 12 mm (9.6 px) from the origin per axis.
                let (cx, cy) = slice.pixel_of(DVec3::ZERO);
                assert_eq!(mean(|n| n % 64) > cx, right_half, "{plane:?}");
                assert_eq!(mean(|n| n / 64) > cy, bottom_half, "{plane:?}");
                let (bx, by) = slice.pixel_of(ball);
                assert!((mean(|n| n % 64) - bx).abs() < 1.0 && (mean(|n| n / 64) - by).abs() < 1.0);
            }
        }
    }

    #[test]
    fn labels_are_drawn_on_their_borders() {
        let volume = ball_volume(DMat3::IDENTITY, DVec3::ZERO);
        let sp = SlicePlane::standard(Plane::Axial, DVec3::ZERO).unwrap();
        let with = reformat(&volume, &sp, &options(64, None, true)).unwrap();
        let without = reformat(&volume, &sp, &options(64, None, false)).unwrap();
        let changed = |x0: usize, x1: usize, y0: usize, y1: usize| {
            (y0..y1)
                .any(|y| (x0..x1).any(|x| with.image().pixel(x, y) != without.image().pixel(x, y)))
        };
        // "R" at the middle of the left edge, "A" at the middle of the top, nothing in a corner.
        assert!(changed(0, 8, 28, 36) && changed(56, 64, 28, 36));
        assert!(changed(28, 36, 0, 10) && changed(28, 36, 54, 64));
        assert!(!changed(0, 10, 0, 10));
        assert_eq!(with.image().pixel(2, 28), Some(LABEL_COLOR)); // top-left of the R
    }

    #[test]
    fn the_camera_marker_sits_at_the_eye() {
        let (volume, tube) = phantom::straight_tube(&PhantomOptions {
            size: 64,
            ..Default::default()
        });
        let g = volume.geometry();
        let eye = g.world_of(tube.centreline.points()[0] + DVec3::new(3.0, -2.0, 20.0));
        let forward = DVec3::new(0.5, 0.2, 1.0).normalize();
        let camera = Camera::look_at(eye, eye + forward, DVec3::Y, 90.0, [8, 8]).unwrap();
        let slices = camera_slices(&volume, &camera, &options(128, None, true)).unwrap();
        for slice in &slices {
            let (x, y) = slice.pixel_of(eye);
            assert_eq!(
                slice.image().pixel(x as usize, y as usize),
                Some(CAMERA_COLOR)
            );
            // The eye's pixel centre is within half a pixel of the eye, in the plane.
            let back = slice.world_at(x.floor() + 0.5, y.floor() + 0.5);
            let normal = slice.plane().right().cross(slice.plane().down());
            let in_plane = (back - eye) - normal * (back - eye).dot(normal);
            assert!(in_plane.length() <= slice.mm_per_px() * 0.71);
            // Halfway along the arrow.
            let p = slice.pixel_of(eye + forward * 0.05 * 128.0 * slice.mm_per_px());
            assert_eq!(
                slice.image().pixel(p.0 as usize, p.1 as usize),
                Some(CAMERA_COLOR)
            );
        }
    }

    /// From outside the scan (an overview of the whole object), each slice still cuts the
    /// scan: the tube's wall shows in all three.
    #[test]
    fn slices_from_outside_the_scan_cut_it_through_its_middle() {
        let (volume, _) = phantom::straight_tube(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        let g = volume.geometry();
        let eye = g.world_of(DVec3::new(16.0, -40.0, -25.0));
        let camera =
            Camera::look_at(eye, g.world_of(DVec3::splat(16.0)), DVec3::Z, 60.0, [8, 8]).unwrap();
        let slices = camera_slices(&volume, &camera, &options(64, None, false)).unwrap();
        for slice in &slices {
            let image = slice.image();
            let levels: std::collections::BTreeSet<_> = (0..image.height())
                .flat_map(|y| (0..image.width()).filter_map(move |x| image.pixel(x, y)))
                .collect();
            assert!(levels.len() > 4, "{:?} is blank", slice.plane());
        }
    }

    #[test]
    fn the_cross_section_cuts_the_tube_across() {
        let (volume, tube) = phantom::straight_tube(&PhantomOptions {
            size: 64,
            ..Default::default()
        });
        let g = volume.geometry();
        let eye = g.world_of(tube.centreline.points()[0] + DVec3::new(0.0, 0.0, 30.0));
        let camera = Camera::look_at(eye, eye + DVec3::Z, -DVec3::Y, 90.0, [8, 8]).unwrap();
        let slice =
            camera_cross_section(&volume, &camera, DVec3::Z, &options(64, Some(64.0), true))
                .unwrap();
        // Looking up the tube (+z, superior) with anterior up: the patient's left on the right.
        assert_eq!(slice.plane().border_labels(), ['R', 'L', 'A', 'P']);
        for (n, v) in slice.values().iter().enumerate() {
            let p = slice.world_at((n % 64) as f64 + 0.5, (n / 64) as f64 + 0.5);
            let r = (p - eye).length();
            if r < tube.radius_vox - 1.5 {
                assert!(*v < -990.0, "air expected at {r} mm: {v}");
            } else if r > tube.radius_vox + 1.5 && v.is_finite() {
                assert!(*v > 30.0, "tissue expected at {r} mm: {v}");
            }
        }
    }

    #[test]
    fn rejects_bad_input() {
        let volume = ball_volume(DMat3::IDENTITY, DVec3::ZERO);
        let p = DVec3::ZERO;
        assert!(SlicePlane::standard(Plane::Axial, DVec3::NAN).is_err());
        assert!(SlicePlane::cross_section(p, DVec3::ZERO, DVec3::Y).is_err());
        assert!(SlicePlane::cross_section(p, DVec3::Z, DVec3::Z * 2.0).is_err());
        assert!(SlicePlane::cross_section(p, DVec3::Z, DVec3::INFINITY).is_err());
        let sp = SlicePlane::standard(Plane::Axial, p).unwrap();
        for bad in [
            options(0, None, true),
            options(64, Some(0.0), true),
            options(64, Some(f64::NAN), true),
            SliceOptions {
                window: Window {
                    level_hu: 0.0,
                    width_hu: 0.0,
                },
                ..SliceOptions::default()
            },
        ] {
            assert!(reformat(&volume, &sp, &bad).is_err(), "{bad:?}");
        }
        assert!(Window::new(f64::NAN, 10.0).is_err());
        // A plane far outside the volume is no error: every pixel is outside.
        let far = SlicePlane::standard(Plane::Axial, DVec3::splat(1e4)).unwrap();
        let slice = reformat(&volume, &far, &options(8, Some(10.0), false)).unwrap();
        assert!(slice.values().iter().all(|v| v.is_nan()));
    }
}
