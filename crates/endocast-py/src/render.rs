//! `endocast.render`: one view of a volume, as `endocast render` makes it.

use crate::errors::{error, to_py};
use crate::kwargs::Kwargs;
use crate::look::{camera, LookOptions, Placed};
use crate::scene::{warn, SceneFiles};
use crate::volume::Volume;
use endocast_core::camera::StereoRig;
use endocast_core::look::{stereo_view, still_view, Look, MAX_STILL_FRAMES};
use endocast_core::render::Filter;
use endocast_core::render::{Camera, Frame, Prepared};
use endocast_core::views::stereo::{self, StereoOutput};
use endocast_core::views::{lens_marks, Image};
use endocast_io::{Limits, RenderKind};
use numpy::ndarray::{Array, IxDyn};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::Path;

/// Stereo options: how the eyes are combined, their distance and the focus distance (mm).
struct Stereo {
    output: StereoOutput,
    eye_separation_mm: Option<f64>,
    focus_mm: Option<f64>,
}

/// A rendered view: RGBA rows (or two, for a stereo pair) and depth images.
struct View {
    /// `[images, height, width]` of the colour.
    rgba_shape: [usize; 3],
    rgba: Vec<u8>,
    /// `[images, height, width]` of the depth.
    depth_shape: [usize; 3],
    depth: Vec<f32>,
}

/// Renders `volume` as `endocast render` does and returns `(rgba, depth)`: RGBA uint8
/// (height, width, 4; the colour over the background, alpha 255 but 0 in the unfolded cube's
/// empty cells) and the depth of the first isosurface hit, float32 mm from the eye (height,
/// width; NaN where none). A stereo pair
/// (`stereo="pair"`) gives (2, height, width, 4) and (2, height, width); a combined stereo
/// image gives the left eye's depth.
///
/// The scan is understood as the command understands it: the `preset` (colonoscopy,
/// bronchoscopy, angioscopy, sinus, ventricles, arthroscopy; `presets()` lists them) is carried
/// into the scan's own units (HU, HU + 1024, MR intensities), and without `eye`/`look_at` the
/// camera starts inside the structure the preset names, looking along the automatic path
/// (`default_view`); without a preset the whole object is framed.
///
/// Options (keywords, as the command's flags with `_` for `-`):
/// - look: `preset`, `mode` (iso, dvr, hybrid, two-iso, mip, minip, peel), `iso` (the wall,
///   in the scan's units; the lumen threshold follows it), `iso2`, `iso_opacity`, `tf` (a
///   JSON file or a preset name), `step` (voxels), `jitter`, `skip_empty`, `shade_dvr`,
///   `background` (r, g, b), `threads`;
/// - camera: `eye`, `look_at`, `up` (LPS mm), `fov` (degrees), `near` (mm), `size`
///   (width, height; default 512 × 512), `lens` (pinhole, equidistant, equisolid,
///   orthographic, cube, panorama), `distortion` (k1, k2), `vignetting` (default: the look's lens, with
///   `look="realistic"` a rigid endoscope's barrel distortion and vignetting; `(0, 0)` and 0
///   for an ideal lens);
/// - stereo: `stereo` (anaglyph, red-cyan, dubois, side-by-side, top-bottom, pair),
///   `eye_separation`, `focus` (mm), in any look (the geometry drawn in each eye, `still`
///   averaging each eye);
/// - depth peeling (`mode="peel"`): `peel` (1, 2, 3 … or "last"), `peel_threshold`,
///   `peel_falling`, `peel_keep` (0–1), `unpeeled` (discard, context), `tf_after`;
/// - the endoscope's look: `look` (plain, clinical, realistic; default the preset's),
///   `secretion` (off, on, accumulate), `secretion_iso`, `wetness` (0–1), `texture`
///   (mucosa, grid, none or a PNG file, its colour kept), `texture_scale` (mm),
///   `specular_map` (a PNG file, grey: bright is glossier), `attenuation` (mm, 0: none),
///   `lighting` (phong, ibl: a built-in lit sphere, or "ibl:FILE.png": yours), `still` (average
///   this many jittered frames, 1–256), `still_filter` (trilinear, the default, or bspline:
///   tricubic B-splines, surfaces exact at the voxels and smooth normals, about ten times
///   slower a frame);
/// - lumen: `lumen_threshold`, `bright_lumen`;
/// - `target` (x, y, z; LPS mm, e.g. a nodule `endocast path --target` routes to): ringed in
///   the view, solid where the view sees it, dashed and dimmer where it lies behind the wall,
///   with its distance from the eye (not with `stereo`);
/// - geometry: `meshes` (STL, OBJ or PLY files, world mm), `overlays` (DICOM segmentations,
///   each segment a surface in its colour, and dose grids, isodose surfaces at `FILE:LEVELS`
///   or 50, 80 and 95 % of the maximum), as `--mesh` and `--overlay` draw them.
#[pyfunction]
#[pyo3(signature = (volume, **options))]
pub fn render<'py>(
    py: Python<'py>,
    volume: &Bound<'py, Volume>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let kw = Kwargs::new(py, "render", options)?;
    let volume = volume.get();
    let options = LookOptions::take(&kw)?;
    let placed = Placed::take(&kw)?;
    let look = options.resolve(py, volume.volume(), placed.pose, placed.fov)?;
    let camera = camera(&kw, &look, volume.volume(), &placed)?;
    let stereo = stereo_options(&kw)?;
    let still = kw.take::<usize>("still")?.unwrap_or(1);
    let filter = match kw.take::<String>("still_filter")? {
        Some(name) => Filter::from_name(&name).ok_or_else(|| {
            error(format!(
                "still_filter must be trilinear or bspline, not {name:?}"
            ))
        })?,
        None => Filter::Trilinear,
    };
    let files = SceneFiles::take(&kw)?;
    let target = crate::target::take(&kw)?;
    kw.finish()?;
    if target.is_some() && stereo.is_some() {
        return Err(error("target draws on one view: leave out stereo"));
    }
    if !(1..=MAX_STILL_FRAMES).contains(&still) {
        return Err(error(format!(
            "still must be between 1 and {MAX_STILL_FRAMES} frames, not {still}"
        )));
    }
    let kind = RenderKind::of(look.look.as_ref(), stereo.is_some());
    Limits::default()
        .check_frames(Path::new("size"), camera.size(), kind, 1)
        .map_err(to_py)?;
    let voxels = volume.volume().voxels().len();
    let (filter, memory) = Limits::default().still_filter(filter, voxels);
    if let Some(memory) = memory {
        warn(py, &[memory])?;
    }
    let renderer = volume.renderer().clone();
    let (view, partial) = py.detach(|| -> PyResult<(View, Vec<String>)> {
        let mut prepared = renderer.prepare(&look.settings).map_err(to_py)?;
        let (scene, partial) = files.read()?;
        prepared.set_scene(scene);
        match &stereo {
            None => {
                let frame = look
                    .in_pool(|| still_view(&prepared, look.look.as_ref(), &camera, still, filter))
                    .map_err(to_py)?;
                let mut view = single(&frame, look.settings.background);
                if let Some(target) = target {
                    let spacing = renderer.volume().geometry().spacing_mm();
                    crate::target::ring(&mut view.rgba, &camera, &frame.depth_mm, spacing, target);
                }
                lens_marks::draw_rgba(&mut view.rgba, &camera);
                Ok((view, partial))
            }
            Some(stereo) => {
                let view = look.in_pool(|| {
                    render_stereo(
                        &prepared,
                        look.look.as_ref(),
                        (&camera, stereo),
                        (still, filter),
                    )
                })?;
                Ok((view, partial))
            }
        }
    })?;
    warn(py, &partial)?;
    let (rgba_dims, depth_dims) = (rgba_dims(&view), depth_dims(&view));
    let rgba = Array::from_shape_vec(IxDyn(&rgba_dims), view.rgba).map_err(to_py)?;
    let depth = Array::from_shape_vec(IxDyn(&depth_dims), view.depth).map_err(to_py)?;
    Ok((
        rgba.into_pyarray(py).into_any(),
        depth.into_pyarray(py).into_any(),
    ))
}

