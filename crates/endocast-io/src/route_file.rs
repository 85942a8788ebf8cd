//! Routes from files: what `endocast fly` follows and `endocast bench` times.
//!
//! - A **route** ([`read_route`]) is endocast's path JSON ([`crate::path_file`]: its key frames
//!   when it has them, else its points) or a 3D Slicer Markups file ([`crate::markups`],
//!   `.mrk.json`: the first curve or point list with two or more points). Points are passed
//!   through exactly ([`Route::through_points`]).
//! - A **camera path** ([`read_camera_path`]) is either a route or a plain JSON list of cameras,
//!   `[{"eye": [x, y, z], "look_at": [x, y, z], "up": [x, y, z]}, ...]` in world (LPS) mm — the
//!   list the VTK peer benchmark script reads too.
//!
//! Errors name the file and say what is wrong with it.

use crate::error::{ReadError, Result};
use crate::{markups, path_file};
use endocast_core::flight::Route;
use endocast_core::pose::Pose;
use glam::DVec3;
use serde_json::Value;
use std::path::Path;

/// Camera lists and route files larger than this are refused.
const MAX_BYTES: u64 = 64 << 20;

/// Whether `file` is named as 3D Slicer Markups (`.mrk.json`, any case).
pub fn is_markups(file: &Path) -> bool {
    file.to_str()
        .is_some_and(|s| s.to_ascii_lowercase().ends_with(".mrk.json"))
}

/// The route in `file`: key frames when it has them, else its points (passed through exactly);
/// Markups when the name ends in `.mrk.json` (see [`is_markups`]), else endocast's path JSON.
pub fn read_route(file: &Path) -> Result<Route> {
    let text = crate::text::read_text(file, MAX_BYTES, "a route file")?;
    parse_route(file, &text)
}

/// The target the route in `file` leads to: endocast's path JSON's `"target"` (a bronchoscopy
/// target, see [`path_file`]); none in a file without one or in Markups.
pub fn read_target(file: &Path) -> Result<Option<DVec3>> {
    if is_markups(file) {
        return Ok(None);
    }
    Ok(path_file::read_path_json(file)?.target_mm)
}

/// Parses the text of a route file named `file` (its name decides the format, see
/// [`read_route`]).
pub fn parse_route(file: &Path, text: &str) -> Result<Route> {
    let points = if is_markups(file) {
        let markups = markups::parse_markups(file, text)?;
        let Some(first) = markups.into_iter().find(|m| m.points_mm.len() >= 2) else {
            return Err(ReadError::format(
                file,
                "no curve or point list with two or more points",
            ));
        };
        first.points_mm
    } else {
        let document = path_file::parse_path_json(file, text)?;
        if !document.key_frames.is_empty() {
            return Route::from_key_frames(document.key_frames)
                .map_err(|e| ReadError::format(file, format!("unusable key frames: {e}")));
        }
        document.points_mm
    };
    Route::through_points(&points)
        .map_err(|e| ReadError::format(file, format!("unusable path: {e}")))
}

/// What a camera path file holds.
#[derive(Debug, Clone)]
pub enum CameraPath {
    /// A list of cameras, each used as it is.
    Cameras(Vec<Pose>),
    /// A route, for the caller to take cameras along.
    Route(Route),
}

/// Reads a camera path file: a JSON list of cameras, or a route (see the module doc).
pub fn read_camera_path(file: &Path) -> Result<CameraPath> {
    let text = crate::text::read_text(file, MAX_BYTES, "a camera path")?;
    parse_camera_path(file, &text)
}

