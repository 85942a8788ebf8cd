//! endocast's own path files (JSON): a path through given points and/or the key frames of an
//! animation, in LPS millimetres. The format is described, with an example, in
//! `docs/path-format.md`:
//!
//! ```json
//! {
//!   "format": "endocast-path",
//!   "version": 1,
//!   "coordinate_system": "LPS",
//!   "units": "mm",
//!   "name": "sigmoid",
//!   "points": [[0.0, 0.0, 0.0], [1.5, 0.2, 0.0]],
//!   "target": [2.0, 9.0, -1.0],
//!   "key_frames": [
//!     {"eye": [0, 0, 0], "forward": [1, 0, 0], "up": [0, 0, 1],
//!      "fov_deg": 60, "iso_hu": -500, "iso_opacity": 1.0, "tf": "colonoscopy"}
//!   ]
//! }
//! ```
//!
//! Reading is strict so that a typo never silently changes a flight: unknown keys are errors
//! (except comments, keys starting with `_`), every number is finite, `version` must be one we
//! know. Files are written in LPS, one point or key frame per line. `"target"` (optional, since
//! `endocast path --target`) is the point the route leads to — a nodule beyond the airway's
//! end — which the endoscope views draw; files without it read as before.

use crate::error::{ReadError, Result};
use crate::markups::{short, vec3, within_range, CoordinateSystem};
use endocast_core::animation::KeyFrame;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::io::Write;
use std::path::Path;

/// The `"format"` value of our path files.
pub const FORMAT: &str = "endocast-path";
/// The format version this code reads and writes.
pub const VERSION: u64 = 1;
/// A path file of a million points is about 60 MiB; refuse larger unread.
const MAX_BYTES: u64 = 64 << 20;
/// Keys of the top-level object.
const KEYS: [&str; 8] = [
    "format",
    "version",
    "coordinate_system",
    "units",
    "name",
    "points",
    "key_frames",
    "target",
];

/// The content of a path file: points to pass through, key frames, or both.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PathDocument {
    /// A name for people (the file's `"name"`, empty when absent).
    pub name: String,
    /// Points the path passes through, LPS mm (empty, or at least two).
    pub points_mm: Vec<DVec3>,
    /// Key frames of an animation, in playback order.
    pub key_frames: Vec<KeyFrame>,
    /// The point the route leads to (a bronchoscopy target), LPS mm; `None` when the file
    /// names none.
    pub target_mm: Option<DVec3>,
}

/// One key frame as the file has it: a view direction and an up vector rather than a
/// quaternion, which no one can read or write by hand.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct KeyFrameJson {
    eye: [f64; 3],
    forward: [f64; 3],
    up: [f64; 3],
    fov_deg: f64,
    iso_hu: f64,
    iso_opacity: f64,
    #[serde(default)]
    tf: Option<String>,
}

/// Reads a path file (at most 64 MiB).
pub fn read_path_json(path: &Path) -> Result<PathDocument> {
    let text = crate::text::read_text(path, MAX_BYTES, "a path file")?;
    parse_path_json(path, &text)
}

