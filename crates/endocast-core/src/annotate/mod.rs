//! Drawing and measuring on tissue (Sinus Endoscopy §4.4, "Drawing Facilities"): points with
//! text labels, strokes (polylines of surface points) and distances between two surface points,
//! all held as world positions (mm, LPS) on the surface the user saw.
//!
//! - [`SurfaceView`] is a rendered view's camera and depth layer: [`SurfaceView::pick`] turns an
//!   image position into the surface point seen there (pixel → ray → depth, any lens), and
//!   [`SurfaceView::visibility`] says whether a world point is on the surface this view shows
//!   (the paper's shadow-map-like depth comparison: a point is hidden when something nearer
//!   covers it, and also when the tissue it was drawn on is gone — a threshold change moved the
//!   surface away, so the view's ray runs past the point);
//! - [`draw`] puts the annotations into a view's image as decals where they are visible, labels
//!   in the built-in bitmap font;
//! - [`draw_target`] rings a bronchoscopy route's target, solid where the view sees it and
//!   dashed where it lies behind the wall the view shows, with its distance from the eye;
//! - [`ScanIdentity`] fingerprints a scan (dimensions, spacing, origin, voxels) so that a case's
//!   annotations are never drawn on another scan.
//!
//! ```
//! use endocast_core::annotate::{Annotation, Annotations, Shape};
//! use glam::DVec3;
//!
//! let mut marks = Annotations::default();
//! let id = marks.add(Annotation::new(Shape::Distance(DVec3::ZERO, DVec3::new(3.0, 4.0, 0.0))))?;
//! assert_eq!(marks.get(id).unwrap().distance_mm(), Some(5.0));
//! assert_eq!(marks.get(id).unwrap().caption(), "5.0 mm");
//! # Ok::<(), endocast_core::annotate::IdsExhausted>(())
//! ```

mod draw;
mod identity;
mod pick;
mod target;

#[cfg(test)]
mod tests;

pub use draw::{draw, DrawOptions};
pub use identity::{IdentityMismatch, ScanIdentity};
pub use pick::{SurfaceView, Visibility};
pub use target::{draw_target, TargetSight, HIDDEN_TARGET_COLOR, TARGET_COLOR, TARGET_RADIUS_MM};

use crate::views::Rgb;
use glam::DVec3;
use std::collections::HashSet;

/// Default colour of points and labels.
pub const POINT_COLOR: Rgb = [255, 220, 0];
/// Default colour of strokes.
pub const STROKE_COLOR: Rgb = [60, 255, 120];
/// Default colour of measurements.
pub const MEASURE_COLOR: Rgb = [0, 220, 255];

/// What an annotation marks, world mm (LPS).
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// One surface point (with a text label when the annotation has one).
    Point(DVec3),
    /// A line drawn on the tissue: surface points in drawing order.
    Stroke(Vec<DVec3>),
    /// The straight distance between two surface points.
    Distance(DVec3, DVec3),
}

impl Shape {
    /// The kind's name as case files and the CLI write it: `point`, `stroke` or `measure`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Point(_) => "point",
            Self::Stroke(_) => "stroke",
            Self::Distance(..) => "measure",
        }
    }

    /// Its points, in order.
    pub fn points(&self) -> Vec<DVec3> {
        match self {
            Self::Point(p) => vec![*p],
            Self::Stroke(points) => points.clone(),
            Self::Distance(a, b) => vec![*a, *b],
        }
    }

    /// The shape of kind `kind` through `points`, or why there is none (a point needs one, a
    /// measurement two, a stroke at least one; every coordinate finite).
    pub fn from_points(kind: &str, points: &[DVec3]) -> Result<Self, String> {
        if let Some(p) = points.iter().find(|p| !p.is_finite()) {
            return Err(format!("point {:?} is not finite", p.to_array()));
        }
        match (kind, points) {
            ("point", [p]) => Ok(Self::Point(*p)),
            ("measure", [a, b]) => Ok(Self::Distance(*a, *b)),
            ("stroke", [_, ..]) => Ok(Self::Stroke(points.to_vec())),
            ("point" | "measure" | "stroke", _) => Err(format!(
                "a {kind} needs {} point(s), found {}",
                match kind {
                    "point" => "1",
                    "measure" => "2",
                    _ => "1 or more",
                },
                points.len()
            )),
            _ => Err(format!(
                "unknown annotation kind {kind:?} (point, stroke or measure)"
            )),
        }
    }
}