/// Parses the text of a camera path file named `file`.
pub fn parse_camera_path(file: &Path, text: &str) -> Result<CameraPath> {
    let value: Value = serde_json::from_str(text)
        .map_err(|e| ReadError::format(file, format!("not JSON: {e}")))?;
    let Some(list) = value.as_array() else {
        return parse_route(file, text).map(CameraPath::Route);
    };
    let vector = |item: &Value, key: &str, n: usize| -> Result<DVec3> {
        let v: Option<Vec<f64>> = item[key]
            .as_array()
            .and_then(|a| a.iter().map(Value::as_f64).collect());
        match v.as_deref() {
            Some(&[x, y, z]) => markups::within_range(&[x, y, z])
                .map(|()| DVec3::new(x, y, z))
                .map_err(|why| ReadError::format(file, format!("camera {n} {key:?}: {why}"))),
            _ => Err(ReadError::format(
                file,
                format!("camera {n} has no {key:?} of three numbers"),
            )),
        }
    };
    let poses = list
        .iter()
        .enumerate()
        .map(|(n, item)| {
            Ok(Pose {
                eye_mm: vector(item, "eye", n)?,
                look_at_mm: vector(item, "look_at", n)?,
                up: vector(item, "up", n)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    if poses.is_empty() {
        return Err(ReadError::format(file, "the path has no cameras"));
    }
    Ok(CameraPath::Cameras(poses))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(name: &str) -> &Path {
        Path::new(name)
    }

    #[test]
    fn a_camera_list_gives_its_cameras_in_order() {
        let text = r#"[
            {"eye": [0, 0, 0], "look_at": [0, 0, 1], "up": [0, 1, 0]},
            {"eye": [1, 2, 3.5], "look_at": [1, 2, 4.5], "up": [0, -1, 0]}
        ]"#;
        let CameraPath::Cameras(poses) = parse_camera_path(file("cams.json"), text).unwrap() else {
            panic!("a list is a list of cameras");
        };
        assert_eq!(poses.len(), 2);
        assert_eq!(poses[1].eye_mm, DVec3::new(1.0, 2.0, 3.5));
        assert_eq!(poses[1].look_at_mm, DVec3::new(1.0, 2.0, 4.5));
        assert_eq!(poses[1].up, DVec3::new(0.0, -1.0, 0.0));
    }

    #[test]
    fn a_path_document_is_a_route() {
        let text = r#"{"format": "endocast-path", "version": 1, "coordinate_system": "LPS",
            "units": "mm", "points": [[0, 0, 0], [0, 0, 10], [0, 5, 20]]}"#;
        let CameraPath::Route(route) = parse_camera_path(file("p.json"), text).unwrap() else {
            panic!("an object is a route");
        };
        assert!(matches!(route, Route::Path(_)));
        assert!(route.len_mm() > 20.0);
        let keys = r#"{"format": "endocast-path", "version": 1, "coordinate_system": "LPS",
            "units": "mm", "key_frames": [
              {"eye": [0, 0, 0], "forward": [0, 0, 1], "up": [0, 1, 0], "fov_deg": 60,
               "iso_hu": -500, "iso_opacity": 1.0},
              {"eye": [0, 0, 9], "forward": [0, 0, 1], "up": [0, 1, 0], "fov_deg": 60,
               "iso_hu": -500, "iso_opacity": 1.0, "tf": "ramp"}]}"#;
        assert!(matches!(
            parse_route(file("k.json"), keys).unwrap(),
            Route::Keys(_)
        ));
    }

    #[test]
    fn markups_give_their_first_curve_with_two_points() {
        let text = r#"{"markups": [
            {"type": "Fiducial", "coordinateSystem": "LPS", "controlPoints": [
                {"position": [9, 9, 9]}]},
            {"type": "Curve", "coordinateSystem": "RAS", "controlPoints": [
                {"position": [1, 0, 0]}, {"position": [1, 0, 10]}]}]}"#;
        let route = parse_route(file("c.mrk.json"), text).unwrap();
        assert!((route.len_mm() - 10.0).abs() < 0.05);
        let Route::Path(path) = route else {
            panic!("markups are points");
        };
        assert!((path.point_at(0.0) - DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-9);
        assert!(is_markups(file("A.MRK.JSON")) && !is_markups(file("a.json")));
    }

    #[test]
    fn errors_name_the_file_and_the_problem() {
        let message = |name: &str, text: &str| {
            let error = parse_camera_path(file(name), text).unwrap_err();
            assert_eq!(error.path(), file(name));
            error.to_string()
        };
        assert!(message("a.json", "[").contains("a.json: not JSON"));
        assert!(message("a.json", "[]").contains("a.json: the path has no cameras"));
        let text = r#"[{"eye": [0, 0, 0], "look_at": [0, 0, 1], "up": [0, 1]}]"#;
        assert!(message("a.json", text).contains("camera 0 has no \"up\" of three numbers"));
        let one = r#"{"markups": [{"type": "Curve", "controlPoints": [{"position": [0, 0, 0]}]}]}"#;
        assert!(message("b.mrk.json", one)
            .contains("b.mrk.json: no curve or point list with two or more points"));
        let same = r#"{"format": "endocast-path", "version": 1, "coordinate_system": "LPS",
            "units": "mm", "points": [[0, 0, 0], [0, 0, 0]]}"#;
        assert!(message("c.json", same).contains("c.json: unusable path"));
        let error = read_route(file("/no/such/route.json")).unwrap_err();
        assert!(matches!(error, ReadError::Io { .. }));
    }
}
