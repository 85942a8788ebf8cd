//! `endocast.fly`: a flight along a path, as `endocast fly` films it (the endoscopic view), to
//! a video file or as frames.

use crate::errors::{error, to_py};
use crate::kwargs::Kwargs;
use crate::look::{optics, LookOptions};
use crate::scene::{warn, SceneFiles};
use crate::volume::Volume;
use endocast_core::flight::{Flight, FlightOptions, Layout, Route, ShotSettings};
use endocast_core::study::LOOK_AHEAD_MM;
use endocast_io::dataset::DatasetWriter;
use endocast_io::route_file::{read_route, read_target};
use endocast_io::transfer_json::transfer_function;
use endocast_io::video::{open_sink, VideoOptions};
use glam::DVec3;
use numpy::ndarray::Array4;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Flies along `route` — an (N, 3) array of points (LPS mm), or a path file as `endocast path`
/// or 3D Slicer writes it (points or key frames) — one frame every `frame_step` mm (default
/// 1) looking `look_ahead` mm ahead (default 10). With `out` (a `.gif`, an `.mp4` or a folder
/// of PNGs) writes the film and returns its path (a `pathlib.Path`); without, returns the
/// frames as an RGB uint8 array (frames, height, width, 3). With `dataset` (a new or empty
/// folder) also writes the training data `endocast fly --dataset` writes: images, depth,
/// normals, masks, transforms.json and colmap/ (docs/dataset-format.md).
///
/// Options: `size` (width, height; default 384 × 384), `frame_step`, `look_ahead` (mm), `fps`,
/// and `render`'s look, peel, lens and lumen options: `preset`, `mode`, `iso`, `iso2`,
/// `iso_opacity`, `tf`, `step`, `jitter`, `skip_empty`, `shade_dvr`, `background`, `peel`,
/// `peel_threshold`, `peel_falling`, `peel_keep`, `unpeeled`, `tf_after`, `look`,
/// `secretion`, `secretion_iso`, `wetness`, `texture`, `texture_scale`, `specular_map`,
/// `attenuation`, `lighting`, `fov`, `near`, `lens`, `distortion`, `vignetting`,
/// `lumen_threshold`, `bright_lumen`, `threads`, `target` (ringed in every frame; default: the
/// path file's target, as `endocast path --target` writes it),
/// `meshes`, `overlays` (see `help(endocast.render)`). The volume may be a nibabel or SimpleITK image.
#[pyfunction]
#[pyo3(signature = (volume, route, out = None, **options))]
pub fn fly<'py>(
    py: Python<'py>,
    volume: &Bound<'py, Volume>,
    route: &Bound<'py, PyAny>,
    out: Option<PathBuf>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let kw = Kwargs::new(py, "fly", options)?;
    let volume = volume.get();
    let options = LookOptions::take(&kw)?;
    let fov = kw.take::<f64>("fov")?;
    let size = kw.take::<[usize; 2]>("size")?.unwrap_or([384, 384]);
    let frame_step = kw.take::<f64>("frame_step")?.unwrap_or(1.0);
    let look_ahead = kw.take::<f64>("look_ahead")?.unwrap_or(LOOK_AHEAD_MM);
    let fps = kw.take::<f64>("fps")?.unwrap_or(25.0);
    let target = match crate::target::take(&kw)? {
        Some(target) => Some(target),
        None => match route.extract::<PathBuf>() {
            Ok(file) => read_target(&file).map_err(to_py)?,
            Err(_) => None,
        },
    };
    let dataset = kw.take::<PathBuf>("dataset")?;
    let route = read(py, route)?;
    let shots = route.shots(frame_step, look_ahead).map_err(to_py)?;
    let first = shots
        .first()
        .ok_or_else(|| error("the route has no frames"))?
        .pose;
    let look = options.resolve(py, volume.volume(), Some(first), fov)?;
    let optics = optics(
        &kw,
        look.study.preset(),
        look.look.as_ref(),
        volume.volume(),
        fov,
    )?;
    let files = SceneFiles::take(&kw)?;
    kw.finish()?;
    let (scene, partial) = py.detach(|| files.read())?;
    warn(py, &partial)?;
    let options = FlightOptions {
        size,
        optics,
        stereo: None,
        layout: Layout::Endoscope,
        window: look.study.window(),
    };
    let renderer = volume.renderer().clone();
    let mut writer = dataset
        .map(|folder| DatasetWriter::create(&folder, renderer.volume(), &options.optics))
        .transpose()
        .map_err(to_py)?;
    let mut flight = Flight::new(renderer.clone(), options);
    flight.set_look(look.look.clone());
    flight.set_scene(scene);
    flight.set_target(target);
    let mut looks = ShotSettings::new(look.settings.clone(), transfer_function);
    let mut frame = |n: usize| {
        py.detach(|| {
            let settings = looks.for_shot(&shots[n]).map_err(to_py)?;
            let (image, _) = look
                .in_pool(|| flight.frame(n, &shots[n], &settings))
                .map_err(to_py)?;
            if let (Some(writer), Some((camera, depth))) = (&mut writer, flight.last_view()) {
                let volume = renderer.volume();
                writer.push(&image, &camera, depth, volume).map_err(to_py)?;
            }
            PyResult::Ok(image)
        })
    };
    if let Some(out) = out {
        let mut video = VideoOptions::default();
        video.fps = fps;
        let mut sink = open_sink(&out, &video).map_err(to_py)?;
        for n in 0..shots.len() {
            sink.push_image(&frame(n)?).map_err(to_py)?;
        }
        let written = sink.finish().map_err(to_py)?;
        finish(writer)?;
        return Ok(written.into_pyobject(py)?.into_any());
    }
    let mut rgb = Vec::new();
    let mut shape = (shots.len(), 0, 0, 3);
    for n in 0..shots.len() {
        let image = frame(n)?;
        (shape.1, shape.2) = (image.height(), image.width());
        rgb.extend_from_slice(image.rgb());
    }
    finish(writer)?;
    let frames = Array4::from_shape_vec(shape, rgb).map_err(to_py)?;
    Ok(frames.into_pyarray(py).into_any())
}

/// Writes the dataset's cameras, if one is written.
fn finish(writer: Option<DatasetWriter>) -> PyResult<()> {
    writer
        .map(DatasetWriter::finish)
        .transpose()
        .map_err(to_py)?;
    Ok(())
}

/// The route `value` gives: a path file's name, or an (N, 3) array of points.
pub(crate) fn read(py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<Route> {
    if let Ok(file) = value.extract::<PathBuf>() {
        return read_route(&file).map_err(to_py);
    }
    let np = py.import("numpy")?;
    let points: Vec<[f64; 3]> = np
        .call_method1("asarray", (value, "float64"))?
        .call_method0("tolist")?
        .extract()
        .map_err(|_| error("the route is neither a path file nor an (N, 3) array of points"))?;
    let points: Vec<DVec3> = points.into_iter().map(DVec3::from).collect();
    Route::through_points(&points).map_err(to_py)
}
