//! 3D Slicer Markups JSON (`.mrk.json`): curves and point lists, so that paths move between
//! Slicer and endocast.
//!
//! A file holds `"markups"`, a list of markups each with a `"type"` (`"Curve"`,
//! `"ClosedCurve"`, `"Fiducial"` — a point list, called `"PointList"` in newer documentation —
//! and others we skip: lines, angles, planes, ROIs), a `"coordinateSystem"` (`"LPS"`, the
//! default, or `"RAS"`), optional `"coordinateUnits"` (`"mm"`, the default, or `"um"`) and
//! `"controlPoints"`, each with a `"position"` `[x, y, z]` and an optional `"label"`. Points
//! whose `"positionStatus"` is `"undefined"` have no position yet and are skipped. Everything we
//! return is in LPS millimetres, endocast's world frame: RAS differs by the sign of x and y.
//!
//! We write one `"Curve"` in LPS, which Slicer loads as a curve node.

use crate::error::{ReadError, Result};
use glam::DVec3;
use serde_json::{json, Map, Value};
use std::path::Path;

/// A markups file of a few hundred thousand points is a few tens of MiB; refuse larger unread.
const MAX_BYTES: u64 = 64 << 20;
/// The schema our files declare (Slicer's markups schema, version 1.0.3).
pub const SCHEMA_URL: &str = "https://raw.githubusercontent.com/Slicer/Slicer/main/Modules/Loadable/Markups/Resources/Schema/markups-schema-v1.0.3.json#";

/// The patient coordinate system a file's coordinates are given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoordinateSystem {
    /// x to the patient's left, y posterior, z superior (DICOM, ITK, endocast).
    Lps,
    /// x to the patient's right, y anterior, z superior (Slicer's internal frame).
    Ras,
}

impl CoordinateSystem {
    /// Parses `"LPS"` or `"RAS"` (exactly, as Slicer writes them).
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "LPS" => Some(Self::Lps),
            "RAS" => Some(Self::Ras),
            _ => None,
        }
    }

    /// A point or direction in this system expressed in LPS (the change is its own inverse).
    pub fn to_lps(self, p: DVec3) -> DVec3 {
        match self {
            Self::Lps => p,
            Self::Ras => DVec3::new(-p.x, -p.y, p.z),
        }
    }
}

/// The kinds of markup we read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MarkupKind {
    /// An open curve through its control points.
    Curve,
    /// A closed curve (the last point joins the first).
    ClosedCurve,
    /// Unconnected points (`"Fiducial"` or `"PointList"`).
    PointList,
}

/// One curve or point list from a markups file, in LPS millimetres.
#[derive(Debug, Clone, PartialEq)]
pub struct Markup {
    /// What the points form.
    pub kind: MarkupKind,
    /// The markup's name (empty when the file gives none).
    pub name: String,
    /// Control point positions, LPS mm, in file order.
    pub points_mm: Vec<DVec3>,
    /// Control point labels (empty strings where the file gives none), one per point.
    pub labels: Vec<String>,
}

/// Reads the curves and point lists of a Slicer markups file (at most 64 MiB); an error if it
/// has none.
pub fn read_markups(path: &Path) -> Result<Vec<Markup>> {
    let text = crate::text::read_text(path, MAX_BYTES, "a markups file")?;
    parse_markups(path, &text)
}

/// Parses the text of a markups file; `path` only names it in errors.
pub fn parse_markups(path: &Path, text: &str) -> Result<Vec<Markup>> {
    let root: Value = serde_json::from_str(text)
        .map_err(|e| ReadError::format(path, format!("not valid JSON: {e}")))?;
    let list = match root.get("markups") {
        Some(Value::Array(list)) => list,
        Some(other) => {
            let found = short(other);
            return Err(ReadError::format(
                path,
                format!("\"markups\" must be a list, found {found}"),
            ));
        }
        None => {
            return Err(ReadError::format(
                path,
                "missing key \"markups\" (not a Slicer markups file?)",
            ))
        }
    };
    let mut markups = Vec::new();
    for (i, item) in list.iter().enumerate() {
        let markup = parse_markup(item)
            .map_err(|why| ReadError::format(path, format!("markups[{i}]{why}")))?;
        markups.extend(markup);
    }
    if markups.is_empty() {
        return Err(ReadError::format(
            path,
            "no curve or point list in the file",
        ));
    }
    Ok(markups)
}

