//! Writing a volume as an attached, gzip-compressed NRRD in the LPS frame.

use crate::atomic::write_file;
use crate::error::Result;
use endocast_core::{ValueMap, Volume};
use flate2::write::GzEncoder;
use flate2::Compression;
use glam::DVec3;
use std::io::{self, Write};
use std::path::Path;

/// How the samples go into the file. NRRD has no standard rescale field, so the samples must
/// be the physical values themselves.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Samples {
    /// `short`: stored + offset, exact (CT in HU with an integral offset lands here).
    Short { offset: i32 },
    /// `ushort`: stored + offset, exact, for integral values beyond the `short` range.
    UShort { offset: i32 },
    /// `float`: the physical values, for fractional scales and offsets.
    Float,
}

impl Samples {
    fn for_volume(volume: &Volume) -> Self {
        let map = volume.value_map();
        let (lo, hi) = volume.physical_range();
        let exact = map.scale() == 1.0 && map.offset().fract() == 0.0;
        // With scale 1 the offset lies within 65 535 of `lo`, so it fits an i32 when `lo` does.
        let offset = map.offset() as i32;
        if exact && lo >= f64::from(i16::MIN) && hi <= f64::from(i16::MAX) {
            Self::Short { offset }
        } else if exact && lo >= 0.0 && hi <= f64::from(u16::MAX) {
            Self::UShort { offset }
        } else {
            Self::Float
        }
    }

    fn type_name(self) -> &'static str {
        match self {
            Self::Short { .. } => "short",
            Self::UShort { .. } => "ushort",
            Self::Float => "float",
        }
    }

    /// Appends the little-endian bytes of `stored`'s samples to `out`.
    fn encode(self, stored: &[u16], map: ValueMap, out: &mut Vec<u8>) {
        match self {
            // The range checks in `for_volume` make these casts exact.
            Self::Short { offset } => {
                for &s in stored {
                    out.extend_from_slice(&((i32::from(s) + offset) as i16).to_le_bytes());
                }
            }
            Self::UShort { offset } => {
                for &s in stored {
                    out.extend_from_slice(&((i32::from(s) + offset) as u16).to_le_bytes());
                }
            }
            Self::Float => {
                for &s in stored {
                    out.extend_from_slice(&(map.physical(s) as f32).to_le_bytes());
                }
            }
        }
    }
}

/// Samples encoded and compressed per chunk, so writing needs no second copy of the volume.
const CHUNK_SAMPLES: usize = 1 << 16;

/// Writes `volume` to `path` (atomically) as an attached NRRD: gzip encoding, space
/// `left-posterior-superior`, `space directions` = spacing × direction columns, `space origin`.
///
/// NRRD has no standard field for a rescale, so samples are written as physical values:
/// `short` when the value map has scale 1 and an integral offset and every value fits 16 signed
/// bits (CT in HU), `ushort` when they fit 16 unsigned bits instead, and `float` otherwise
/// (a fractional scale or offset): the file then holds the physical values to float precision.
pub fn write(path: &Path, volume: &Volume) -> Result<()> {
    let samples = Samples::for_volume(volume);
    let header = header_text(volume, samples);
    let map = volume.value_map();
    write_file(path, |out| {
        out.write_all(header.as_bytes())?;
        // Level 1: volumes run to hundreds of megabytes; the default level is several times
        // slower for files only slightly smaller.
        let mut gz = GzEncoder::new(out, Compression::fast());
        write_samples(&mut gz, volume.voxels(), map, samples)?;
        gz.finish().map(|_| ())
    })
}

fn write_samples(
    out: &mut impl Write,
    voxels: &[u16],
    map: ValueMap,
    samples: Samples,
) -> io::Result<()> {
    let mut bytes = Vec::with_capacity(CHUNK_SAMPLES * 4);
    for chunk in voxels.chunks(CHUNK_SAMPLES) {
        bytes.clear();
        samples.encode(chunk, map, &mut bytes);
        out.write_all(&bytes)?;
    }
    Ok(())
}

/// `(x,y,z)` with every digit needed to read the same f64 back.
fn vector(v: DVec3) -> String {
    format!("({},{},{})", v.x, v.y, v.z)
}

fn header_text(volume: &Volume, samples: Samples) -> String {
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
        samples.type_name(),
        steps.join(" "),
        vector(geometry.origin_mm()),
    )
}