/// Parses the text of a path file; `path` only names it in errors.
pub fn parse_path_json(path: &Path, text: &str) -> Result<PathDocument> {
    let error = |message: String| ReadError::format(path, message);
    let root: Value =
        serde_json::from_str(text).map_err(|e| error(format!("not valid JSON: {e}")))?;
    let Value::Object(map) = root else {
        return Err(error(format!(
            "expected a JSON object, found {}",
            short(&root)
        )));
    };
    let system = check_header(&map).map_err(error)?;
    if let Some(key) = map
        .keys()
        .find(|k| !k.starts_with('_') && !KEYS.contains(&k.as_str()))
    {
        return Err(error(format!(
            "unknown key \"{key}\" (expected one of {KEYS:?} or a \"_\" comment)"
        )));
    }
    let name = match map.get("name") {
        None => String::new(),
        Some(Value::String(s)) => s.clone(),
        Some(other) => {
            return Err(error(format!(
                "\"name\": expected a string, found {}",
                short(other)
            )))
        }
    };
    let points_mm = points(&map, system).map_err(error)?;
    let key_frames = key_frames(&map, system).map_err(error)?;
    let target_mm = match map.get("target") {
        None => None,
        Some(value) => Some(
            vec3(value)
                .map(|p| system.to_lps(p))
                .map_err(|why| error(format!("target: {why}")))?,
        ),
    };
    if points_mm.is_empty() && key_frames.is_empty() {
        return Err(error(
            "the file has neither \"points\" nor \"key_frames\"".into(),
        ));
    }
    Ok(PathDocument {
        name,
        points_mm,
        key_frames,
        target_mm,
    })
}

/// Checks format, version and units, and returns the coordinate system.
fn check_header(map: &Map<String, Value>) -> std::result::Result<CoordinateSystem, String> {
    let text = |key: &str| match map.get(key) {
        Some(Value::String(s)) => Ok(s.as_str()),
        Some(other) => Err(format!(
            "\"{key}\": expected a string, found {}",
            short(other)
        )),
        None => Err(format!("missing key \"{key}\"")),
    };
    let format = text("format")?;
    if format != FORMAT {
        return Err(format!("\"format\" is \"{format}\", expected \"{FORMAT}\""));
    }
    match map.get("version") {
        Some(v) if v.as_u64() == Some(VERSION) => {}
        Some(v) => {
            return Err(format!(
                "unsupported version {v}: this endocast reads version {VERSION}"
            ))
        }
        None => return Err("missing key \"version\"".into()),
    }
    let units = text("units")?;
    if units != "mm" {
        return Err(format!("\"units\" is \"{units}\", expected \"mm\""));
    }
    let system = text("coordinate_system")?;
    CoordinateSystem::parse(system).ok_or_else(|| {
        format!("\"coordinate_system\" is \"{system}\", expected \"LPS\" or \"RAS\"")
    })
}

/// The `"points"` list in LPS: absent, or at least two `[x, y, z]`.
fn points(
    map: &Map<String, Value>,
    system: CoordinateSystem,
) -> std::result::Result<Vec<DVec3>, String> {
    let list = match map.get("points") {
        None => return Ok(Vec::new()),
        Some(Value::Array(list)) if list.len() >= 2 => list,
        Some(other) => {
            return Err(format!(
                "\"points\": expected a list of at least two [x, y, z], found {}",
                short(other)
            ))
        }
    };
    list.iter()
        .enumerate()
        .map(|(i, p)| {
            vec3(p)
                .map(|p| system.to_lps(p))
                .map_err(|why| format!("points[{i}]: {why}"))
        })
        .collect()
}

/// The `"key_frames"` list, each checked and converted to LPS.
fn key_frames(
    map: &Map<String, Value>,
    system: CoordinateSystem,
) -> std::result::Result<Vec<KeyFrame>, String> {
    let list = match map.get("key_frames") {
        None => return Ok(Vec::new()),
        Some(Value::Array(list)) if !list.is_empty() => list,
        Some(other) => {
            return Err(format!(
                "\"key_frames\": expected a non-empty list of key frames, found {}",
                short(other)
            ))
        }
    };
    list.iter()
        .enumerate()
        .map(|(i, k)| key_frame(k, system).map_err(|why| format!("key_frames[{i}]: {why}")))
        .collect()
}

