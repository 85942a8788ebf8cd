//! nerfstudio's `transforms.json`: the camera model and intrinsics of the first frame at the
//! top (a frame whose intrinsics differ carries its own), per frame the camera-to-world matrix
//! (OpenGL convention, mm) and its files, and a note on units and layers.

use super::FrameRecord;
use endocast_core::dataset::{CameraModel, Intrinsics};
use serde_json::{json, Map, Value};

/// What the dataset's layers and units are, for a reader of the JSON.
const NOTE: &str = "endocast training data (docs/dataset-format.md). World: patient LPS, \
    millimetres; transform_matrix is camera to world with the camera in the OpenGL convention \
    (x right, y up, looking along -z). Depth PNGs are 16-bit: millimetres = code * \
    depth_scale_mm, code 0 = no wall; depth/ is along each pixel's ray, depth_z/ along the view \
    axis (depth_file_path, 0 also where the wall is not in front of the eye). normals/ are unit \
    normals in the OpenCV camera frame (x right, y down, z forward) facing the camera, stored \
    as (n + 1) / 2 * 255. masks/ are 255 where the pixel sees the wall, else 0. Pixel centres \
    at half-integers (COLMAP's and nerfstudio's convention).";

/// The JSON text of `frames`, depths in codes of `depth_scale_mm`.
pub(super) fn to_json(frames: &[FrameRecord], depth_scale_mm: f64) -> String {
    let mut top = Map::new();
    let first = frames.first().map(|f| f.intrinsics);
    if let Some(intrinsics) = &first {
        top.extend(intrinsics_json(intrinsics));
    }
    top.insert("units".into(), json!("mm"));
    top.insert("depth_scale_mm".into(), json!(depth_scale_mm));
    top.insert("note".into(), json!(NOTE));
    let frames: Vec<Value> = frames
        .iter()
        .map(|frame| {
            let file = |folder: &str| format!("{folder}/{}.png", frame.stem);
            let mut entry = Map::new();
            entry.insert("file_path".into(), json!(file("images")));
            entry.insert(
                "transform_matrix".into(),
                json!(frame.pose.camera_to_world_opengl()),
            );
            entry.insert("depth_file_path".into(), json!(file("depth_z")));
            entry.insert("depth_ray_file_path".into(), json!(file("depth")));
            entry.insert("normal_file_path".into(), json!(file("normals")));
            entry.insert("mask_path".into(), json!(file("masks")));
            if first != Some(frame.intrinsics) {
                entry.extend(intrinsics_json(&frame.intrinsics));
            }
            Value::Object(entry)
        })
        .collect();
    top.insert("frames".into(), Value::Array(frames));
    let mut text = serde_json::to_string_pretty(&Value::Object(top)).unwrap_or_default();
    text.push('\n');
    text
}

/// nerfstudio's intrinsics keys for `intrinsics`.
fn intrinsics_json(intrinsics: &Intrinsics) -> Map<String, Value> {
    let i = intrinsics;
    let names = match i.model {
        CameraModel::OpenCv => ["k1", "k2", "p1", "p2"],
        CameraModel::OpenCvFisheye => ["k1", "k2", "k3", "k4"],
    };
    let mut map = Map::new();
    map.insert("camera_model".into(), json!(i.model.name()));
    for (key, value) in [("fl_x", i.fx), ("fl_y", i.fy), ("cx", i.cx), ("cy", i.cy)] {
        map.insert(key.into(), json!(value));
    }
    map.insert("w".into(), json!(i.width));
    map.insert("h".into(), json!(i.height));
    for (key, value) in names.into_iter().zip(i.distortion) {
        map.insert(key.into(), json!(value));
    }
    map
}
