//! The NIfTI-1 (348-byte) and NIfTI-2 (540-byte) headers, and the Analyze 7.5 header NIfTI-1
//! grew from: decoding each in either byte order, checking the fields a volume is built from,
//! and encoding the little-endian NIfTI-1 header the writer emits.
//!
//! Field offsets follow `nifti1.h` and `nifti2.h`. NIfTI-2 widens most fields (dims to i64,
//! floats to f64) and reorders them; [`Header`] holds the widened types for all three. A
//! 348-byte header without NIfTI-1's magic is Analyze 7.5 with SPM's reading of its spare
//! fields (`funused1` the scale factor, `funused2` the intercept, `originator` the origin), as
//! nibabel's `Spm2AnalyzeHeader` reads it.

use crate::error::{ReadError, Result};
use crate::samples::{ElementType, Endian};
use std::io::{ErrorKind, Read};
use std::path::Path;

/// Which header a file carries; `sizeof_hdr` (the first four bytes) and the magic tell them
/// apart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Version {
    /// 348-byte header, 16-bit dims, 32-bit floats.
    One,
    /// 540-byte header, 64-bit dims and floats.
    Two,
    /// 348 bytes laid out as NIfTI-1 up to `funused3`, without the magic: always a `.hdr` whose
    /// voxels are in the `.img` beside it; no transform, SPM's fields instead.
    Analyze(SpmFields),
}

/// The fields SPM reads from an Analyze 7.5 header beyond those NIfTI-1 kept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SpmFields {
    /// `originator` read as five int16: the first three are the 1-based voxel at the world
    /// origin (SPM99), or zeros.
    pub origin: [i16; 3],
    /// `cal_min`, `cal_max`: the scaled range, SPM2's fallback scaling with `glmin`, `glmax`.
    pub cal: [f32; 2],
    /// `glmin`, `glmax`: the stored range.
    pub gl: [i32; 2],
}

impl Version {
    /// `sizeof_hdr`: the header's length in bytes.
    pub(super) fn header_size(self) -> usize {
        match self {
            Self::One | Self::Analyze(_) => 348,
            Self::Two => 540,
        }
    }

    /// `NIfTI-1` or `NIfTI-2`.
    pub(super) fn name(self) -> &'static str {
        match self {
            Self::One => "NIfTI-1",
            Self::Two => "NIfTI-2",
            Self::Analyze(_) => "Analyze 7.5",
        }
    }
}

/// `xyzt_units` code for millimetres (the low three bits hold the spatial unit).
pub(super) const UNITS_MM: i32 = 2;
/// Bytes the writer puts before the voxels: the NIfTI-1 header and the 4-byte extension flag.
pub(super) const NIFTI1_VOX_OFFSET: usize = 352;

/// The header fields endocast reads or writes, widened to the NIfTI-2 types.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Header {
    pub version: Version,
    pub endian: Endian,
    /// A `.hdr` whose voxels are in the `.img` beside it (magic `ni1`/`ni2`, or Analyze), not
    /// after it.
    pub paired: bool,
    /// `dim[0]` is the number of dimensions, `dim[1..=dim[0]]` their sizes.
    pub dim: [i64; 8],
    pub datatype: i16,
    pub bitpix: i16,
    /// `pixdim[0]` is qfac (the qform's handedness), `pixdim[1..=3]` the voxel size.
    pub pixdim: [f64; 8],
    /// Byte offset of the first voxel (NIfTI-1 stores it as a float).
    pub vox_offset: f64,
    pub scl_slope: f64,
    pub scl_inter: f64,
    /// The whole `xyzt_units` byte (spatial unit in the low three bits).
    pub xyzt_units: i32,
    pub qform_code: i32,
    pub sform_code: i32,
    /// `quatern_b`, `quatern_c`, `quatern_d`.
    pub quatern: [f64; 3],
    /// `qoffset_x`, `qoffset_y`, `qoffset_z` (mm, RAS).
    pub qoffset: [f64; 3],
    /// `srow_x`, `srow_y`, `srow_z`: the rows of the sform's 3×4 affine (RAS mm from index).
    pub srow: [[f64; 4]; 3],
}

/// Reads exactly one header (348 or 540 bytes) from the start of `reader`.
pub(super) fn read_header(path: &Path, reader: &mut dyn Read) -> Result<Header> {
    let mut bytes = [0u8; 540];
    read_header_bytes(path, reader, &mut bytes[..4], "NIfTI")?;
    let (version, endian) = detect(path, [bytes[0], bytes[1], bytes[2], bytes[3]])?;
    let size = version.header_size();
    read_header_bytes(path, reader, &mut bytes[4..size], version.name())?;
    let fields = Fields {
        bytes: &bytes[..size],
        endian,
    };
    match version {
        Version::Two => decode_nifti2(path, &fields),
        _ if matches!(&bytes[344..348], b"n+1\0" | b"ni1\0") => Ok(decode_nifti1(&fields)),
        _ => Ok(decode_analyze(&Fields {
            endian: analyze_endian(&fields),
            ..fields
        })),
    }
}