/// The colour array's shape: one image (h, w, 4) or a pair (2, h, w, 4).
fn rgba_dims(view: &View) -> Vec<usize> {
    let [n, h, w] = view.rgba_shape;
    if n == 1 {
        vec![h, w, 4]
    } else {
        vec![n, h, w, 4]
    }
}

/// The depth array's shape: one image (h, w) or a pair (2, h, w).
fn depth_dims(view: &View) -> Vec<usize> {
    let [n, h, w] = view.depth_shape;
    if n == 1 {
        vec![h, w]
    } else {
        vec![n, h, w]
    }
}

/// Takes `stereo`, `eye_separation` and `focus`.
fn stereo_options(kw: &Kwargs<'_>) -> PyResult<Option<Stereo>> {
    let output = kw.take::<String>("stereo")?;
    let eye_separation_mm = kw.take("eye_separation")?;
    let focus_mm = kw.take("focus")?;
    let Some(name) = output else {
        if eye_separation_mm.is_some() || focus_mm.is_some() {
            return Err(error("eye_separation and focus need stereo"));
        }
        return Ok(None);
    };
    let output = StereoOutput::from_name(&name).ok_or_else(|| {
        error(format!(
            "unknown stereo output {name:?}: use anaglyph, red-cyan, dubois, side-by-side, \
             top-bottom or pair"
        ))
    })?;
    Ok(Some(Stereo {
        output,
        eye_separation_mm,
        focus_mm,
    }))
}

/// One frame as a view.
fn single(frame: &Frame, background: [f32; 3]) -> View {
    let [w, h] = [frame.width, frame.height];
    View {
        rgba_shape: [1, h, w],
        rgba: frame.to_rgba8(background),
        depth_shape: [1, h, w],
        depth: frame.depth_mm.clone(),
    }
}

/// Both eyes of `camera` in `look` (`None`: plain), each the average of `still` frames,
/// combined as `stereo.output` says (a pair stays two images).
fn render_stereo(
    prepared: &Prepared,
    look: Option<&Look>,
    (camera, stereo): (&Camera, &Stereo),
    still: (usize, Filter),
) -> PyResult<View> {
    let nearest = || prepared.nearest_surface_mm(camera);
    let rig =
        StereoRig::for_view(stereo.eye_separation_mm, stereo.focus_mm, nearest).map_err(to_py)?;
    let [left, right] = stereo_view(prepared, look, (camera, &rig), still).map_err(to_py)?;
    let background = prepared.settings().background;
    if stereo.output == StereoOutput::Pair {
        let (l, r) = (single(&left, background), single(&right, background));
        let [_, h, w] = l.rgba_shape;
        return Ok(View {
            rgba_shape: [2, h, w],
            rgba: [l.rgba, r.rgba].concat(),
            depth_shape: [2, h, w],
            depth: [l.depth, r.depth].concat(),
        });
    }
    let image = |frame: &Frame| Image::from_frame(frame, background).map_err(to_py);
    let combined =
        stereo::combine(&image(&left)?, &image(&right)?, stereo.output).map_err(to_py)?;
    let [w, h] = [combined.width(), combined.height()];
    Ok(View {
        rgba_shape: [1, h, w],
        rgba: combined
            .rgb()
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect(),
        depth_shape: [1, left.height, left.width],
        depth: left.depth_mm,
    })
}