/// One markup, `None` for a type we skip; errors start with the field path (".type: ...").
fn parse_markup(item: &Value) -> std::result::Result<Option<Markup>, String> {
    let Value::Object(map) = item else {
        return Err(format!(": expected an object, found {}", short(item)));
    };
    let kind = match optional_str(map, "type")? {
        Some("Curve") => MarkupKind::Curve,
        Some("ClosedCurve") => MarkupKind::ClosedCurve,
        Some("Fiducial" | "PointList") => MarkupKind::PointList,
        Some(_) => return Ok(None),
        None => return Err(".type: missing".into()),
    };
    let system = match optional_str(map, "coordinateSystem")? {
        None => CoordinateSystem::Lps,
        Some(name) => CoordinateSystem::parse(name).ok_or_else(|| {
            format!(".coordinateSystem: expected \"LPS\" or \"RAS\", found \"{name}\"")
        })?,
    };
    let mm_per_unit = units_mm(map.get("coordinateUnits"))?;
    let points = match map.get("controlPoints") {
        None => &Vec::new(),
        Some(Value::Array(points)) => points,
        Some(other) => {
            return Err(format!(
                ".controlPoints: expected a list, found {}",
                short(other)
            ))
        }
    };
    let mut markup = Markup {
        kind,
        name: optional_str(map, "name")?.unwrap_or_default().to_string(),
        points_mm: Vec::with_capacity(points.len()),
        labels: Vec::with_capacity(points.len()),
    };
    for (j, point) in points.iter().enumerate() {
        let parsed = control_point(point).map_err(|why| format!(".controlPoints[{j}]{why}"))?;
        if let Some((position, label)) = parsed {
            markup.points_mm.push(system.to_lps(position * mm_per_unit));
            markup.labels.push(label);
        }
    }
    Ok(Some(markup))
}

/// Millimetres per coordinate unit: `"mm"` (the default) or `"um"`, alone or as the first entry
/// of a coded triple `["mm", "UCUM", "millimeter"]`.
fn units_mm(units: Option<&Value>) -> std::result::Result<f64, String> {
    let code = match units {
        None => return Ok(1.0),
        Some(Value::Array(coded)) => coded.first(),
        Some(other) => Some(other),
    };
    match code.and_then(Value::as_str) {
        Some("mm") => Ok(1.0),
        Some("um") => Ok(1e-3),
        _ => Err(format!(
            ".coordinateUnits: expected \"mm\" or \"um\", found {}",
            short(units.unwrap_or(&Value::Null))
        )),
    }
}

/// Position and label of a control point, `None` when its position is undefined.
fn control_point(point: &Value) -> std::result::Result<Option<(DVec3, String)>, String> {
    let Value::Object(map) = point else {
        return Err(format!(": expected an object, found {}", short(point)));
    };
    if optional_str(map, "positionStatus")? == Some("undefined") {
        return Ok(None);
    }
    let position = map.get("position").ok_or(".position: missing")?;
    let position = vec3(position).map_err(|why| format!(".position: {why}"))?;
    let label = optional_str(map, "label")?.unwrap_or_default().to_string();
    Ok(Some((position, label)))
}

/// Largest coordinate (mm, either sign) a point may have. No patient is a kilometre wide, and
/// numbers near f64's limits overflow the path arithmetic (lengths become infinite or NaN).
pub(crate) const MAX_COORDINATE_MM: f64 = 1e6;

/// `[x, y, z]`, three numbers within [`MAX_COORDINATE_MM`], or what was found instead. The JSON
/// parser has already refused NaN, infinities and numbers beyond an f64.
pub(crate) fn vec3(value: &Value) -> std::result::Result<DVec3, String> {
    let numbers: Option<Vec<f64>> = match value {
        Value::Array(items) if items.len() == 3 => items.iter().map(Value::as_f64).collect(),
        _ => None,
    };
    let numbers =
        numbers.ok_or_else(|| format!("expected [x, y, z] numbers, found {}", short(value)))?;
    within_range(&numbers)?;
    Ok(DVec3::new(numbers[0], numbers[1], numbers[2]))
}

