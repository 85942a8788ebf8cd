//! MetaImage (ITK's MetaIO format): `.mha` with the voxels after the header
//! (`ElementDataFile = LOCAL`), or a `.mhd` header beside a `.raw` / `.zraw` data file (a regular
//! file in the header's folder or below it).
//!
//! World coordinates are LPS, as in ITK, so the geometry needs no conversion: `Offset` is the
//! origin, `ElementSpacing` the spacing and `TransformMatrix` the direction (see
//! [`Header::direction_columns`] for how its nine numbers map onto the axes).
//! `AnatomicalOrientation` is recorded in the header and checked against the matrix (a
//! contradiction is a warning; the matrix wins). Compressed data are one zlib stream, read to
//! its end so that its Adler-32 checksum is checked; a stream that inflates to more bytes than
//! the voxels, or that does not fill its CompressedDataSize, is corrupt.
//! MetaImage names no modality, so volumes are [`Modality::Unknown`].

mod header;
mod write;

pub use header::{read_header, DataFile, DataStart, Header};
pub use write::write;

use crate::compressed;
use crate::detached;
use crate::error::{ReadError, Result};
use crate::loaded::{Format, Loaded, OpenOptions, SourceInfo};
use crate::samples::{read_voxels, Endian, Rescale};
use endocast_core::{Geometry, Modality, Volume};
use flate2::bufread::ZlibDecoder;
use glam::{DMat3, DVec3};
use std::fs::File;
use std::io::{self, BufReader, Read, Seek, SeekFrom, Take};
use std::path::Path;

/// Reads a MetaImage volume (`.mha`, or `.mhd` with its data file).
///
/// Errors: a header that is not key = value text ending with `ElementDataFile` within 1 MiB,
/// malformed or missing DimSize / NDims / ElementType, vector or text voxels and per-slice
/// file lists (unsupported), a missing data file, data that end early or do not inflate, and
/// more voxels than `options.limits` allow.
pub fn read(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    let header = read_header(path)?;
    let count = options.limits.check_dims(path, &header.dims)?;
    let mut warnings = Vec::new();
    let geometry = geometry(path, &header)?;
    check_orientation(path, &header, &geometry, &mut warnings);

    let data_path = match &header.data_file {
        DataFile::Local => path,
        DataFile::Detached(file) => file.as_path(),
    };
    let mut data = open_data(path, data_path, &header, count, options, &mut warnings)?;
    let (voxels, map) = read_voxels(
        data_path,
        &mut data,
        header.element,
        header.endian,
        count,
        Rescale::IDENTITY,
        &mut warnings,
    )
    .map_err(|e| match data {
        Data::Zlib(_) => compressed::io_as_corrupt(e, "zlib"),
        Data::Plain(_) => e,
    })?;
    data.finish(data_path)?;
    let volume = Volume::new(geometry, voxels, map, Modality::Unknown)
        .map_err(|e| ReadError::format(path, e.to_string()))?;
    Ok(Loaded {
        volume,
        source: SourceInfo::new(Format::MetaImage, stored_type(&header)),
        warnings,
    })
}

/// E.g. `uint8 (MetaImage, zlib)` or `int16 (MetaImage, big-endian)`.
fn stored_type(header: &Header) -> String {
    let mut parts = vec!["MetaImage"];
    if header.endian == Endian::Big {
        parts.push("big-endian");
    }
    if header.compressed {
        parts.push("zlib");
    }
    format!("{} ({})", header.element.name(), parts.join(", "))
}

/// The LPS geometry. A 2-D image's 2×2 matrix keeps both axes in the xy plane, so its
/// third axis (+z) is always independent of them.
fn geometry(path: &Path, header: &Header) -> Result<Geometry> {
    let [c0, c1, c2] = header.direction_columns.map(DVec3::from);
    // check_dims proved the product fits usize, so each factor does.
    let dims = header.dims.map(|d| d as usize);
    Geometry::new(
        dims,
        DVec3::from(header.spacing_mm),
        DVec3::from(header.origin_mm),
        DMat3::from_cols(c0, c1, c2),
    )
    .map_err(|e| {
        ReadError::format(
            path,
            format!("the header does not describe a voxel grid: {e}"),
        )
    })
}

/// ITK's `AnatomicalOrientation` letters for a geometry: for each index axis the side it
/// comes *from* (the opposite of [`Geometry::orientation_code`]), so identity is `RAI`.
fn itk_orientation(geometry: &Geometry) -> String {
    geometry
        .orientation_code()
        .chars()
        .map(opposite_side)
        .collect()
}

fn opposite_side(side: char) -> char {
    match side {
        'L' => 'R',
        'R' => 'L',
        'P' => 'A',
        'A' => 'P',
        'S' => 'I',
        'I' => 'S',
        other => other,
    }
}

