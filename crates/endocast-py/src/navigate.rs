//! `endocast.path` (the centred flight path through a lumen, as `endocast path` plans it) and
//! `endocast.default_view` (the camera `render` takes when none is given).

use crate::errors::{error, to_py};
use crate::kwargs::Kwargs;
use crate::look::{find_preset, LookOptions};
use crate::route::{RouteSummary, TargetOptions};
use crate::volume::Volume;
use endocast_core::path::SmoothOptions;
use endocast_core::study::{Study, StudyPath, StudyPathError, StudyRequest};
use glam::DVec3;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// A point in LPS mm, as (x, y, z).
type Point = (f64, f64, f64);

/// The centred path through the lumen from `start` (LPS mm; or `start_voxel`, an index) to
/// `end` (or `end_voxel`), as `endocast path` plans it and writes it. Without a start, the
/// `preset`'s structure is found and the path starts where `default_view` puts the camera;
/// without an end it runs to the structure's known end (the aorta's lowest section), else to
/// the farthest lumen point. Returns points every `step` mm (default 2) and the last, as an
/// (N, 3) array in LPS mm, and each point's distance to the lumen wall (N,), mm. Options:
/// `preset`, `iso` (the wall, in the scan's units: the lumen threshold follows it),
/// `lumen_threshold`, `bright_lumen`, `smoothing` (control point spacing, mm, default 5) and
/// `step`.
///
/// With `target` (LPS mm, a nodule) and the bronchoscopy preset, the path is the bronchoscope's
/// route from the trachea through airways at least `scope_diameter` wide (mm, default 4.9) to
/// the reachable centreline point nearest the target, as `endocast path --target` plans it, and
/// a third element is returned: a dict with `target`, `scope_diameter_mm`, `end`,
/// `remaining_mm` (from the end to the target), `narrowest_diameter_mm` (None where only the
/// scan's border limits it), `branches` (the branches passed, each a dict of `name` and
/// `generation`) and `carina` (where the trachea's lumen splits, LPS mm; None when it does not
/// fork).
#[pyfunction]
#[pyo3(signature = (volume, start = None, end = None, **options))]
pub fn path<'py>(
    py: Python<'py>,
    volume: &Bound<'py, Volume>,
    start: Option<[f64; 3]>,
    end: Option<[f64; 3]>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let kw = Kwargs::new(py, "path", options)?;
    let volume = volume.get().volume();
    let start_voxel = kw.take::<[f64; 3]>("start_voxel")?;
    let end_voxel = kw.take::<[f64; 3]>("end_voxel")?;
    let request = StudyRequest {
        preset: kw
            .take::<String>("preset")?
            .map(|n| find_preset(&n))
            .transpose()?,
        iso: kw.take::<f64>("iso")?,
        lumen_threshold: kw.take("lumen_threshold")?,
        bright_lumen: kw.take("bright_lumen")?.unwrap_or(false),
        ..StudyRequest::default()
    };
    let smoothing = kw.take::<f64>("smoothing")?.unwrap_or(5.0);
    let step = kw.take::<f64>("step")?.unwrap_or(2.0);
    let target = TargetOptions::take(&kw)?;
    kw.finish()?;
    if target.is_some() && (start.is_some() || end.is_some()) {
        return Err(error("give target, or start and end, not both"));
    }
    let world = |p: Option<[f64; 3]>, v: Option<[f64; 3]>, name: &str| match (p, v) {
        (Some(_), Some(_)) => Err(error(format!("give {name} or {name}_voxel, not both"))),
        (Some(p), None) => Ok(Some(DVec3::from(p))),
        (None, Some(v)) => Ok(Some(volume.geometry().world_of(DVec3::from(v)))),
        (None, None) => Ok(None),
    };
    let start = world(start, start_voxel, "start")?;
    let end = world(end, end_voxel, "end")?;
    let options = SmoothOptions {
        control_spacing_mm: smoothing,
        step_mm: 0.5,
        ..SmoothOptions::default()
    };
    let (points, radii, route) = py.detach(|| -> PyResult<_> {
        let study = Study::resolve(volume, &request);
        if let Some(target) = &target {
            let routed = target.plan(volume, &study, &options)?;
            let (points, radii) = sampled(&routed.path, step)?;
            return Ok((points, radii, Some(RouteSummary::of(&routed))));
        }
        let planned = study
            .plan(volume, start, end, &options)
            .map_err(|e| match e {
                StudyPathError::NoStart(why) => error(format!(
                    "{why}: start=(x, y, z) in LPS mm or start_voxel=(i, j, k), or a preset \
                     whose structure is found"
                )),
                e => error(e.to_string()),
            })?;
        let (points, radii) = sampled(&planned, step)?;
        Ok((points, radii, None))
    })?;
    let flat: Vec<f64> = points.iter().flat_map(|p| p.to_array()).collect();
    let points = Array2::from_shape_vec((points.len(), 3), flat).map_err(to_py)?;
    let (points, radii) = (points.into_pyarray(py), PyArray1::from_vec(py, radii));
    match route {
        Some(route) => PyTuple::new(
            py,
            [
                points.into_any(),
                radii.into_any(),
                route.to_dict(py)?.into_any(),
            ],
        ),
        None => PyTuple::new(py, [points.into_any(), radii.into_any()]),
    }
}

/// A planned path's points every `step` mm and their distances to the wall.
fn sampled(planned: &StudyPath, step: f64) -> PyResult<(Vec<DVec3>, Vec<f64>)> {
    let points = planned.planned.path.points_every(step).map_err(to_py)?;
    let radii = points
        .iter()
        .map(|&p| planned.field.distance_mm(p))
        .collect();
    Ok((points, radii))
}

/// The camera `render` takes when given no `eye`, the same as `endocast render`'s: for an
/// endoscopic preset inside the structure it means (the airways from the trachea, the aorta,
/// the colon, the nasal cavity, the ventricles), looking along the automatic path; else the
/// whole object framed from the front. Returns `(eye, look_at, up)`, LPS mm. Takes the look
/// options of `render` (`preset`, `iso`, `lumen_threshold`, `bright_lumen`, `fov`, ...).
#[pyfunction]
#[pyo3(signature = (volume, **options))]
pub fn default_view<'py>(
    py: Python<'py>,
    volume: &Bound<'py, Volume>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Point, Point, Point)> {
    let kw = Kwargs::new(py, "default_view", options)?;
    let volume = volume.get().volume();
    let look = LookOptions::take(&kw)?;
    let fov = kw.take::<f64>("fov")?;
    kw.finish()?;
    let pose = look.resolve(py, volume, None, fov)?.study.start_pose();
    let triple = |v: DVec3| (v.x, v.y, v.z);
    Ok((
        triple(pose.eye_mm),
        triple(pose.look_at_mm),
        triple(pose.up),
    ))
}