/// Refuses a coordinate beyond ±[`MAX_COORDINATE_MM`].
pub(crate) fn within_range(numbers: &[f64]) -> std::result::Result<(), String> {
    match numbers.iter().find(|x| x.abs() > MAX_COORDINATE_MM) {
        Some(x) => Err(format!(
            "coordinate {x:e} is beyond ±{MAX_COORDINATE_MM:e} mm (a corrupt or mistyped number)"
        )),
        None => Ok(()),
    }
}

/// The string under `key`, `None` when absent, an error when not a string.
fn optional_str<'a>(
    map: &'a Map<String, Value>,
    key: &str,
) -> std::result::Result<Option<&'a str>, String> {
    match map.get(key) {
        None => Ok(None),
        Some(Value::String(s)) => Ok(Some(s)),
        Some(other) => Err(format!(".{key}: expected a string, found {}", short(other))),
    }
}

/// A value as JSON, cut short for error messages.
pub(crate) fn short(value: &Value) -> String {
    let text = value.to_string();
    match text.char_indices().nth(60) {
        Some((end, _)) => format!("{}…", &text[..end]),
        None => text,
    }
}

/// Writes `points_mm` (LPS) as one open Slicer curve called `name`, atomically. Errors for fewer
/// than one point or a non-finite coordinate (JSON cannot hold them).
pub fn write_markups_curve(path: &Path, name: &str, points_mm: &[DVec3]) -> Result<()> {
    if points_mm.is_empty() {
        return Err(ReadError::format(
            path,
            "cannot write a curve without points",
        ));
    }
    if let Some(i) = points_mm.iter().position(|p| !p.is_finite()) {
        return Err(ReadError::format(
            path,
            format!("cannot write point {i} {:?}: not finite", points_mm[i]),
        ));
    }
    let control_points: Vec<Value> = points_mm
        .iter()
        .enumerate()
        .map(|(i, p)| {
            json!({
                "id": (i + 1).to_string(),
                "label": format!("{name}-{}", i + 1),
                "position": p.to_array(),
                "positionStatus": "defined",
            })
        })
        .collect();
    let document = json!({
        "@schema": SCHEMA_URL,
        "markups": [{
            "type": "Curve",
            "coordinateSystem": "LPS",
            "coordinateUnits": "mm",
            "name": name,
            "controlPoints": control_points,
        }],
    });
    crate::atomic::write_file(path, |w| {
        serde_json::to_writer_pretty(&mut *w, &document)?;
        w.write_all(b"\n")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Vec<Markup>> {
        parse_markups(Path::new("a.mrk.json"), text)
    }

    #[test]
    fn reads_slicer_ras_point_lists_and_curves() {
        // Written by hand after Slicer's documented format: a RAS point list, a RAS curve with
        // an unplaced point, and a line, which we skip.
        let text = r#"{
          "@schema": "https://raw.githubusercontent.com/Slicer/Slicer/main/Modules/Loadable/Markups/Resources/Schema/markups-schema-v1.0.3.json#",
          "markups": [
            {"type": "Fiducial", "coordinateSystem": "RAS", "coordinateUnits": "mm", "name": "F",
             "controlPoints": [
               {"id": "1", "label": "F-1", "position": [10.5, -20.0, 30.0], "positionStatus": "defined"},
               {"id": "2", "label": "F-2", "position": [-1.0, 2.0, -3.0]}
             ]},
            {"type": "Line", "controlPoints": [{"position": [0, 0, 0]}, {"position": [1, 1, 1]}]},
            {"type": "Curve", "coordinateSystem": "RAS", "coordinateUnits": ["mm", "UCUM", "millimeter"],
             "name": "C", "display": {"color": [1, 0, 0]},
             "controlPoints": [
               {"position": [1.0, 2.0, 3.0]},
               {"position": [0.0, 0.0, 0.0], "positionStatus": "undefined"},
               {"position": [4.0, 5.0, 6.0], "label": "end"}
             ]},
            {"type": "PointList", "coordinateUnits": "um", "controlPoints": [{"position": [1000, 2000, 3000]}]}
          ]
        }"#;
        let markups = parse(text).unwrap();
        assert_eq!(markups.len(), 3);
        assert_eq!(markups[0].kind, MarkupKind::PointList);
        assert_eq!(markups[0].name, "F");
        assert_eq!(
            markups[0].points_mm,
            vec![DVec3::new(-10.5, 20.0, 30.0), DVec3::new(1.0, -2.0, -3.0)]
        );
        assert_eq!(markups[0].labels, vec!["F-1", "F-2"]);
        assert_eq!(markups[1].kind, MarkupKind::Curve);
        assert_eq!(
            markups[1].points_mm,
            vec![DVec3::new(-1.0, -2.0, 3.0), DVec3::new(-4.0, -5.0, 6.0)]
        );
        assert_eq!(markups[1].labels, vec!["", "end"]);
        // No coordinate system means LPS; micrometres become millimetres.
        assert_eq!(markups[2].points_mm, vec![DVec3::new(1.0, 2.0, 3.0)]);
    }

    #[test]
    fn export_then_import_gives_the_same_points() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("path.mrk.json");
        let points: Vec<DVec3> = (0..50)
            .map(|i| {
                let t = f64::from(i) * 0.37;
                DVec3::new(t.cos() * 12.345_678_9, -t.sin() * 1e-7, t * 3.0 - 100.0)
            })
            .collect();
        write_markups_curve(&file, "centreline", &points).unwrap();
        let read = read_markups(&file).unwrap();
        assert_eq!(read.len(), 1);
        assert_eq!(read[0].kind, MarkupKind::Curve);
        assert_eq!(read[0].name, "centreline");
        assert_eq!(read[0].points_mm, points);
        let text = std::fs::read_to_string(&file).unwrap();
        assert!(text.contains(SCHEMA_URL) && text.contains("\"coordinateSystem\": \"LPS\""));
        assert!(write_markups_curve(&file, "x", &[DVec3::NAN]).is_err());
        assert!(write_markups_curve(&file, "x", &[]).is_err());
        assert_eq!(read_markups(&file).unwrap()[0].points_mm, points);
    }

    #[test]
    fn bad_files_are_errors_naming_the_file() {
        let curve =
            |cp: &str| format!(r#"{{"markups": [{{"type": "Curve", "controlPoints": [{cp}]}}]}}"#);
        for (text, needle) in [
            ("{", "not valid JSON"),
            ("[]", "missing key \"markups\""),
            (r#"{"markups": {}}"#, "must be a list"),
            (r#"{"markups": []}"#, "no curve or point list"),
            (
                r#"{"markups": [{"type": "ROI"}]}"#,
                "no curve or point list",
            ),
            (
                r#"{"markups": [{"controlPoints": []}]}"#,
                "markups[0].type: missing",
            ),
            (
                r#"{"markups": [{"type": 3}]}"#,
                "markups[0].type: expected a string",
            ),
            (
                r#"{"markups": [{"type": "Curve", "coordinateSystem": "XYZ"}]}"#,
                "expected \"LPS\" or \"RAS\", found \"XYZ\"",
            ),
            (
                r#"{"markups": [{"type": "Curve", "coordinateUnits": "inch"}]}"#,
                "coordinateUnits: expected",
            ),
            (
                &curve(r#"{"label": "a"}"#),
                "controlPoints[0].position: missing",
            ),
            (
                &curve(r#"{"position": [1, 2]}"#),
                "controlPoints[0].position: expected [x, y, z]",
            ),
            (
                &curve(r#"{"position": [1, 2, "NaN"]}"#),
                "found [1,2,\"NaN\"]",
            ),
            (&curve(r#"{"position": [1, 2, 1e999]}"#), "not valid JSON"),
            (&curve(r#"{"position": [1, 2, NaN]}"#), "not valid JSON"),
        ] {
            let e = parse(text).unwrap_err().to_string();
            assert!(
                e.starts_with("a.mrk.json: ") && e.contains(needle),
                "{text}: {e}"
            );
        }
        let missing = read_markups(Path::new("/nonexistent/b.mrk.json")).unwrap_err();
        assert!(missing.to_string().starts_with("/nonexistent/b.mrk.json"));
    }
}
