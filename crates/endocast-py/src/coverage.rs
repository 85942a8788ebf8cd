//! `endocast.coverage`: the review of what a flight missed, as `endocast coverage --json`
//! reports it.

use crate::errors::{error, to_py};
use crate::fly::read;
use crate::kwargs::Kwargs;
use crate::look::{optics, LookOptions};
use crate::volume::Volume;
use endocast_core::flight::{
    review, FlightError, FlightOptions, Layout, PatchView, Review, ReviewRequest, Route,
    DEFAULT_MIN_AREA_MM2, REVIEW_FRAME_PX, REVIEW_STEP_MM,
};
use endocast_core::path::SmoothOptions;
use endocast_core::study::LOOK_AHEAD_MM;
use endocast_core::views::Image;
use endocast_io::review_json;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// Flies `path` — an (N, 3) array of points (LPS mm) or a path file, as `fly` takes it; without
/// it, the automatic path through the structure the `preset` finds, as `path` plans it —
/// forward, and back unless `forward_only`, and reviews the wall it missed: the unseen wall split
/// into patches of at least `min_area` mm² (default 10), each with a camera that sees it, whose
/// view is rendered (written as `views/patch_NNN.png` with `views`) and added to the coverage.
///
/// Returns the dict `endocast coverage --json` prints: `patches` (largest first, each with
/// `area_mm2`, `centroid`, `eye`, `look_at`, `up`, `fov_deg`, `clear`, `voxels`,
/// `voxels_seen_by_view`, `view`), `patches_total`, `patches_at_least_300_mm2`,
/// `min_area_mm2`, `both_ways`, `wall_voxels`, `reach_mm`, `coverage_forward`,
/// `coverage_before` and `coverage_after` (fractions, 0–1).
///
/// Options: `size` (width, height; default 256 × 256), `frame_step` (mm, default 1),
/// `look_ahead` (mm), `min_area`, `forward_only`, `views`, and `render`'s look, lens and lumen
/// options (`preset`, `iso`, `look`, `fov`, `lens`, `lumen_threshold`, …).
#[pyfunction]
#[pyo3(signature = (volume, path = None, **options))]
pub fn coverage<'py>(
    py: Python<'py>,
    volume: &Bound<'py, Volume>,
    path: Option<&Bound<'py, PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let kw = Kwargs::new(py, "coverage", options)?;
    let volume = volume.get();
    let look_options = LookOptions::take(&kw)?;
    let fov = kw.take::<f64>("fov")?;
    let size = kw.take::<[usize; 2]>("size")?.unwrap_or(REVIEW_FRAME_PX);
    let step_mm = positive(
        "frame_step",
        kw.take::<f64>("frame_step")?.unwrap_or(REVIEW_STEP_MM),
    )?;
    let look_ahead_mm = kw.take::<f64>("look_ahead")?.unwrap_or(LOOK_AHEAD_MM);
    let min_area_mm2 = kw.take::<f64>("min_area")?.unwrap_or(DEFAULT_MIN_AREA_MM2);
    if !(min_area_mm2.is_finite() && min_area_mm2 >= 0.0) {
        return Err(error(format!(
            "min_area must be a number of mm² ≥ 0, not {min_area_mm2}"
        )));
    }
    let forward_only = kw.take::<bool>("forward_only")?.unwrap_or(false);
    let views = kw.take::<PathBuf>("views")?;
    let given = path.map(|p| read(py, p)).transpose()?;
    let first = match &given {
        Some(route) => Some(route.shots(step_mm, look_ahead_mm).map_err(to_py)?),
        None => None,
    }
    .and_then(|shots| shots.first().map(|s| s.pose));
    let look = look_options.resolve(py, volume.volume(), first, fov)?;
    let optics = optics(
        &kw,
        look.study.preset(),
        look.look.as_ref(),
        volume.volume(),
        fov,
    )?;
    kw.finish()?;
    let scan = volume.volume();
    let route = match given {
        Some(route) => route,
        None => {
            // `endocast path`'s smoothing without `--smoothing`: the defaults.
            let options = SmoothOptions::default();
            let planned = py.detach(|| look.study.plan(scan, None, None, &options));
            Route::Path(planned.map_err(to_py)?.planned.path)
        }
    };
    let start = route.points_mm(1.0).map_err(to_py)?[0];
    let (lumen, _) = look.study.lumen_from(scan, start).map_err(to_py)?;
    let request = ReviewRequest {
        settings: look.settings.clone(),
        look: look.look.clone(),
        flight: FlightOptions {
            size,
            optics,
            stereo: None,
            layout: Layout::Endoscope,
            window: look.study.window(),
        },
        step_mm,
        look_ahead_mm,
        both_ways: !forward_only,
        min_area_mm2,
    };
    if let Some(dir) = &views {
        std::fs::create_dir_all(dir).map_err(to_py)?;
    }
    let review = py.detach(|| {
        look.in_pool(|| {
            let write = |n: usize, _: &PatchView, image: &Image| match &views {
                Some(dir) => save(&review_json::view_file(dir, n), image),
                None => Ok(()),
            };
            review::<ViewError>(volume.renderer(), &lumen, &route, &request, || {}, write)
        })
    });
    let review = review.map_err(|e| error(e.0))?;
    to_dict(py, &review, &request, views.as_deref())
}

/// A flight or a view file that failed, in words.
struct ViewError(String);

impl From<FlightError> for ViewError {
    fn from(e: FlightError) -> Self {
        Self(e.to_string())
    }
}

/// `value` when it is a positive finite number, else an error naming the option.
fn positive(name: &str, value: f64) -> PyResult<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(error(format!(
            "{name} must be a positive number of mm, not {value}"
        )))
    }
}

fn save(path: &Path, image: &Image) -> Result<(), ViewError> {
    let (w, h) = (image.width() as u32, image.height() as u32);
    endocast_io::image_out::write_png_rgb8(path, w, h, image.rgb())
        .map_err(|e| ViewError(format!("cannot write {}: {e}", path.display())))
}

/// The review as the dict `endocast coverage --json` prints (each patch's `view` a path).
fn to_dict<'py>(
    py: Python<'py>,
    review: &Review,
    request: &ReviewRequest,
    views: Option<&Path>,
) -> PyResult<Bound<'py, PyAny>> {
    let json = review_json::to_json(review, request.min_area_mm2, request.both_ways, None);
    let dict = py
        .import("json")?
        .call_method1("loads", (json.to_string(),))?;
    if let Some(dir) = views {
        for (n, patch) in dict.get_item("patches")?.try_iter()?.enumerate() {
            patch?.set_item("view", review_json::view_file(dir, n))?;
        }
    }
    Ok(dict)
}
