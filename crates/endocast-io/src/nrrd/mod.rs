//! NRRD, the format of teem and 3D Slicer: a text header followed by the samples (`.nrrd`), or
//! a header naming the file(s) that hold them (`.nhdr`).
//!
//! Read: every sample type of the spec, raw, gzip, ascii or hex encoding (not bzip2), either
//! byte order, `line skip` and `byte skip` (−1 included), a single detached file, a `LIST` of
//! files or a `%d` pattern of slice files (regular files in the header's folder or below it,
//! each checked to hold its share of the samples before anything is allocated), 2-D images (as
//! one slice) and 4-D files whose first axis has size 1. Geometry comes from `space directions`
//! and `space origin` in any anatomical space (converted to LPS), or from the older `spacings`
//! and `axis mins` as an axis-aligned grid. Spaces without an anatomical meaning
//! (`scanner-xyz`, `3D-right-handed`, `3D-left-handed`) are read as LPS with a warning.
//!
//! Written: see [`write`].

mod data;
mod fields;
mod files;
mod header;
mod values;
mod write;

pub use write::write;

use crate::error::{ReadError, Result};
use crate::loaded::{Format, Loaded, OpenOptions, SourceInfo};
use crate::samples::Endian;
use endocast_core::{Geometry, Modality, Volume};
use fields::{Center, DataFiles, Encoding, Space};
use glam::{DMat3, DVec3};
use header::Header;
use std::path::Path;

/// Reads the NRRD file (`.nrrd`) or detached header (`.nhdr`) at `path` into a volume in the
/// LPS frame. Samples keep their values: 8- and 16-bit types exactly, wider types through
/// [`read_voxels`](crate::samples::read_voxels)'s mapping onto 16 bits.
pub fn read(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    let mut warnings = Vec::new();
    let header = header::read_header(path, &options.limits, &mut warnings)?;
    let axes = spatial_axes(path, &header)?;
    let count = options.limits.check_dims(path, &header.sizes)?;
    let geometry = geometry(path, &header, &axes, &mut warnings)?;
    let endian = endian(path, &header, &mut warnings);
    let (voxels, map) = data::read_samples(path, &header, count, endian, options, &mut warnings)?;
    let volume = Volume::new(geometry, voxels, map, Modality::Unknown)
        .map_err(|e| ReadError::format(path, e.to_string()))?;
    let mut source = SourceInfo::new(Format::Nrrd, stored_type(&header, endian));
    source.orientation_declared = header.space_directions.is_some()
        && matches!(header.space, Some(Space::Lps | Space::Ras | Space::Las));
    Ok(Loaded {
        volume,
        source,
        warnings,
    })
}

/// The header's axes that become the volume's `i`, `j` (and `k`): all of them for 2-D and 3-D
/// files, all but a leading axis of size 1 (a single vector component or time point) for 4-D.
fn spatial_axes(path: &Path, header: &Header) -> Result<Vec<usize>> {
    match header.dimension {
        2 => Ok(vec![0, 1]),
        3 => Ok(vec![0, 1, 2]),
        4 if header.sizes[0] == 1 => Ok(vec![1, 2, 3]),
        _ => Err(ReadError::unsupported(
            path,
            format!(
                "{}-D NRRD with sizes {:?} (read: 2-D, 3-D, and 4-D with a first axis of size 1)",
                header.dimension, header.sizes
            ),
        )),
    }
}

fn geometry(
    path: &Path,
    header: &Header,
    axes: &[usize],
    warnings: &mut Vec<String>,
) -> Result<Geometry> {
    let (mut steps, origin) = match &header.space_directions {
        Some(directions) => from_space_directions(path, header, directions, axes, warnings)?,
        None => from_spacings(path, header, axes, warnings)?,
    };
    if let [a, b] = steps[..] {
        // A 2-D image is one slice of unit thickness, its normal completing a right-handed set.
        steps.push(a.cross(b).normalize_or_zero());
    }
    let mut dims = [1usize; 3];
    for (dim, &axis) in dims.iter_mut().zip(axes) {
        // Each size fits: check_dims has accepted their product as a usize.
        *dim = usize::try_from(header.sizes[axis]).unwrap_or(usize::MAX);
    }
    let spacing = DVec3::new(steps[0].length(), steps[1].length(), steps[2].length());
    let direction = DMat3::from_cols(
        steps[0] / spacing.x,
        steps[1] / spacing.y,
        steps[2] / spacing.z,
    );
    Geometry::new(dims, spacing, origin, direction)
        .map_err(|e| ReadError::format(path, format!("the header's geometry is invalid: {e}")))
}

/// World steps (spacing × direction, LPS) of the spatial axes and the origin, from
/// `space directions` and `space origin`.
fn from_space_directions(
    path: &Path,
    header: &Header,
    directions: &[Option<[f64; 3]>],
    axes: &[usize],
    warnings: &mut Vec<String>,
) -> Result<(Vec<DVec3>, DVec3)> {
    let lps_from_space = lps_from_space(path, header, warnings)?;
    if header.spacings.is_some() {
        warnings.push(format!(
            "{}: the header gives both space directions and spacings, which the NRRD format \
             forbids; the spacings were ignored",
            path.display()
        ));
    }
    if let Some(units) = &header.space_units {
        if units.iter().any(|u| !u.is_empty() && u != "mm") {
            warnings.push(format!(
                "{}: space units {units:?} were read as millimetres",
                path.display()
            ));
        }
    }
    let steps = axes
        .iter()
        .map(|&axis| match directions[axis] {
            Some(v) => Ok(lps_from_space * DVec3::from(v)),
            None => Err(ReadError::format(
                path,
                format!("space directions: axis {axis} is an image axis but its direction is none"),
            )),
        })
        .collect::<Result<Vec<_>>>()?;
    let origin = header.space_origin.map_or(DVec3::ZERO, DVec3::from);
    Ok((steps, lps_from_space * origin))
}

