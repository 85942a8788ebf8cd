//! `endocast.open` and `endocast.Volume`: a scan read by the library's readers, or made from a
//! numpy array and its affine, held by the renderer that every call shares.

use crate::errors::{error, to_py};
use endocast_core::cleanse::Cleanse;
use endocast_core::render::Renderer;
use endocast_core::{Geometry, Modality};
use endocast_io::{ElementType, Endian, Limits, OpenOptions, Rescale};
use glam::{DAffine3, DMat3, DVec3};
use numpy::ndarray::{Array2, Array3, ShapeBuilder};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A scan: voxels with their geometry in the patient (LPS mm) and their physical values.
///
/// Its voxels are kept once, by the renderer that `render`, `path` and `fly` share (16-bit
/// stored values and a linear map to physical values, as the library keeps every volume).
#[pyclass(frozen, module = "endocast")]
pub struct Volume {
    renderer: Arc<Renderer>,
    warnings: Vec<String>,
    source: String,
    /// The physical values as float32, made on first use.
    physical: PyOnceLock<Py<PyArray3<f32>>>,
}

impl Volume {
    fn new(volume: endocast_core::Volume, warnings: Vec<String>, source: String) -> Self {
        Self {
            renderer: Arc::new(Renderer::new(volume)),
            warnings,
            source,
            physical: PyOnceLock::new(),
        }
    }

    /// The renderer holding the volume.
    pub fn renderer(&self) -> &Arc<Renderer> {
        &self.renderer
    }

    /// The volume.
    pub fn volume(&self) -> &endocast_core::Volume {
        self.renderer.volume()
    }
}

/// Reads a scan as every endocast command does: a DICOM directory or file (the largest series,
/// or `series`), NIfTI, NRRD, MetaImage. Keywords as the command's options: `max_voxels`,
/// `orientation` (for a file that declares none, e.g. "LPI"; a head CT is otherwise turned
/// upright from its anatomy), `fill_missing_slices` (accept a DICOM series with missing slices,
/// interpolated and warned), `allow_outside_data` (a detached NRRD/MetaImage data file outside
/// the header's folder), `cleanse` (CT colonography: remove pools of tagged fluid under air and
/// their rims, as `--cleanse on`; what was removed is added to `warnings`).
#[pyfunction]
#[pyo3(signature = (
    path,
    series = None,
    *,
    max_voxels = None,
    orientation = None,
    fill_missing_slices = false,
    allow_outside_data = false,
    cleanse = false,
))]
#[allow(clippy::needless_pass_by_value)] // PyO3 hands arguments over by value.
#[allow(clippy::too_many_arguments)] // Python keyword arguments, each optional.
pub fn open(
    py: Python<'_>,
    path: PathBuf,
    series: Option<String>,
    max_voxels: Option<u64>,
    orientation: Option<String>,
    fill_missing_slices: bool,
    allow_outside_data: bool,
    cleanse: bool,
) -> PyResult<Volume> {
    let mut options = OpenOptions::default();
    options.series = series;
    if let Some(max) = max_voxels {
        options.limits = Limits::with_max_voxels(max);
    }
    options.orientation = orientation;
    options.fill_missing_slices = fill_missing_slices;
    options.allow_outside_data = allow_outside_data;
    let mut loaded = py
        .detach(|| endocast_io::open(&path, &options))
        .map_err(to_py)?;
    let switch = if cleanse { Cleanse::On } else { Cleanse::Off };
    let (volume, summary) = py.detach(|| switch.apply(loaded.volume)).map_err(to_py)?;
    loaded.warnings.extend(summary);
    let source = loaded.source.format.name().to_owned();
    Ok(Volume::new(volume, loaded.warnings, source))
}

