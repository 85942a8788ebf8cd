//! OME-Zarr, the chunked format of large and cloud-hosted bio-imaging, read and written
//! through the `zarrs` crate.
//!
//! Read: OME-Zarr 0.4 (Zarr v2 arrays, `multiscales` in the group's `.zattrs`) and 0.5 (Zarr
//! v3, `zarr.json` with `attributes.ome.multiscales`); codecs blosc, zstd, gzip, sharding and
//! crc32c; samples of 8- to 64-bit integers and 32- and 64-bit floats. The group's folder
//! gives the highest resolution (the first dataset); a level's own array folder
//! (`scan.zarr/1`) gives that level. Axes: `z, y, x` space axes, optionally after time and
//! channel axes of size 1; units from nanometer to meter (none: millimetres, with a warning).
//! Each level's `scale` and `translation` (or the 0.6 `affine`) are applied, then the
//! multiscale's own.
//!
//! OME-Zarr has no patient orientation: its physical `x, y, z` are read as the LPS patient
//! axes (x to the patient's left, y to the back, z up), the convention of other files here
//! that declare none (NRRD without a space), with a warning; `--orientation` or the head CT
//! guess then apply. A store endocast wrote carries the patient frame in its own group
//! attribute `endocast` (direction, origin, value rescale, modality), which it reads back
//! exactly.
//!
//! Written: see [`write`].

mod array;
mod json;
mod metadata;
mod pyramid;
mod transform;
mod write;

pub(crate) use metadata::is_zarr;
pub use write::write;

use crate::error::{ReadError, Result};
use crate::loaded::{Format, Loaded, OpenOptions, SourceInfo};
use crate::samples::Rescale;
use array::LevelArray;
use endocast_core::{Geometry, Modality, Volume};
use glam::{DAffine3, DMat3, DVec3};
use metadata::Image;
use serde::Deserialize;
use std::path::Path;

/// Distance within which the origin endocast wrote is taken over exactly, mm.
const ORIGIN_TOLERANCE_MM: f64 = 1e-6;

/// Difference of direction cosines within which endocast's written direction is taken over.
const DIRECTION_TOLERANCE: f64 = 1e-9;

/// endocast's group attribute: the patient frame and values of a store it wrote.
#[derive(Debug, Deserialize, serde::Serialize, Default)]
pub(super) struct Extra {
    /// The direction cosines of the physical `x, y, z` axes in LPS, as rows of columns.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub direction: Option<[[f64; 3]; 3]>,
    /// The LPS position of the first voxel of level 0, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub origin: Option<[f64; 3]>,
    /// Stored samples to physical values.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rescale: Option<[f64; 2]>,
    /// The modality code (`CT`, `MR`, ...).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub modality: Option<String>,
}

/// Reads the OME-Zarr image at `folder` (a group, or one of its levels' arrays) into a volume
/// in the LPS frame.
pub fn read(folder: &Path, options: &OpenOptions) -> Result<Loaded> {
    let (image, level) = metadata::locate(folder)?;
    let extra = extra(&image)?;
    let dataset = &image.multiscale.datasets[level];
    let array = LevelArray::open(&image.root, &dataset.path, &options.limits)?;
    let mut warnings = Vec::new();
    let physical = transform::physical_from_voxel(&image, level, array.shape(), &mut warnings)?;
    let geometry = patient_geometry(&image, &extra, level, array.shape(), physical)?;
    if extra.direction.is_none() {
        warnings.push(format!(
            "{}: OME-Zarr gives no patient orientation; its x, y, z were read as left, \
             posterior, superior (LPS), so left/right, front/back and up/down may be wrong",
            image.root.display()
        ));
    }
    let rescale = extra
        .rescale
        .map_or(Rescale::IDENTITY, |[slope, intercept]| Rescale {
            slope,
            intercept,
        });
    let level_folder = image.root.join(&dataset.path);
    let (voxels, map) = array.read(&level_folder, rescale, &mut warnings)?;
    let modality = Modality::from_code(extra.modality.as_deref().unwrap_or(""));
    let volume = Volume::new(geometry, voxels, map, modality)
        .map_err(|e| ReadError::format(&level_folder, e.to_string()))?;
    let stored = format!(
        "{}, OME-Zarr {}, level {level} of {}",
        array.element().name(),
        image.version,
        image.multiscale.datasets.len()
    );
    let mut source = SourceInfo::new(Format::OmeZarr, stored);
    source.orientation_declared = extra.direction.is_some();
    Ok(Loaded {
        volume,
        source,
        warnings,
    })
}

/// endocast's attribute of `image`, empty for a store another tool wrote.
fn extra(image: &Image) -> Result<Extra> {
    let Some(value) = &image.endocast else {
        return Ok(Extra::default());
    };
    let extra = Extra::deserialize(value)
        .map_err(|e| ReadError::format(&image.file, format!("{}: {e}", metadata::ENDOCAST_KEY)))?;
    Ok(extra)
}

/// The LPS geometry of a level whose array has `shape` and whose physical frame is
/// `physical`: turned by endocast's direction where the store has one, its written origin
/// taken over exactly at level 0 where it agrees.
fn patient_geometry(
    image: &Image,
    extra: &Extra,
    level: usize,
    shape: &[u64],
    physical: DAffine3,
) -> Result<Geometry> {
    let n = shape.len();
    let dims = [shape[n - 1], shape[n - 2], shape[n - 3]].map(|d| usize::try_from(d).unwrap_or(0));
    let direction = extra
        .direction
        .map_or(DMat3::IDENTITY, |cols| DMat3::from_cols_array_2d(&cols));
    let world = DAffine3::from_mat3(direction) * physical;
    let invalid = |e: endocast_core::GeometryError| {
        ReadError::format(
            &image.file,
            format!("the coordinate transformations give an invalid grid: {e}"),
        )
    };
    let geometry = Geometry::from_world_from_voxel(dims, world).map_err(invalid)?;
    let agrees = geometry
        .direction()
        .abs_diff_eq(direction, DIRECTION_TOLERANCE);
    let written = extra.origin.map(DVec3::from).filter(|origin| {
        level == 0 && agrees && origin.distance(geometry.origin_mm()) <= ORIGIN_TOLERANCE_MM
    });
    match (written, extra.direction) {
        (Some(origin), Some(_)) => {
            Geometry::new(dims, geometry.spacing_mm(), origin, direction).map_err(invalid)
        }
        _ => Ok(geometry),
    }
}
