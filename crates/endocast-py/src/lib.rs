//! Python bindings of endocast, built by maturin into the `endocast` package: a scan (any
//! format the readers take, or a numpy array with its affine) as a [`volume::Volume`] whose
//! voxels are a numpy array in physical units; `render` to an RGBA image and a depth image;
//! `path` through a lumen to points and radii; `fly` along a path to a video or frames.
//!
//! Every function is a thin front end over `endocast-core` and `endocast-io`, as the CLI is:
//! the options are the CLI's (`--look-at` is `look_at=`), with the same defaults and presets,
//! and the same library messages in the exceptions. The GIL is released while reading,
//! rendering and planning, so Python threads run those in parallel.

mod coverage;
mod dissect;
mod errors;
mod fly;
mod image;
mod kwargs;
mod look;
mod matching;
mod navigate;
mod polyps;
mod render;
mod route;
mod scene;
mod target;
mod volume;

use pyo3::prelude::*;

/// The native module, re-exported by `endocast/__init__.py`.
#[pymodule]
fn _endocast(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("EndocastError", m.py().get_type::<errors::EndocastError>())?;
    m.add_class::<volume::Volume>()?;
    m.add_function(wrap_pyfunction!(volume::open, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(navigate::default_view, m)?)?;
    m.add_function(wrap_pyfunction!(navigate::path, m)?)?;
    m.add_function(wrap_pyfunction!(fly::fly, m)?)?;
    m.add_function(wrap_pyfunction!(coverage::coverage, m)?)?;
    m.add_function(wrap_pyfunction!(matching::match_scans, m)?)?;
    m.add_function(wrap_pyfunction!(dissect::dissect, m)?)?;
    m.add_function(wrap_pyfunction!(polyps::polyps, m)?)?;
    m.add_function(wrap_pyfunction!(look::preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(image::save_png, m)?)?;
    Ok(())
}
