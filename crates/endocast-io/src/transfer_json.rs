//! Transfer functions from JSON files, in the format the VTK peer reads too
//! (`../shared/peers/vtk_render.py --tf`), so one file drives both renderers:
//!
//! ```json
//! {
//!   "_comment": "anything; keys starting with '_' are ignored",
//!   "opacity": [[-1024, 0.0], [-500, 0.12], [3071, 0.9]],
//!   "color":   [[-1024, 0.0, 0.0, 0.0], [300, 1.0, 1.0, 1.0]]
//! }
//! ```
//!
//! Values are in physical units (HU for CT); opacity is per 1 mm of ray; colour components and
//! opacities are in [0, 1]. This module only reads and checks the points; ordering and
//! interpolation belong to the renderer's transfer function.

use crate::error::{ReadError, Result};
use endocast_core::render::TransferFunction;
use serde_json::Value;
use std::path::Path;

/// A transfer-function file is a few hundred bytes; refuse anything absurdly larger unread.
const MAX_BYTES: u64 = 1 << 20;

/// The control points of a transfer function, in the order the file lists them.
#[derive(Debug, Clone, PartialEq)]
pub struct TfPoints {
    /// (value in physical units, opacity per 1 mm in [0, 1]).
    pub opacity: Vec<(f64, f32)>,
    /// (value in physical units, linear RGB in [0, 1]).
    pub color: Vec<(f64, [f32; 3])>,
}

/// Reads a transfer-function JSON file (at most 1 MiB).
pub fn read_transfer_json(path: &Path) -> Result<TfPoints> {
    let text = crate::text::read_text(path, MAX_BYTES, "a transfer function file")?;
    parse_transfer_json(path, &text)
}

/// The transfer function `spec` names: a JSON file (when that path exists or ends in `.json`)
/// or else a preset by name ([`TransferFunction::PRESETS`]); how `--tf` and the Python
/// bindings read it.
pub fn transfer_function(spec: &str) -> Result<TransferFunction> {
    let path = Path::new(spec);
    if path.exists() || spec.ends_with(".json") {
        let points = read_transfer_json(path)?;
        return TransferFunction::from_points(&points.opacity, &points.color)
            .map_err(|e| ReadError::format(path, format!("not a usable transfer function: {e}")));
    }
    TransferFunction::preset(spec).ok_or_else(|| {
        let presets = TransferFunction::PRESETS.join(", ");
        let what = format!("transfer function: neither a file nor a preset ({presets})");
        ReadError::unsupported(path, what)
    })
}

/// Parses the text of a transfer-function file; `path` only names it in errors.
pub fn parse_transfer_json(path: &Path, text: &str) -> Result<TfPoints> {
    let root: Value = serde_json::from_str(text)
        .map_err(|e| ReadError::format(path, format!("not valid JSON: {e}")))?;
    let Value::Object(map) = root else {
        return Err(ReadError::format(
            path,
            "expected a JSON object with \"opacity\" and \"color\"",
        ));
    };
    if let Some(key) = map
        .keys()
        .find(|k| !k.starts_with('_') && *k != "opacity" && *k != "color")
    {
        return Err(ReadError::format(
            path,
            format!("unknown key \"{key}\" (expected \"opacity\", \"color\" or a \"_\" comment)"),
        ));
    }
    let opacity = points(path, &map, "opacity")?
        .into_iter()
        .map(|(v, [a])| (v, a))
        .collect();
    let color = points(path, &map, "color")?;
    Ok(TfPoints { opacity, color })
}

/// The list under `key`: non-empty, each entry `[value, N numbers in [0, 1]]`.
fn points<const N: usize>(
    path: &Path,
    map: &serde_json::Map<String, Value>,
    key: &str,
) -> Result<Vec<(f64, [f32; N])>> {
    let shape = if N == 1 {
        "[value, alpha]"
    } else {
        "[value, r, g, b]"
    };
    let list = match map.get(key) {
        Some(Value::Array(list)) if !list.is_empty() => list,
        Some(_) => {
            return Err(ReadError::format(
                path,
                format!("\"{key}\" must be a non-empty list of {shape} points"),
            ))
        }
        None => return Err(ReadError::format(path, format!("missing key \"{key}\""))),
    };
    list.iter()
        .enumerate()
        .map(|(i, entry)| {
            point(entry).map_err(|why| {
                ReadError::format(
                    path,
                    format!("\"{key}\" point {i}: expected {shape}, {why}"),
                )
            })
        })
        .collect()
}