/// The matrix taking the header's space to LPS.
fn lps_from_space(path: &Path, header: &Header, warnings: &mut Vec<String>) -> Result<DMat3> {
    if let Some(d) = header.space_dimension.filter(|&d| d != 3) {
        return Err(ReadError::unsupported(
            path,
            format!("NRRD space dimension {d} (read: 3)"),
        ));
    }
    let flip = |x: f64, y: f64| DMat3::from_diagonal(DVec3::new(x, y, 1.0));
    let not_anatomical = match &header.space {
        Some(Space::Lps) => return Ok(DMat3::IDENTITY),
        Some(Space::Ras) => return Ok(flip(-1.0, -1.0)),
        Some(Space::Las) => return Ok(flip(1.0, -1.0)),
        Some(Space::NonAnatomical(name)) => format!("space {name:?}"),
        None => "no space field".to_owned(),
    };
    warnings.push(format!(
        "{}: {not_anatomical} gives no patient orientation; the grid was read as if its \
         frame were LPS, so left/right, front/back and up/down may be wrong",
        path.display()
    ));
    Ok(DMat3::IDENTITY)
}

/// World steps and origin of an axis-aligned grid from `spacings` and `axis mins`.
fn from_spacings(
    path: &Path,
    header: &Header,
    axes: &[usize],
    warnings: &mut Vec<String>,
) -> Result<(Vec<DVec3>, DVec3)> {
    if let Some(space) = &header.space {
        warnings.push(format!(
            "{}: the header declares space {:?} but gives spacings instead of space \
             directions, which the NRRD format forbids (ITK refuses such files); it was read \
             as an axis-aligned grid",
            path.display(),
            space.name()
        ));
    }
    if header.space.is_none() && header.spacings.is_some() {
        warnings.push(format!(
            "{}: the header declares no patient orientation (spacings without a space); read as \
             axis-aligned LPS (give the orientation, e.g. LPI, if you know it)",
            path.display()
        ));
    }
    let Some(spacings) = &header.spacings else {
        warnings.push(format!(
            "{}: the header gives neither space directions nor spacings: 1 mm voxels assumed",
            path.display()
        ));
        return Ok((
            vec![DVec3::X, DVec3::Y, DVec3::Z][..axes.len()].to_vec(),
            DVec3::ZERO,
        ));
    };
    let mut steps = Vec::with_capacity(3);
    let mut origin = DVec3::ZERO;
    for (n, &axis) in axes.iter().enumerate() {
        let spacing = axis_spacing(path, spacings[axis], axis, warnings)?;
        // A negative spacing means the axis runs backwards.
        steps.push(DVec3::AXES[n] * spacing);
        let min = header.axis_mins.as_ref().map_or(f64::NAN, |m| m[axis]);
        if min.is_finite() {
            let cell = header.centers.as_ref().and_then(|c| c[axis]) == Some(Center::Cell);
            // `axis mins` is the low edge of the first cell for cell-centred samples.
            origin[n] = if cell { min + spacing.abs() / 2.0 } else { min };
        }
    }
    Ok((steps, origin))
}

fn axis_spacing(path: &Path, spacing: f64, axis: usize, warnings: &mut Vec<String>) -> Result<f64> {
    if spacing.is_nan() {
        warnings.push(format!(
            "{}: axis {axis} has no spacing (nan): 1 mm assumed",
            path.display()
        ));
        return Ok(1.0);
    }
    if !spacing.is_finite() || spacing == 0.0 {
        return Err(ReadError::format(
            path,
            format!(
                "spacings: axis {axis} has spacing {spacing}, expected a finite non-zero number"
            ),
        ));
    }
    Ok(spacing)
}

fn endian(path: &Path, header: &Header, warnings: &mut Vec<String>) -> Endian {
    if header.encoding == Encoding::Ascii {
        // Numbers in text have no byte order; the decoder hands them on little-endian.
        return Endian::Little;
    }
    header.endian.unwrap_or_else(|| {
        if header.element.size() > 1 {
            warnings.push(format!(
                "{}: no endian field for {} samples: little-endian assumed",
                path.display(),
                header.element.name()
            ));
        }
        Endian::Little
    })
}

/// E.g. `int16 big-endian, raw, 113 data files`.
fn stored_type(header: &Header, endian: Endian) -> String {
    let mut text = header.element.name().to_owned();
    if header.element.size() > 1 && header.encoding != Encoding::Ascii {
        text += match endian {
            Endian::Little => " little-endian",
            Endian::Big => " big-endian",
        };
    }
    text += ", ";
    text += header.encoding.name();
    if let DataFiles::Many { names, .. } = &header.data {
        text += &format!(", {} data files", names.len());
    }
    text
}