fn read_header_bytes(path: &Path, reader: &mut dyn Read, buf: &mut [u8], what: &str) -> Result<()> {
    reader.read_exact(buf).map_err(|e| match e.kind() {
        ErrorKind::UnexpectedEof => {
            ReadError::format(path, format!("the file ends within the {what} header"))
        }
        _ => ReadError::io(path, e),
    })
}

/// NIfTI has no byte-order mark: `sizeof_hdr` reads as 348 or 540 only in the right order.
fn detect(path: &Path, first: [u8; 4]) -> Result<(Version, Endian)> {
    let (le, be) = (i32::from_le_bytes(first), i32::from_be_bytes(first));
    match (le, be) {
        (348, _) => Ok((Version::One, Endian::Little)),
        (_, 348) => Ok((Version::One, Endian::Big)),
        (540, _) => Ok((Version::Two, Endian::Little)),
        (_, 540) => Ok((Version::Two, Endian::Big)),
        _ => Err(ReadError::format(
            path,
            format!(
                "not a NIfTI file: sizeof_hdr is {le} (expected 348 for NIfTI-1 or 540 for NIfTI-2)"
            ),
        )),
    }
}

/// Typed reads at fixed offsets of a complete header buffer.
#[derive(Clone, Copy)]
struct Fields<'a> {
    bytes: &'a [u8],
    endian: Endian,
}

macro_rules! field_reader {
    ($name:ident, $t:ty) => {
        fn $name(&self, at: usize) -> $t {
            let mut raw = [0u8; std::mem::size_of::<$t>()];
            let n = raw.len();
            raw.copy_from_slice(&self.bytes[at..at + n]);
            match self.endian {
                Endian::Little => <$t>::from_le_bytes(raw),
                Endian::Big => <$t>::from_be_bytes(raw),
            }
        }
    };
}

impl Fields<'_> {
    field_reader!(i16, i16);
    field_reader!(i32, i32);
    field_reader!(i64, i64);
    field_reader!(f32, f32);
    field_reader!(f64, f64);

    /// `N` consecutive values read by `get` from `at`, `step` bytes apart.
    fn array<T, const N: usize>(
        &self,
        at: usize,
        step: usize,
        get: fn(&Self, usize) -> T,
    ) -> [T; N] {
        std::array::from_fn(|n| get(self, at + n * step))
    }

    fn f32_wide(&self, at: usize) -> f64 {
        f64::from(self.f32(at))
    }

    fn i16_wide(&self, at: usize) -> i64 {
        i64::from(self.i16(at))
    }
}

/// Whether the magic `found` is a pair's (`.hdr` + `.img`) rather than a single file's.
fn check_magic(
    path: &Path,
    found: &[u8],
    single: &[u8],
    pair: &[u8],
    version: &str,
) -> Result<bool> {
    if found == single || found == pair {
        Ok(found == pair)
    } else {
        Err(ReadError::format(
            path,
            format!(
                "bad {version} magic \"{}\", expected \"{}\"",
                found.escape_ascii(),
                single.escape_ascii()
            ),
        ))
    }
}

fn decode_nifti1(f: &Fields) -> Header {
    Header {
        version: Version::One,
        endian: f.endian,
        paired: &f.bytes[344..348] == b"ni1\0",
        dim: f.array(40, 2, Fields::i16_wide),
        datatype: f.i16(70),
        bitpix: f.i16(72),
        pixdim: f.array(76, 4, Fields::f32_wide),
        vox_offset: f.f32_wide(108),
        scl_slope: f.f32_wide(112),
        scl_inter: f.f32_wide(116),
        xyzt_units: i32::from(f.bytes[123]),
        qform_code: i32::from(f.i16(252)),
        sform_code: i32::from(f.i16(254)),
        quatern: f.array(256, 4, Fields::f32_wide),
        qoffset: f.array(268, 4, Fields::f32_wide),
        srow: [280, 296, 312].map(|at| f.array(at, 4, Fields::f32_wide)),
    }
}

/// The NIfTI-1 fields Analyze shares (`funused1` and `funused2` are SPM's `scl_slope` and
/// `scl_inter`); the units (a string nibabel ignores) are taken as mm, and no transform is set.
fn decode_analyze(f: &Fields) -> Header {
    Header {
        version: Version::Analyze(SpmFields {
            origin: f.array(253, 2, Fields::i16),
            cal: [f.f32(128), f.f32(124)],
            gl: [f.i32(144), f.i32(140)],
        }),
        paired: true,
        xyzt_units: UNITS_MM,
        qform_code: 0,
        sform_code: 0,
        quatern: [0.0; 3],
        qoffset: [0.0; 3],
        srow: [[0.0; 4]; 3],
        ..decode_nifti1(f)
    }
}