/// One `[value, c1..cN]` entry: numbers, the components in [0, 1]; or why not. Every number is
/// finite: the JSON parser already refuses `NaN`, `Infinity` (which Python's `json` writes) and
/// literals that overflow an f64.
fn point<const N: usize>(entry: &Value) -> std::result::Result<(f64, [f32; N]), String> {
    let numbers = match entry {
        Value::Array(items) if items.len() == N + 1 => items
            .iter()
            .map(|x| {
                x.as_f64()
                    .ok_or_else(|| format!("found {x} which is not a number"))
            })
            .collect::<std::result::Result<Vec<f64>, String>>()?,
        other => return Err(format!("found {other}")),
    };
    let mut components = [0f32; N];
    for (c, &x) in components.iter_mut().zip(&numbers[1..]) {
        if !(0.0..=1.0).contains(&x) {
            return Err(format!("found {x} outside [0, 1]"));
        }
        *c = x as f32;
    }
    Ok((numbers[0], components))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spec_is_a_file_or_a_preset() {
        assert!(transfer_function("colonoscopy").is_ok());
        let unknown = transfer_function("gastroscopy").unwrap_err().to_string();
        assert!(unknown.contains("neither a file nor a preset"), "{unknown}");
        let missing = transfer_function("no/such/tf.json")
            .unwrap_err()
            .to_string();
        assert!(missing.contains("no/such/tf.json"), "{missing}");
    }

    fn parse(text: &str) -> Result<TfPoints> {
        parse_transfer_json(Path::new("tf.json"), text)
    }

    fn error(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn reads_points_in_file_order_and_ignores_comments() {
        let tf = parse(
            r#"{"_comment": "x", "opacity": [[-1024, 0], [3071.5, 0.9]],
                "color": [[-1024, 0, 0.5, 1], [300, 1, 1, 1]]}"#,
        )
        .unwrap();
        assert_eq!(tf.opacity, vec![(-1024.0, 0.0), (3071.5, 0.9)]);
        assert_eq!(
            tf.color,
            vec![(-1024.0, [0.0, 0.5, 1.0]), (300.0, [1.0, 1.0, 1.0])]
        );
    }

    #[test]
    fn errors_name_the_file_and_the_problem() {
        let color = r#""color": [[0, 1, 1, 1]]"#;
        for (text, needle) in [
            ("[1, 2]", "expected a JSON object"),
            ("{", "not valid JSON"),
            (&format!(r#"{{{color}}}"#), "missing key \"opacity\""),
            (r#"{"opacity": [[0, 1]]}"#, "missing key \"color\""),
            (&format!(r#"{{"opacity": [], {color}}}"#), "non-empty list"),
            (
                &format!(r#"{{"opacity": [[0, 1.5]], {color}}}"#),
                "1.5 outside [0, 1]",
            ),
            (
                &format!(r#"{{"opacity": [[0, "a"]], {color}}}"#),
                "not a number",
            ),
            (
                &format!(r#"{{"opacity": [[0, 1, 2]], {color}}}"#),
                "point 0: expected [value, alpha]",
            ),
            (
                &format!(r#"{{"opacity": [[1e400, 1]], {color}}}"#),
                "out of range",
            ),
            (
                &format!(r#"{{"opacity": [[NaN, 1]], {color}}}"#),
                "not valid JSON",
            ),
            (
                r#"{"opacity": [[0, 1]], "color": [[0, 1, -0.1, 1]]}"#,
                "-0.1 outside",
            ),
            (
                &format!(r#"{{"opacity": [[0, 1]], "colour": [], {color}}}"#),
                "unknown key \"colour\"",
            ),
        ] {
            let e = error(text);
            assert!(
                e.starts_with("tf.json: ") && e.contains(needle),
                "{text}: {e}"
            );
        }
    }
}
