//! `endocast.dissect`: the lumen cut open along its path and laid flat, as `endocast dissect`
//! writes it, with its map from each pixel back to the 3D wall.

use crate::errors::{error, to_py};
use crate::fly::read;
use crate::kwargs::Kwargs;
use crate::look::LookOptions;
use crate::volume::Volume;
use endocast_core::dissect::{
    dissect as lay_flat, DissectOptions, Wall, DEFAULT_REACH_MM, DEFAULT_ROWS, DEFAULT_STEP_MM,
};
use endocast_core::flight::Route;
use endocast_core::path::SmoothOptions;
use numpy::ndarray::Array3;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The wall of the lumen along `path` (an (N, 3) array of points, LPS mm, or a path file;
/// without it, the automatic path through the structure the `preset` finds, as `path` plans
/// it) cut open and laid flat: length along the path across, the circumference down.
///
/// Returns a dict: `image` (height × width × 3 uint8, the picture `endocast dissect` writes,
/// with its mm axis), `map` (height × width × 3 float32, the LPS mm wall point of each pixel,
/// NaN where none: `endocast dissect`'s `.map.npy`), and the figures of `endocast dissect
/// --json`: `width`, `height`, `plot` (`x`, `y`, `columns`, `rows`: where the wall pixels lie
/// in the image), `path_length_mm`, `along_mm_per_px`, `around_deg_per_px`, `around_mm_per_px`
/// and `wall_fraction`.
///
/// Options: `along_step` (mm per column, default 0.5), `rows` (default 360), `reach` (mm,
/// default 60) and the look and lumen options of `render` (`preset`, `iso`, …).
#[pyfunction]
#[pyo3(signature = (volume, path = None, **options))]
pub fn dissect<'py>(
    py: Python<'py>,
    volume: &Bound<'py, Volume>,
    path: Option<&Bound<'py, PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let kw = Kwargs::new(py, "dissect", options)?;
    let volume = volume.get();
    let look_options = LookOptions::take(&kw)?;
    let options = DissectOptions {
        step_mm: kw.take::<f64>("along_step")?.unwrap_or(DEFAULT_STEP_MM),
        rows: kw.take::<usize>("rows")?.unwrap_or(DEFAULT_ROWS),
        reach_mm: kw.take::<f64>("reach")?.unwrap_or(DEFAULT_REACH_MM),
    };
    let given = path.map(|p| read(py, p)).transpose()?;
    let look = look_options.resolve(py, volume.volume(), None, None)?;
    kw.finish()?;
    let scan = volume.volume();
    let path = match given {
        Some(Route::Path(path)) => path,
        Some(Route::Keys(_)) => {
            return Err(error(
                "path holds key frames: dissection needs a path's points",
            ))
        }
        None => {
            let smooth = SmoothOptions::default();
            let planned = py.detach(|| look.study.plan(scan, None, None, &smooth));
            planned.map_err(to_py)?.planned.path
        }
    };
    let wall = Wall::of(&look.settings);
    let flat = py
        .detach(|| look.in_pool(|| lay_flat(scan, &path, &wall, &options)))
        .map_err(to_py)?;
    let (w, h) = (flat.image.width(), flat.image.height());
    let image = Array3::from_shape_vec((h, w, 3), flat.image.rgb().to_vec()).map_err(to_py)?;
    let map = Array3::from_shape_vec((h, w, 3), flat.map.as_slice().to_vec()).map_err(to_py)?;
    let out = PyDict::new(py);
    out.set_item("image", image.into_pyarray(py))?;
    out.set_item("map", map.into_pyarray(py))?;
    out.set_item("width", w)?;
    out.set_item("height", h)?;
    let plot = PyDict::new(py);
    plot.set_item("x", flat.plot.x)?;
    plot.set_item("y", flat.plot.y)?;
    plot.set_item("columns", flat.plot.columns)?;
    plot.set_item("rows", flat.plot.rows)?;
    out.set_item("plot", plot)?;
    out.set_item("path_length_mm", path.len_mm())?;
    out.set_item("along_mm_per_px", flat.scale.along_mm_per_px)?;
    out.set_item("around_deg_per_px", flat.scale.around_deg_per_px)?;
    out.set_item("around_mm_per_px", flat.scale.around_mm_per_px)?;
    out.set_item("wall_fraction", flat.hit_fraction)?;
    Ok(out)
}