/// One key frame from its JSON object.
fn key_frame(value: &Value, system: CoordinateSystem) -> std::result::Result<KeyFrame, String> {
    let k = KeyFrameJson::deserialize(value).map_err(|e| e.to_string())?;
    for (name, numbers) in [("eye", k.eye), ("forward", k.forward), ("up", k.up)] {
        within_range(&numbers).map_err(|why| format!("{name}: {why}"))?;
    }
    let lps = |v: [f64; 3]| system.to_lps(DVec3::from(v));
    let mut key = KeyFrame::new(
        lps(k.eye),
        lps(k.forward),
        lps(k.up),
        k.fov_deg,
        k.iso_hu,
        k.iso_opacity,
    )
    .map_err(|e| e.to_string())?;
    key.tf = k.tf;
    Ok(key)
}

/// Writes `document` in LPS, atomically. Errors for a document with neither points nor key
/// frames, a single point, or non-finite numbers (which JSON cannot hold).
pub fn write_path_json(path: &Path, document: &PathDocument) -> Result<()> {
    let error = |message: String| ReadError::format(path, message);
    if document.points_mm.len() == 1
        || (document.points_mm.is_empty() && document.key_frames.is_empty())
    {
        return Err(error(
            "a path file needs two or more points, or key frames".into(),
        ));
    }
    let points: Vec<String> = document
        .points_mm
        .iter()
        .enumerate()
        .map(|(i, p)| finite_json(&format!("point {i}"), &p.to_array(), &p.to_array()))
        .collect::<std::result::Result<_, _>>()
        .map_err(error)?;
    let keys: Vec<String> = document
        .key_frames
        .iter()
        .enumerate()
        .map(|(i, k)| {
            let json = KeyFrameJson {
                eye: k.eye_mm.to_array(),
                forward: k.forward().to_array(),
                up: k.up().to_array(),
                fov_deg: k.fov_deg,
                iso_hu: k.iso_hu,
                iso_opacity: k.iso_opacity,
                tf: k.tf.clone(),
            };
            let mut numbers = [json.eye, json.forward, json.up].concat();
            numbers.extend([json.fov_deg, json.iso_hu, json.iso_opacity]);
            finite_json(&format!("key frame {i}"), &numbers, &json)
        })
        .collect::<std::result::Result<_, _>>()
        .map_err(error)?;
    let target = document
        .target_mm
        .map(|t| finite_json("the target", &t.to_array(), &t.to_array()))
        .transpose()
        .map_err(error)?;
    let name = serde_json::to_string(&document.name).map_err(|e| error(e.to_string()))?;
    crate::atomic::write_file(path, |w| {
        writeln!(
            w,
            "{{\n  \"format\": \"{FORMAT}\",\n  \"version\": {VERSION},"
        )?;
        writeln!(w, "  \"coordinate_system\": \"LPS\",\n  \"units\": \"mm\",")?;
        write!(w, "  \"name\": {name}")?;
        write_list(w, "points", &points)?;
        write_list(w, "key_frames", &keys)?;
        if let Some(target) = &target {
            write!(w, ",\n  \"target\": {target}")?;
        }
        writeln!(w, "\n}}")
    })
}

/// `value` as compact JSON, or an error naming `what` if any of its `numbers` is NaN or
/// infinite (serde_json would quietly write `null`).
fn finite_json(
    what: &str,
    numbers: &[f64],
    value: &impl Serialize,
) -> std::result::Result<String, String> {
    if !numbers.iter().all(|x| x.is_finite()) {
        return Err(format!("cannot write {what} {numbers:?}: not finite"));
    }
    serde_json::to_string(value).map_err(|e| e.to_string())
}

