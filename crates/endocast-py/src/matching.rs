//! `endocast.match`: supine/prone correspondence, as `endocast match --json` reports it.

use crate::errors::{error, to_py};
use crate::volume::Volume;
use endocast_core::correspond::{side_by_side, Correspondence};
use endocast_core::presets::Preset;
use endocast_core::study::{Study, StudyRequest};
use glam::DVec3;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// The counterpart in `second` (e.g. the prone scan) of the point `at` (LPS mm) of `first` (the
/// supine scan): each scan's `preset` path (default colonoscopy) planned as `path` plans it,
/// the paths matched, the point carried over.
///
/// Returns the dict `endocast match --json` prints: `point`, `arc_mm`, `eye`, `look_at`, `up`
/// (the second scan), `first` (`arc_mm`, `distance_mm`, `eye`, `look_at`, `up`, `path_mm`),
/// `path_mm`, `turn_deg`, `reversed`, `match_cost`. With `output`, also writes the two views
/// side by side (PNG, each `size` = (width, height) pixels, default 384 × 384, field `fov`
/// degrees, default the preset's).
#[pyfunction]
#[pyo3(name = "match", signature = (first, second, at, preset = "colonoscopy", output = None, size = (384, 384), fov = None))]
#[allow(clippy::too_many_arguments)]
#[allow(clippy::needless_pass_by_value)] // PyO3 hands arguments over by value.
pub fn match_scans<'py>(
    py: Python<'py>,
    first: &Bound<'py, Volume>,
    second: &Bound<'py, Volume>,
    at: [f64; 3],
    preset: &str,
    output: Option<PathBuf>,
    size: (usize, usize),
    fov: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let procedure =
        Preset::find(preset).ok_or_else(|| error(format!("unknown preset {preset:?}")))?;
    let request = StudyRequest::preset(procedure);
    let (first, second) = (first.get(), second.get());
    let (found, matched) = py
        .detach(|| {
            let study_a = Study::resolve(first.volume(), &request);
            let study_b = Study::resolve(second.volume(), &request);
            let matched = Correspondence::of_studies(
                (first.volume(), &study_a),
                (second.volume(), &study_b),
            )?;
            let found = matched.counterpart(DVec3::from(at))?;
            if let Some(path) = &output {
                let scans = [
                    (first.renderer(), study_a.settings()),
                    (second.renderer(), study_b.settings()),
                ];
                let fov = fov.unwrap_or(procedure.fov_deg);
                let image = side_by_side(scans, &found, fov, [size.0, size.1])
                    .map_err(|e| MatchFailure(error(format!("cannot render the views: {e}"))))?;
                let (w, h) = (image.width() as u32, image.height() as u32);
                endocast_io::image_out::write_png_rgb8(path, w, h, image.rgb()).map_err(|e| {
                    MatchFailure(error(format!("cannot write {}: {e}", path.display())))
                })?;
            }
            Ok::<_, MatchFailure>((found, matched))
        })
        .map_err(|e| e.0)?;
    let v = |p: DVec3| [p.x, p.y, p.z];
    let (length_first, length_second) = matched.lengths_mm();
    let first_view = PyDict::new(py);
    first_view.set_item("arc_mm", found.arc_first_mm)?;
    first_view.set_item("distance_mm", found.distance_mm)?;
    first_view.set_item("eye", v(found.view_first.eye_mm))?;
    first_view.set_item("look_at", v(found.view_first.look_at_mm))?;
    first_view.set_item("up", v(found.view_first.up))?;
    first_view.set_item("path_mm", length_first)?;
    let out = PyDict::new(py);
    out.set_item("point", v(found.point_mm))?;
    out.set_item("arc_mm", found.arc_mm)?;
    out.set_item("eye", v(found.view.eye_mm))?;
    out.set_item("look_at", v(found.view.look_at_mm))?;
    out.set_item("up", v(found.view.up))?;
    out.set_item("first", first_view)?;
    out.set_item("path_mm", length_second)?;
    out.set_item("turn_deg", matched.turn_deg())?;
    out.set_item("reversed", matched.reversed())?;
    out.set_item("match_cost", matched.cost())?;
    Ok(out)
}

/// Why the match failed, as the exception to raise.
struct MatchFailure(PyErr);

impl<E: std::error::Error> From<E> for MatchFailure {
    fn from(e: E) -> Self {
        Self(to_py(e))
    }
}