/// Warns when `AnatomicalOrientation` names other sides than the matrix implies. Letters
/// other than RLAPIS (e.g. `?`) are not compared.
fn check_orientation(
    path: &Path,
    header: &Header,
    geometry: &Geometry,
    warnings: &mut Vec<String>,
) {
    let Some(given) = &header.anatomical_orientation else {
        return;
    };
    let expected = itk_orientation(geometry);
    let contradicts = given
        .to_ascii_uppercase()
        .chars()
        .zip(expected.chars())
        .any(|(g, e)| "RLAPIS".contains(g) && g != e);
    if contradicts {
        warnings.push(format!(
            "{}: AnatomicalOrientation {given} contradicts the TransformMatrix (which implies \
             {expected} in ITK's convention); the matrix was used",
            path.display()
        ));
    }
}

/// The voxel bytes of the data file: the stored bytes, or the zlib stream inflating them.
enum Data {
    Plain(Take<BufReader<File>>),
    Zlib(ZlibDecoder<Take<BufReader<File>>>),
}

impl Read for Data {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self {
            Self::Plain(reader) => reader.read(buf),
            Self::Zlib(reader) => reader.read(buf),
        }
    }
}

impl Data {
    /// After the voxels: a zlib stream must end (checksum checked) without inflating more,
    /// and exactly where its stored bytes end.
    fn finish(self, path: &Path) -> Result<()> {
        let Self::Zlib(mut decoder) = self else {
            return Ok(());
        };
        compressed::finish(path, &mut decoder, "zlib", 0)?;
        let trailing =
            io::copy(decoder.get_mut(), &mut io::sink()).map_err(|e| ReadError::io(path, e))?;
        if trailing > 0 {
            return Err(ReadError::format(
                path,
                format!(
                    "the zlib data are corrupt: {trailing} stored bytes follow the end of the \
                     stream"
                ),
            ));
        }
        Ok(())
    }
}

/// Opens the data file (`data_path`, named by the header at `path`) positioned at the voxels,
/// bounded to the bytes they may occupy, and inflating when compressed. Lengths are checked
/// before anything is read or allocated; bytes after the data are ignored with a warning.
fn open_data(
    path: &Path,
    data_path: &Path,
    header: &Header,
    count: usize,
    options: &OpenOptions,
    warnings: &mut Vec<String>,
) -> Result<Data> {
    let (base, file_len) = match header.data_file {
        DataFile::Local => (header.text_bytes, file_len(path)?),
        DataFile::Detached(_) => (
            0,
            detached::data_file_len_where(path, data_path, options.allow_outside_data)?,
        ),
    };
    let file = File::open(data_path).map_err(|e| ReadError::io(data_path, e))?;
    let raw_bytes = count as u64 * header.element.size() as u64;
    let ends_early = |start: u64, bytes: u64| {
        ReadError::format(
            data_path,
            format!(
                "the voxel data end early: {bytes} bytes needed from offset {start}, \
                 the file has {file_len}"
            ),
        )
    };
    let stored_bytes = match (header.compressed, header.compressed_size) {
        (false, _) => raw_bytes,
        (true, Some(size)) => size,
        (true, None) if header.data_start == DataStart::AtEnd => {
            return Err(ReadError::format(
                data_path,
                "HeaderSize = -1 with compressed data needs CompressedDataSize",
            ))
        }
        // MetaIO's rule: without CompressedDataSize the stream runs to the end of the file.
        (true, None) => file_len.saturating_sub(base),
    };
    let start = match header.data_start {
        DataStart::Skip(n) => base.saturating_add(n),
        DataStart::AtEnd => file_len
            .checked_sub(stored_bytes)
            .ok_or_else(|| ends_early(0, stored_bytes))?,
    };
    if start.saturating_add(stored_bytes) > file_len {
        return Err(ends_early(start, stored_bytes));
    }
    if header.compressed {
        compressed::check_inflates_to(data_path, "zlib", stored_bytes, raw_bytes)?;
    }
    let surplus = file_len - start - stored_bytes;
    if surplus > 0 {
        warnings.push(format!(
            "{}: {surplus} bytes after the voxel data were ignored",
            data_path.display()
        ));
    }
    let mut file = BufReader::new(file);
    file.seek(SeekFrom::Start(start))
        .map_err(|e| ReadError::io(data_path, e))?;
    let bounded = file.take(stored_bytes);
    Ok(if header.compressed {
        Data::Zlib(ZlibDecoder::new(bounded))
    } else {
        Data::Plain(bounded)
    })
}

fn file_len(path: &Path) -> Result<u64> {
    Ok(std::fs::metadata(path)
        .map_err(|e| ReadError::io(path, e))?
        .len())
}
