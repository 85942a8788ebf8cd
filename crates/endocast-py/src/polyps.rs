//! `endocast.polyps`: polyp candidates on the wall of the study's lumen, as
//! `endocast polyps --json` lists them.

use crate::errors::to_py;
use crate::fly::read;
use crate::kwargs::Kwargs;
use crate::look::LookOptions;
use crate::volume::Volume;
use endocast_core::polyps::{find_candidates, searched_lumen, PolypOptions};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// Polyp candidates on the wall of the lumen `path` starts in (an (N, 3) array of points, LPS
/// mm, or a path file; without it, the structure the `preset` finds: the colon with
/// `preset="colonoscopy"`), by shape index and curvedness.
///
/// Returns the dict `endocast polyps --json` prints: `candidates`, best score first, each with
/// `centre` (the tip on the wall, LPS mm), `size_mm` and `score` (0–1).
///
/// Options: `sigma` (smoothing, mm, default 1), `min_size` (mm, default 4: smaller candidates
/// are dropped) and the look and lumen options of `render` (`preset`, `iso`, `lumen_threshold`, …).
#[pyfunction]
#[pyo3(signature = (volume, path = None, **options))]
pub fn polyps<'py>(
    py: Python<'py>,
    volume: &Bound<'py, Volume>,
    path: Option<&Bound<'py, PyAny>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let kw = Kwargs::new(py, "polyps", options)?;
    let volume = volume.get();
    let look_options = LookOptions::take(&kw)?;
    let defaults = PolypOptions::default();
    let detection = PolypOptions {
        sigma_mm: kw.take::<f64>("sigma")?.unwrap_or(defaults.sigma_mm),
        min_size_mm: kw.take::<f64>("min_size")?.unwrap_or(defaults.min_size_mm),
        ..defaults
    };
    detection.check().map_err(to_py)?;
    let start = match path {
        Some(p) => Some(read(py, p)?.points_mm(1.0).map_err(to_py)?[0]),
        None => None,
    };
    let look = look_options.resolve(py, volume.volume(), None, None)?;
    kw.finish()?;
    let scan = volume.volume();
    let found = py.detach(|| {
        let lumen = searched_lumen(&look.study, scan, start).map_err(|e| e.to_string())?;
        look.in_pool(|| find_candidates(scan, &lumen, &detection))
            .map_err(|e| e.to_string())
    });
    let found = found.map_err(crate::errors::error)?;
    let records = PyList::empty(py);
    for c in &found {
        let record = PyDict::new(py);
        record.set_item("centre", c.centre_mm.to_array())?;
        record.set_item("size_mm", c.size_mm)?;
        record.set_item("score", c.score)?;
        records.append(record)?;
    }
    let out = PyDict::new(py);
    out.set_item("candidates", records)?;
    Ok(out)
}