/// `,\n  "key": [\n    item,\n    …\n  ]`, nothing for an empty list.
fn write_list(w: &mut dyn Write, key: &str, items: &[String]) -> std::io::Result<()> {
    if items.is_empty() {
        return Ok(());
    }
    write!(w, ",\n  \"{key}\": [\n    {}\n  ]", items.join(",\n    "))
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str =
        r#""format": "endocast-path", "version": 1, "coordinate_system": "LPS", "units": "mm""#;

    fn parse(text: &str) -> Result<PathDocument> {
        parse_path_json(Path::new("p.json"), text)
    }

    fn key(eye: [f64; 3], forward: DVec3) -> KeyFrame {
        KeyFrame::new(
            DVec3::from(eye),
            forward,
            DVec3::new(0.2, 0.0, 1.0),
            65.0,
            -480.5,
            0.75,
        )
        .unwrap()
    }

    #[test]
    fn write_then_read_gives_the_same_document() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("flight.json");
        let mut keys = vec![
            key([1.0, 2.0, 3.0], DVec3::X),
            key([9.5, -2.25, 3.0], DVec3::new(1.0, 1.0, 0.3)),
        ];
        keys[1].tf = Some("my tf.json".into());
        let document = PathDocument {
            name: "sigmoid \"colon\"".into(),
            points_mm: (0..20)
                .map(|i| DVec3::new(f64::from(i) / 3.0, 1e-9, -1e3))
                .collect(),
            key_frames: keys,
            target_mm: Some(DVec3::new(2.5, -7.0, 31.25)),
        };
        write_path_json(&file, &document).unwrap();
        let read = read_path_json(&file).unwrap();
        assert_eq!(read.name, document.name);
        assert_eq!(read.points_mm, document.points_mm);
        assert_eq!(read.target_mm, document.target_mm);
        for (a, b) in read.key_frames.iter().zip(&document.key_frames) {
            assert_eq!(
                (a.eye_mm, a.fov_deg, a.iso_hu, a.iso_opacity),
                (b.eye_mm, b.fov_deg, b.iso_hu, b.iso_opacity)
            );
            assert!(a.orientation.dot(b.orientation).abs() > 1.0 - 1e-12);
            assert_eq!(a.tf, b.tf);
        }
        // Points only, and key frames only, are documents too.
        let points_only = PathDocument {
            key_frames: vec![],
            target_mm: None,
            ..document.clone()
        };
        write_path_json(&file, &points_only).unwrap();
        assert_eq!(read_path_json(&file).unwrap(), points_only);
        let mut bad = document.clone();
        bad.points_mm[3].y = f64::NAN;
        let e = write_path_json(&file, &bad).unwrap_err().to_string();
        assert!(e.contains("point 3") && e.contains("not finite"), "{e}");
        assert!(write_path_json(&file, &PathDocument::default()).is_err());
        let mut bad = document.clone();
        bad.target_mm = Some(DVec3::new(0.0, f64::INFINITY, 0.0));
        let e = write_path_json(&file, &bad).unwrap_err().to_string();
        assert!(e.contains("the target") && e.contains("not finite"), "{e}");
        // The failed writes left the good file in place.
        assert_eq!(read_path_json(&file).unwrap(), points_only);
    }

    #[test]
    fn ras_files_are_converted_to_lps() {
        let text = r#"{"format": "endocast-path", "version": 1, "coordinate_system": "RAS", "units": "mm",
            "_comment": "made by hand",
            "points": [[1, 2, 3], [4, 5, 6]], "target": [7, 8, 9],
            "key_frames": [{"eye": [1, 2, 3], "forward": [1, 0, 0], "up": [0, 1, 0],
                            "fov_deg": 60, "iso_hu": -500, "iso_opacity": 1}]}"#;
        let d = parse(text).unwrap();
        assert_eq!(
            d.points_mm,
            vec![DVec3::new(-1.0, -2.0, 3.0), DVec3::new(-4.0, -5.0, 6.0)]
        );
        assert_eq!(d.target_mm, Some(DVec3::new(-7.0, -8.0, 9.0)));
        let k = &d.key_frames[0];
        assert_eq!(k.eye_mm, DVec3::new(-1.0, -2.0, 3.0));
        assert!(k.forward().distance(-DVec3::X) < 1e-12 && k.up().distance(-DVec3::Y) < 1e-12);
        assert_eq!(k.tf, None);
    }

    #[test]
    fn bad_files_are_errors_naming_the_file() {
        let key = r#"{"eye": [0, 0, 0], "forward": [1, 0, 0], "up": [0, 0, 1], "fov_deg": 60, "iso_hu": -500, "iso_opacity": 1}"#;
        let with = |rest: &str| format!("{{{HEADER}, {rest}}}");
        for (text, needle) in [
            ("{".to_string(), "not valid JSON".to_string()),
            ("[1]".into(), "expected a JSON object".into()),
            ("{}".into(), "missing key \"format\"".into()),
            (
                r#"{"format": "other"}"#.into(),
                "expected \"endocast-path\"".into(),
            ),
            (
                r#"{"format": "endocast-path", "version": 2}"#.into(),
                "unsupported version 2".into(),
            ),
            (
                r#"{"format": "endocast-path", "version": 1, "units": "mm"}"#.into(),
                "missing key \"coordinate_system\"".into(),
            ),
            (
                HEADER
                    .replace("\"mm\"", "\"cm\"")
                    .replace("\"format\"", "{\"format\"")
                    + "}",
                "\"units\" is \"cm\"".into(),
            ),
            (
                format!("{{{HEADER}}}"),
                "neither \"points\" nor \"key_frames\"".into(),
            ),
            (with(r#""points": []"#), "at least two".into()),
            (with(r#""points": [[0, 0, 0]]"#), "at least two".into()),
            (
                with(r#""points": [[0, 0, 0], [1, 2]]"#),
                "points[1]: expected [x, y, z]".into(),
            ),
            (
                with(r#""points": [[0, 0, 0], [1, 2, "NaN"]]"#),
                "points[1]".into(),
            ),
            (
                with(r#""points": [[0, 0, 0], [1, 2, 1e400]]"#),
                "not valid JSON".into(),
            ),
            (
                with(r#""points": [[0, 0, 0], [1, 2, NaN]]"#),
                "not valid JSON".into(),
            ),
            (with(r#""pionts": []"#), "unknown key \"pionts\"".into()),
            (
                with(r#""points": [[0, 0, 0], [1, 2, 3]], "target": [1, "x", 2]"#),
                "target: expected [x, y, z]".into(),
            ),
            (with(r#""key_frames": []"#), "non-empty list".into()),
            (
                with(&format!(
                    r#""key_frames": [{key}, {}]"#,
                    key.replace(r#""eye": [0, 0, 0], "#, "")
                )),
                "key_frames[1]: missing field `eye`".into(),
            ),
            (
                with(&format!(
                    r#""key_frames": [{}]"#,
                    key.replace("60", "\"NaN\"")
                )),
                "key_frames[0]: invalid type: string \"NaN\"".into(),
            ),
            (
                with(&format!(r#""key_frames": [{}]"#, key.replace("60", "200"))),
                "key_frames[0]: field of view 200".into(),
            ),
            (
                with(&format!(
                    r#""key_frames": [{}]"#,
                    key.replace("[0, 0, 1]", "[1, 0, 0]")
                )),
                "key_frames[0]: forward".into(),
            ),
            (
                with(&format!(
                    r#""key_frames": [{}]"#,
                    key.replace("}", r#", "speed": 3}"#)
                )),
                "unknown field `speed`".into(),
            ),
        ] {
            let e = parse(&text).unwrap_err().to_string();
            assert!(
                e.starts_with("p.json: ") && e.contains(&needle),
                "{text}: {e}"
            );
        }
    }

    #[test]
    fn the_documented_example_reads() {
        let doc = include_str!("../../../docs/path-format.md");
        let start = doc.find("```json\n").unwrap() + 8;
        let end = start + doc[start..].find("```").unwrap();
        let d = parse(&doc[start..end]).unwrap();
        assert_eq!((d.points_mm.len(), d.key_frames.len()), (3, 2));
        assert_eq!(d.key_frames[0].tf.as_deref(), Some("colonoscopy"));
    }
}
