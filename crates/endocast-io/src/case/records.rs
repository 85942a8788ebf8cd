//! The parts of a case file besides its scan: the viewer's controls and camera, key frames and
//! annotations, each as the JSON holds it.

use endocast_core::annotate::{Annotation, Shape};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// The viewer's controls by name, so the file reads as the CLI's options do.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CaseControls {
    pub preset: String,
    pub mode: String,
    pub iso_hu: f64,
    pub iso_opacity: f32,
    pub lens: String,
    pub fov_deg: f64,
    pub stereo: bool,
    pub collision: bool,
    pub speed_mm_s: f64,
    pub window_level_hu: f64,
    pub window_width_hu: f64,
}

/// A camera: eye (world mm, LPS), view direction and image up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CaseCamera {
    pub eye: [f64; 3],
    pub forward: [f64; 3],
    pub up: [f64; 3],
}

/// A key frame as path files have it (see `docs/path-format.md`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CaseKeyFrame {
    pub eye: [f64; 3],
    pub forward: [f64; 3],
    pub up: [f64; 3],
    pub fov_deg: f64,
    pub iso_hu: f64,
    pub iso_opacity: f64,
}

/// An annotation: `{"id": 2, "kind": "measure", "label": "", "points": [[..], [..]],
/// "color": [0, 220, 255], "distance_mm": 12.3}` (the distance is written for people and
/// scripts, and recomputed on reading). Version 1 files held labelled points as
/// `{"label": .., "point": [..]}`, still read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnnotationRecord {
    /// Its number in the case (0: give it one).
    #[serde(default)]
    pub id: u32,
    /// `point`, `stroke` or `measure`.
    #[serde(default = "point_kind")]
    pub kind: String,
    /// Text drawn beside it.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub label: String,
    /// Its surface points, world mm (LPS).
    #[serde(default)]
    pub points: Vec<[f64; 3]>,
    /// Version 1: the one point of a labelled point.
    #[serde(default, skip_serializing)]
    pub point: Option<[f64; 3]>,
    /// RGB, 0–255 (default: the kind's colour).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<[u8; 3]>,
    /// A measurement's length, mm (written, not read).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distance_mm: Option<f64>,
}

fn point_kind() -> String {
    "point".into()
}

impl From<&Annotation> for AnnotationRecord {
    fn from(a: &Annotation) -> Self {
        Self {
            id: a.id,
            kind: a.shape.kind().into(),
            label: a.label.clone(),
            points: a.shape.points().iter().map(|p| p.to_array()).collect(),
            point: None,
            color: Some(a.color),
            distance_mm: a.distance_mm(),
        }
    }
}

impl AnnotationRecord {
    /// The annotation it records, or what is wrong with it.
    pub fn annotation(&self) -> Result<Annotation, String> {
        let points: Vec<DVec3> = self
            .points
            .iter()
            .chain(&self.point)
            .map(|p| DVec3::from_array(*p))
            .collect();
        let shape = Shape::from_points(&self.kind, &points)
            .map_err(|e| format!("annotation {}: {e}", self.id))?;
        let mut annotation = Annotation::new(shape).labelled(&self.label);
        annotation.id = self.id;
        if let Some(color) = self.color {
            annotation.color = color;
        }
        Ok(annotation)
    }
}
