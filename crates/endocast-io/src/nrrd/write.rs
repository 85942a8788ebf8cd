//! Writing a volume as an attached, gzip-compressed NRRD in the LPS frame.

use crate::atomic::write_file;
use crate::encode::SampleEncoding;
use crate::error::Result;
use crate::samples::ElementType;
use endocast_core::Volume;
use flate2::write::GzEncoder;
use flate2::Compression;
use glam::DVec3;
use std::path::Path;

/// The sample encoding for NRRD, which has no standard rescale field: the samples must be the
/// physical values themselves (never [`SampleEncoding::U16Stored`]).
fn encoding(volume: &Volume) -> SampleEncoding {
    SampleEncoding::exact_integer(volume).unwrap_or(SampleEncoding::F32Physical)
}

/// The NRRD `type` of an encoding's samples.
fn type_name(encoding: SampleEncoding) -> &'static str {
    match encoding.element_type() {
        ElementType::I16 => "short",
        ElementType::U16 => "ushort",
        _ => "float",
    }
}

/// Writes `volume` to `path` (atomically) as an attached NRRD: gzip encoding, space
/// `left-posterior-superior`, `space directions` = spacing × direction columns, `space origin`.
///
/// NRRD has no standard field for a rescale, so samples are written as physical values:
/// `short` when the value map has scale 1 and an integral offset and every value fits 16 signed
/// bits (CT in HU), `ushort` when they fit 16 unsigned bits instead, and `float` otherwise
/// (a fractional scale or offset): the file then holds the physical values to float precision.
pub fn write(path: &Path, volume: &Volume) -> Result<()> {
    let samples = encoding(volume);
    let header = header_text(volume, samples);
    write_file(path, |out| {
        out.write_all(header.as_bytes())?;
        // Level 1: volumes run to hundreds of megabytes; the default level is several times
        // slower for files only slightly smaller.
        let mut gz = GzEncoder::new(out, Compression::fast());
        samples.write_voxels(volume, &mut gz)?;
        gz.finish().map(|_| ())
    })
}

/// `(x,y,z)` with every digit needed to read the same f64 back.
fn vector(v: DVec3) -> String {
    format!("({},{},{})", v.x, v.y, v.z)
}

fn header_text(volume: &Volume, samples: SampleEncoding) -> String {
    let geometry = volume.geometry();
    let [nx, ny, nz] = geometry.dims();
    let direction = geometry.direction();
    let spacing = geometry.spacing_mm();
    let steps = [
        vector(direction.x_axis * spacing.x),
        vector(direction.y_axis * spacing.y),
        vector(direction.z_axis * spacing.z),
    ];
    format!(
        "NRRD0004\n\
         # Complete NRRD file format specification at:\n\
         # http://teem.sourceforge.net/nrrd/format.html\n\
         # Written by endocast.\n\
         type: {}\n\
         dimension: 3\n\
         space: left-posterior-superior\n\
         sizes: {nx} {ny} {nz}\n\
         space directions: {}\n\
         kinds: domain domain domain\n\
         endian: little\n\
         encoding: gzip\n\
         space origin: {}\n\n",
        type_name(samples),
        steps.join(" "),
        vector(geometry.origin_mm()),
    )
}