/// Analyze's byte order as nibabel guesses it: the one in which `dim[0]` is 1 to 7, else the
/// one in which `sizeof_hdr` is 348 (`f.endian`).
fn analyze_endian(f: &Fields) -> Endian {
    [Endian::Little, Endian::Big]
        .into_iter()
        .find(|&endian| (1..=7).contains(&Fields { endian, ..*f }.i16(40)))
        .unwrap_or(f.endian)
}

fn decode_nifti2(path: &Path, f: &Fields) -> Result<Header> {
    let paired = check_magic(path, &f.bytes[4..8], b"n+2\0", b"ni2\0", "NIfTI-2")?;
    Ok(Header {
        version: Version::Two,
        endian: f.endian,
        paired,
        dim: f.array(16, 8, Fields::i64),
        datatype: f.i16(12),
        bitpix: f.i16(14),
        pixdim: f.array(104, 8, Fields::f64),
        // An i64 offset: exact as f64 for any file that fits on a disk (< 2^53 bytes).
        vox_offset: f.i64(168) as f64,
        scl_slope: f.f64(176),
        scl_inter: f.f64(184),
        xyzt_units: f.i32(500),
        qform_code: f.i32(344),
        sform_code: f.i32(348),
        quatern: f.array(352, 8, Fields::f64),
        qoffset: f.array(376, 8, Fields::f64),
        srow: [400, 432, 464].map(|at| f.array(at, 8, Fields::f64)),
    })
}

/// The NIfTI `datatype` codes of the scalar types endocast reads and writes.
const DATATYPES: [(i16, ElementType); 10] = [
    (2, ElementType::U8),
    (4, ElementType::I16),
    (8, ElementType::I32),
    (16, ElementType::F32),
    (64, ElementType::F64),
    (256, ElementType::I8),
    (512, ElementType::U16),
    (768, ElementType::U32),
    (1024, ElementType::I64),
    (1280, ElementType::U64),
];

/// The NIfTI `datatype` code of a sample type.
pub(super) fn datatype_code(element: ElementType) -> i16 {
    DATATYPES
        .iter()
        .find(|(_, ty)| *ty == element)
        .map_or(0, |(code, _)| *code)
}

impl Header {
    /// The sample type `datatype` names; RGB, complex and the rest are unsupported.
    pub(super) fn element_type(&self, path: &Path) -> Result<ElementType> {
        if let Some((_, ty)) = DATATYPES.iter().find(|(code, _)| *code == self.datatype) {
            return Ok(*ty);
        }
        let code = self.datatype;
        let name = match code {
            1 => " (binary)",
            32 => " (complex64)",
            128 => " (RGB24)",
            1536 => " (float128)",
            1792 => " (complex128)",
            2048 => " (complex256)",
            2304 => " (RGBA32)",
            _ => "",
        };
        Err(ReadError::unsupported(
            path,
            format!(
                "{} datatype {code}{name}: only scalar integer and float voxels are read",
                self.version.name()
            ),
        ))
    }