#[pymethods]
impl Volume {
    /// A volume from a 3-D array indexed `[i, j, k]` and the 4 × 4 affine from voxel index to
    /// world mm in `space` ("RAS", as nibabel's `img.affine`, or "LPS", as DICOM and ITK).
    #[staticmethod]
    #[pyo3(signature = (array, affine, space = "RAS", modality = None))]
    fn from_array(
        py: Python<'_>,
        array: &Bound<'_, PyAny>,
        affine: &Bound<'_, PyAny>,
        space: &str,
        modality: Option<&str>,
    ) -> PyResult<Self> {
        let mut warnings = Vec::new();
        let (dims, voxels, map) = stored_voxels(py, array, &mut warnings)?;
        let world_from_voxel = lps_affine(py, affine, space)?;
        let geometry = Geometry::from_world_from_voxel(dims, world_from_voxel).map_err(to_py)?;
        let modality = Modality::from_code(modality.unwrap_or(""));
        let volume = endocast_core::Volume::new(geometry, voxels, map, modality).map_err(to_py)?;
        Ok(Self::new(volume, warnings, "array".to_owned()))
    }

    /// The voxels in physical units (Hounsfield units for CT) as a read-only float32 array
    /// indexed `[i, j, k]` (Fortran order, like nibabel's). Made once, on first use: a copy
    /// of the 16-bit voxels through the value map.
    #[getter]
    fn voxels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let array = self.physical.get_or_try_init(py, || -> PyResult<_> {
            let volume = self.volume();
            let map = volume.value_map();
            let values: Vec<f32> = py.detach(|| {
                let voxels = volume.voxels();
                voxels.par_iter().map(|&s| map.physical(s) as f32).collect()
            });
            let [x, y, z] = volume.dims();
            let array = Array3::from_shape_vec((x, y, z).f(), values).map_err(to_py)?;
            let array = array.into_pyarray(py);
            array.getattr("flags")?.setattr("writeable", false)?;
            Ok(array.unbind())
        })?;
        Ok(array.bind(py).clone())
    }

    /// Voxels along i, j, k.
    #[getter]
    fn shape(&self) -> (usize, usize, usize) {
        let [x, y, z] = self.volume().dims();
        (x, y, z)
    }

    /// The 4 × 4 affine from voxel index (i, j, k, 1) to LPS mm (DICOM's patient frame).
    #[getter]
    fn affine<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        matrix(py, self.volume().geometry().world_from_voxel())
    }

    /// The 4 × 4 affine from voxel index to RAS mm (nibabel's and NIfTI's world).
    #[getter]
    fn affine_ras<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let flip = DAffine3::from_scale(DVec3::new(-1.0, -1.0, 1.0));
        matrix(py, flip * self.volume().geometry().world_from_voxel())
    }

    /// Voxel spacing along i, j, k, mm.
    #[getter]
    fn spacing<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let spacing = self.volume().geometry().spacing_mm().to_array();
        PyArray1::from_slice(py, &spacing)
    }

    /// World position (LPS mm) of the centre of voxel (0, 0, 0).
    #[getter]
    fn origin<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let origin = self.volume().geometry().origin_mm().to_array();
        PyArray1::from_slice(py, &origin)
    }

    /// The imaging modality: "CT", "MR", another DICOM code, or "unknown".
    #[getter]
    fn modality(&self) -> String {
        self.volume().modality().name().to_owned()
    }

    /// What the reader noted without stopping (skipped files, uneven gaps, quantisation, ...).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The format it was read from ("NIfTI", "DICOM", ...), or "array".
    #[getter]
    fn source(&self) -> String {
        self.source.clone()
    }

    /// The smallest and largest physical value.
    #[getter]
    fn value_range(&self) -> (f64, f64) {
        self.volume().physical_range()
    }

    fn __repr__(&self) -> String {
        let [x, y, z] = self.volume().dims();
        let s = self.volume().geometry().spacing_mm();
        format!(
            "<endocast.Volume {x}×{y}×{z} voxels of {:.3}×{:.3}×{:.3} mm, {} from {}>",
            s.x,
            s.y,
            s.z,
            self.volume().modality().name(),
            self.source
        )
    }
}