/// One annotation: a shape, an optional text label and a colour.
#[derive(Debug, Clone, PartialEq)]
pub struct Annotation {
    /// Its number in its set (given by [`Annotations::add`]; stable when others are removed).
    pub id: u32,
    /// What it marks.
    pub shape: Shape,
    /// Text drawn beside it (may be empty).
    pub label: String,
    /// Its colour.
    pub color: Rgb,
}

impl Annotation {
    /// An unlabelled annotation of `shape` in its kind's default colour (id 0 until added).
    pub fn new(shape: Shape) -> Self {
        let color = match shape {
            Shape::Point(_) => POINT_COLOR,
            Shape::Stroke(_) => STROKE_COLOR,
            Shape::Distance(..) => MEASURE_COLOR,
        };
        Self {
            id: 0,
            shape,
            label: String::new(),
            color,
        }
    }

    /// The same annotation labelled `label`.
    pub fn labelled(self, label: &str) -> Self {
        Self {
            label: label.to_owned(),
            ..self
        }
    }

    /// A measurement's length, mm.
    pub fn distance_mm(&self) -> Option<f64> {
        match self.shape {
            Shape::Distance(a, b) => Some(a.distance(b)),
            _ => None,
        }
    }

    /// The text drawn beside it: the label, and for a measurement its length (`"12.3 mm"`).
    pub fn caption(&self) -> String {
        match (self.distance_mm(), self.label.is_empty()) {
            (Some(mm), true) => format!("{mm:.1} mm"),
            (Some(mm), false) => format!("{} {mm:.1} mm", self.label),
            (None, _) => self.label.clone(),
        }
    }

    /// Where its caption is anchored: a point's position, a stroke's first point, a
    /// measurement's midpoint.
    pub fn anchor(&self) -> DVec3 {
        match &self.shape {
            Shape::Point(p) => *p,
            Shape::Stroke(points) => points.first().copied().unwrap_or(DVec3::NAN),
            Shape::Distance(a, b) => (*a + *b) / 2.0,
        }
    }
}

/// A new annotation would need an id past `u32::MAX`: ids are one more than the largest, and
/// the largest is already the most an id may be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error(
    "no annotation id is left: a new id is one more than the largest, and the largest is \
     already {max} (renumber the case's annotations)",
    max = u32::MAX
)]
pub struct IdsExhausted;

/// The annotations of a case, oldest first, each with a unique id.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Annotations {
    items: Vec<Annotation>,
}

impl Annotations {
    /// A set holding `items` as they are (ids kept; a case file's). Duplicate ids are renumbered
    /// after the largest (an error when that would pass `u32::MAX`). Linear in the count (the ids seen so far are hashed, not searched),
    /// so that a case of hundreds of thousands of annotations opens at once.
    pub fn from_items(items: Vec<Annotation>) -> Result<Self, IdsExhausted> {
        let mut taken = HashSet::with_capacity(items.len());
        let mut largest = 0u32;
        let items = items
            .into_iter()
            .map(|item| {
                let id = if item.id == 0 || taken.contains(&item.id) {
                    largest.checked_add(1).ok_or(IdsExhausted)?
                } else {
                    item.id
                };
                taken.insert(id);
                largest = largest.max(id);
                Ok(Annotation { id, ..item })
            })
            .collect::<Result<_, _>>()?;
        Ok(Self { items })
    }

    /// Adds `annotation` with a new id (one more than the largest) and returns the id; nothing
    /// is added when the largest id is already `u32::MAX`.
    pub fn add(&mut self, annotation: Annotation) -> Result<u32, IdsExhausted> {
        let largest = self.items.iter().map(|a| a.id).max().unwrap_or(0);
        let id = largest.checked_add(1).ok_or(IdsExhausted)?;
        self.items.push(Annotation { id, ..annotation });
        Ok(id)
    }

    /// Removes annotation `id`; returns it, or `None` when there is none.
    pub fn remove(&mut self, id: u32) -> Option<Annotation> {
        let at = self.items.iter().position(|a| a.id == id)?;
        Some(self.items.remove(at))
    }

    /// Annotation `id`.
    pub fn get(&self, id: u32) -> Option<&Annotation> {
        self.items.iter().find(|a| a.id == id)
    }

    /// Every annotation, oldest first.
    pub fn items(&self) -> &[Annotation] {
        &self.items
    }

    /// How many there are.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }
}