    /// The size of the first 3-D volume and the number of 3-D volumes the file holds,
    /// validated: `dim[0]` must be 2 (one slice) to 7, every used `dim[n]` positive. Extra
    /// dimensions (time, components) are dropped with a warning.
    pub(super) fn volume_dims(
        &self,
        path: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<([u64; 3], u64)> {
        let rank = self.dim[0];
        if !(1..=7).contains(&rank) {
            return Err(ReadError::format(
                path,
                format!("dim[0] = {rank}: expected the number of dimensions, 1 to 7"),
            ));
        }
        if rank < 2 {
            return Err(ReadError::unsupported(
                path,
                format!("a 1-D {} image (dim[0] = 1)", self.version.name()),
            ));
        }
        let mut sizes = [1u64; 7];
        for (n, size) in sizes.iter_mut().enumerate().take(rank as usize) {
            let d = self.dim[n + 1];
            *size = u64::try_from(d).ok().filter(|&d| d > 0).ok_or_else(|| {
                ReadError::format(
                    path,
                    format!("dim[{}] = {d}: sizes must be positive", n + 1),
                )
            })?;
        }
        let extra = sizes[3..]
            .iter()
            .fold(1u64, |acc, &d| acc.saturating_mul(d));
        if extra > 1 {
            warnings.push(format!(
                "{}: the image has {extra} volumes (dims {:?}); only the first is read",
                path.display(),
                &self.dim[1..=rank as usize]
            ));
        }
        Ok(([sizes[0], sizes[1], sizes[2]], extra))
    }

    /// The byte offset of the first voxel, validated: a whole number, not inside the header.
    pub(super) fn data_offset(&self, path: &Path) -> Result<u64> {
        // A pair's voxels are in their own file, from its first byte by default.
        let min = if self.paired {
            0.0
        } else {
            self.version.header_size() as f64
        };
        let offset = self.vox_offset;
        if !offset.is_finite() || offset.fract() != 0.0 || offset < min || offset > 2f64.powi(53) {
            return Err(ReadError::format(
                path,
                format!("vox_offset {offset} must be a whole number of bytes, at least {min}"),
            ));
        }
        Ok(offset as u64)
    }

    /// Encodes a little-endian single-file NIfTI-1 header followed by a zero extension flag.
    /// Fails when a value does not fit the NIfTI-1 field (dims above 32 767).
    pub(super) fn encode_nifti1(&self) -> Result<[u8; NIFTI1_VOX_OFFSET], String> {
        let mut b = [0u8; NIFTI1_VOX_OFFSET];
        let mut put = |at: usize, bytes: &[u8]| b[at..at + bytes.len()].copy_from_slice(bytes);
        let f32_at = |v: f64| (v as f32).to_le_bytes();
        put(0, &348i32.to_le_bytes());
        put(38, b"r");
        for (n, &d) in self.dim.iter().enumerate() {
            let d =
                i16::try_from(d).map_err(|_| format!("dimension {d} exceeds NIfTI-1's 32767"))?;
            put(40 + 2 * n, &d.to_le_bytes());
        }
        put(70, &self.datatype.to_le_bytes());
        put(72, &self.bitpix.to_le_bytes());
        for (n, &p) in self.pixdim.iter().enumerate() {
            put(76 + 4 * n, &f32_at(p));
        }
        put(108, &f32_at(self.vox_offset));
        put(112, &f32_at(self.scl_slope));
        put(116, &f32_at(self.scl_inter));
        put(
            123,
            &[u8::try_from(self.xyzt_units).map_err(|_| "bad xyzt_units")?],
        );
        put(148, b"endocast");
        put(
            252,
            &i16::try_from(self.qform_code)
                .map_err(|_| "bad qform_code")?
                .to_le_bytes(),
        );
        put(
            254,
            &i16::try_from(self.sform_code)
                .map_err(|_| "bad sform_code")?
                .to_le_bytes(),
        );
        for (n, &v) in self.quatern.iter().chain(&self.qoffset).enumerate() {
            put(256 + 4 * n, &f32_at(v));
        }
        for (n, &v) in self.srow.iter().flatten().enumerate() {
            put(280 + 4 * n, &f32_at(v));
        }
        put(344, b"n+1\0");
        Ok(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Header {
        Header {
            version: Version::One,
            endian: Endian::Little,
            paired: false,
            dim: [3, 4, 5, 6, 1, 1, 1, 1],
            datatype: 4,
            bitpix: 16,
            pixdim: [-1.0, 0.5, 0.75, 2.0, 0.0, 0.0, 0.0, 0.0],
            vox_offset: 352.0,
            scl_slope: 2.0,
            scl_inter: -3.5,
            xyzt_units: UNITS_MM,
            qform_code: 1,
            sform_code: 2,
            quatern: [0.0, 0.5, 0.5],
            qoffset: [1.0, -2.0, 3.0],
            srow: [
                [1.0, 0.0, 0.0, 4.0],
                [0.0, 2.0, 0.0, 5.0],
                [0.0, 0.0, 3.0, 6.0],
            ],
        }
    }

    #[test]
    fn nifti1_encoding_decodes_to_the_same_header() {
        let h = sample();
        let bytes = h.encode_nifti1().unwrap();
        let back = read_header(Path::new("t.nii"), &mut &bytes[..]).unwrap();
        assert_eq!(back, h);
    }

    #[test]
    fn oversized_dims_do_not_encode() {
        let mut h = sample();
        h.dim[1] = 40_000;
        assert!(h.encode_nifti1().is_err());
    }

    #[test]
    fn dims_are_validated() {
        let p = Path::new("t.nii");
        let mut w = Vec::new();
        let mut h = sample();
        h.dim = [4, 2, 3, 4, 5, 1, 1, 1];
        assert_eq!(h.volume_dims(p, &mut w).unwrap(), ([2, 3, 4], 5));
        assert_eq!(w.len(), 1);
        h.dim = [2, 7, 9, 0, 0, 0, 0, 0];
        assert_eq!(h.volume_dims(p, &mut w).unwrap(), ([7, 9, 1], 1));
        for bad in [
            [3, 2, 0, 4, 1, 1, 1, 1],
            [3, 2, -3, 4, 1, 1, 1, 1],
            [9, 1, 1, 1, 1, 1, 1, 1],
        ] {
            h.dim = bad;
            assert!(h.volume_dims(p, &mut w).is_err());
        }
    }
}