/// A 4 × 4 matrix of an affine, rows first.
fn matrix(py: Python<'_>, affine: DAffine3) -> Bound<'_, PyArray2<f64>> {
    let m = affine.matrix3;
    let t = affine.translation;
    let rows = [
        [m.x_axis.x, m.y_axis.x, m.z_axis.x, t.x],
        [m.x_axis.y, m.y_axis.y, m.z_axis.y, t.y],
        [m.x_axis.z, m.y_axis.z, m.z_axis.z, t.z],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    let array = Array2::from_shape_vec((4, 4), flat).expect("16 values make a 4 × 4 matrix");
    array.into_pyarray(py)
}

/// The stored 16-bit voxels and value map of a 3-D numpy array, converted as the readers
/// convert a file's samples (8- and 16-bit exactly, wider types exactly when they hold at most
/// 65 536 integers, else quantised with a warning).
fn stored_voxels(
    py: Python<'_>,
    array: &Bound<'_, PyAny>,
    warnings: &mut Vec<String>,
) -> PyResult<([usize; 3], Vec<u16>, endocast_core::ValueMap)> {
    let np = py.import("numpy")?;
    let mut array = np.call_method1("asarray", (array,))?;
    let ndim: usize = array.getattr("ndim")?.extract()?;
    if ndim != 3 {
        return Err(error(format!(
            "the array has {ndim} dimensions; a volume needs 3, indexed [i, j, k]"
        )));
    }
    if array
        .getattr("dtype")?
        .getattr("kind")?
        .extract::<String>()?
        == "b"
    {
        array = array.call_method1("astype", (np.getattr("uint8")?,))?;
    }
    let dtype = array.getattr("dtype")?;
    let name: String = dtype.getattr("name")?.extract()?;
    let element = ElementType::from_name(&name).ok_or_else(|| {
        error(format!(
            "unsupported array type {name}: use an integer or float type of up to 64 bits"
        ))
    })?;
    let endian = if dtype.getattr("byteorder")?.extract::<String>()? == ">" {
        Endian::Big
    } else {
        Endian::Little
    };
    let dims: [usize; 3] = array.getattr("shape")?.extract()?;
    // The samples in voxel order (i fastest): a view when the array is already in Fortran
    // order, as nibabel's arrays are.
    let bytes = np
        .call_method1("asfortranarray", (array,))?
        .call_method1("ravel", ("F",))?
        .call_method1("view", (np.getattr("uint8")?,))?;
    let bytes: PyReadonlyArray1<'_, u8> = bytes.extract()?;
    let mut samples = bytes.as_slice()?;
    let count = dims.iter().product();
    let (voxels, map) = endocast_io::samples::read_voxels(
        Path::new("array"),
        &mut samples,
        element,
        endian,
        count,
        Rescale::IDENTITY,
        warnings,
    )
    .map_err(to_py)?;
    Ok((dims, voxels, map))
}

/// The LPS affine of a 4 × 4 `affine` given in `space` ("RAS" or "LPS").
fn lps_affine(py: Python<'_>, affine: &Bound<'_, PyAny>, space: &str) -> PyResult<DAffine3> {
    let np = py.import("numpy")?;
    let affine = np.call_method1("asarray", (affine, "float64"))?;
    let shape: Vec<usize> = affine.getattr("shape")?.extract()?;
    if shape != [4, 4] {
        return Err(error(format!(
            "the affine has shape {shape:?}; it must be 4 × 4"
        )));
    }
    let rows: [[f64; 4]; 4] = affine.call_method0("tolist")?.extract()?;
    if rows[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(error(format!(
            "the affine's last row is {:?}, not [0, 0, 0, 1]",
            rows[3]
        )));
    }
    let column = |c: usize| DVec3::new(rows[0][c], rows[1][c], rows[2][c]);
    let given = DAffine3::from_mat3_translation(
        DMat3::from_cols(column(0), column(1), column(2)),
        column(3),
    );
    match space.to_ascii_uppercase().as_str() {
        "LPS" => Ok(given),
        "RAS" => Ok(DAffine3::from_scale(DVec3::new(-1.0, -1.0, 1.0)) * given),
        _ => Err(error(format!(
            "space {space:?}: the affine's world is \"RAS\" or \"LPS\""
        ))),
    }
}
