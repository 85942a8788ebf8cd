//! The parts of a case file besides its scan: the viewer's controls and camera, key frames and
//! annotations, each as the JSON holds it.

use endocast_core::annotate::{Annotation, Shape};
use endocast_core::render::{PeelLayer, PeelSettings, TransferFunction, Unpeeled};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

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
    /// The transfer function (version 3; absent: the preset's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tf: Option<CaseTransfer>,
    /// How `peel` mode peels (version 3; absent: the preset's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peel: Option<CasePeel>,
    /// The geometry shown with the scan (version 3; absent: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometry: Option<CaseGeometry>,
    /// The endoscope's look: plain, clinical or realistic (absent: the preset's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub look: Option<String>,
    /// The look's lighting: phong or ibl, as `--lighting` takes it (absent: phong).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lighting: Option<String>,
}

/// A transfer function's points as transfer-function files hold them (see
/// [`crate::transfer_json`]): `[value, opacity per mm]` and `[value, r, g, b]`, values in
/// physical units, the rest 0–1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CaseTransfer {
    pub opacity: Vec<[f64; 2]>,
    pub color: Vec<[f64; 4]>,
}

impl From<&TransferFunction> for CaseTransfer {
    fn from(tf: &TransferFunction) -> Self {
        let opacity = tf.opacity_points().iter();
        let color = tf.color_points().iter();
        Self {
            opacity: opacity.map(|(v, a)| [*v, f64::from(*a)]).collect(),
            color: color
                .map(|(v, [r, g, b])| [*v, f64::from(*r), f64::from(*g), f64::from(*b)])
                .collect(),
        }
    }
}

impl CaseTransfer {
    /// The transfer function, or why these points make none.
    pub fn transfer_function(&self) -> Result<TransferFunction, String> {
        let opacity: Vec<(f64, f32)> = self.opacity.iter().map(|[v, a]| (*v, *a as f32)).collect();
        let color: Vec<(f64, [f32; 3])> = self
            .color
            .iter()
            .map(|[v, r, g, b]| (*v, [*r as f32, *g as f32, *b as f32]))
            .collect();
        TransferFunction::from_points(&opacity, &color)
            .map_err(|e| format!("transfer function: {e}"))
    }
}

/// The peel settings of `peel` mode, as `endocast render --peel …` takes them: `layer` is
/// `"1"`, `"2"`, … or `"last"`; `context`: rays without the peel show the unpeeled volume.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CasePeel {
    pub layer: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold_hu: Option<f64>,
    pub falling: bool,
    pub keep: f32,
    pub context: bool,
}

impl CasePeel {
    /// The record of `peel` (its transfer function behind the peel is not recorded).
    pub fn of(peel: &PeelSettings) -> Self {
        Self {
            layer: match peel.layer {
                PeelLayer::Nth(n) => n.to_string(),
                PeelLayer::Last => "last".into(),
            },
            threshold_hu: peel.threshold_hu,
            falling: peel.falling,
            keep: peel.keep,
            context: peel.unpeeled == Unpeeled::Context,
        }
    }

    /// `peel` with these settings (its transfer function behind the peel kept), or what is
    /// wrong with them.
    pub fn apply(&self, peel: &PeelSettings) -> Result<PeelSettings, String> {
        if !(0.0..=1.0).contains(&self.keep) {
            return Err(format!("peel keep {} is not between 0 and 1", self.keep));
        }
        let mut settings = peel.clone();
        settings.layer = peel_layer(&self.layer)?;
        settings.threshold_hu = self.threshold_hu;
        settings.falling = self.falling;
        settings.keep = self.keep;
        settings.unpeeled = if self.context {
            Unpeeled::Context
        } else {
            Unpeeled::Discard
        };
        Ok(settings)
    }
}

/// A peel layer by name: `N` (1, 2, 3 …) or `last`.
pub fn peel_layer(text: &str) -> Result<PeelLayer, String> {
    endocast_core::study::named::peel_layer(text).map_err(|e| e.problem)
}

/// Which geometry the viewer shows with the scan, and the mesh files it read (read again when
/// the case is reopened).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CaseGeometry {
    pub grid: bool,
    pub endoscope: bool,
    pub markers: bool,
    pub meshes: bool,
    /// The meshes' files, absolute where they could be made so, in the order read (absent:
    /// none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mesh_files: Vec<PathBuf>,
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
