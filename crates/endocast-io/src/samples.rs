//! Turning a stream of typed samples (any integer or float type, either byte order) into the
//! volume's `u16` voxels and the [`ValueMap`] back to physical values. Shared by every reader of
//! headerless sample blocks: NIfTI, NRRD, MetaImage and raw.

use crate::error::{ReadError, Result};
use endocast_core::ValueMap;
use std::io::{ErrorKind, Read};
use std::path::Path;

/// The type of one stored sample in a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)] // the names are the types
pub enum ElementType {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    F32,
    F64,
}

impl ElementType {
    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            Self::U8 | Self::I8 => 1,
            Self::U16 | Self::I16 => 2,
            Self::U32 | Self::I32 | Self::F32 => 4,
            Self::U64 | Self::I64 | Self::F64 => 8,
        }
    }

    /// A short name such as `uint16` or `float32`.
    pub fn name(self) -> &'static str {
        match self {
            Self::U8 => "uint8",
            Self::I8 => "int8",
            Self::U16 => "uint16",
            Self::I16 => "int16",
            Self::U32 => "uint32",
            Self::I32 => "int32",
            Self::U64 => "uint64",
            Self::I64 => "int64",
            Self::F32 => "float32",
            Self::F64 => "float64",
        }
    }

    /// Parses the names [`ElementType::name`] gives (also `u8`, `i16`, `f32`, ... ).
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name.to_ascii_lowercase().as_str() {
            "uint8" | "u8" => Self::U8,
            "int8" | "i8" => Self::I8,
            "uint16" | "u16" => Self::U16,
            "int16" | "i16" => Self::I16,
            "uint32" | "u32" => Self::U32,
            "int32" | "i32" => Self::I32,
            "uint64" | "u64" => Self::U64,
            "int64" | "i64" => Self::I64,
            "float32" | "f32" | "float" => Self::F32,
            "float64" | "f64" | "double" => Self::F64,
            _ => return None,
        })
    }

    /// The smallest value of an 8- or 16-bit integer type: stored = raw − this, exactly.
    fn narrow_integer_min(self) -> Option<f64> {
        match self {
            Self::U8 | Self::U16 => Some(0.0),
            Self::I8 => Some(f64::from(i8::MIN)),
            Self::I16 => Some(f64::from(i16::MIN)),
            _ => None,
        }
    }
}

/// Byte order of multi-byte samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Endian {
    /// Least significant byte first (x86, most files).
    Little,
    /// Most significant byte first (old workstations, the Stanford CThead slices).
    Big,
}

/// The linear map a file declares from raw samples to physical values:
/// `physical = raw * slope + intercept` (DICOM RescaleSlope/Intercept, NIfTI scl_slope/scl_inter).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rescale {
    /// Physical units per raw unit; must be finite and non-zero.
    pub slope: f64,
    /// Physical value of raw 0; must be finite.
    pub intercept: f64,
}

impl Rescale {
    /// Raw values are physical values.
    pub const IDENTITY: Self = Self {
        slope: 1.0,
        intercept: 0.0,
    };
}

/// Samples decoded per chunk: large enough to amortise the read, small enough to stay in cache.
const CHUNK_SAMPLES: usize = 1 << 16;

/// Reads exactly `count` samples of type `ty` from `reader` into `u16` voxels.
///
/// 8- and 16-bit integers are stored exactly (`stored = raw − type minimum`) in one streaming
/// pass, so peak memory is the voxel buffer itself. Wider integers and floats are read whole,
/// then mapped onto 16 bits: exactly when their range holds at most 65 536 integers, otherwise
/// quantised over the range (a warning is pushed). Non-finite float samples become the smallest
/// finite value (also warned). `path` only names the file in errors.
pub fn read_voxels(
    path: &Path,
    reader: &mut dyn Read,
    ty: ElementType,
    endian: Endian,
    count: usize,
    rescale: Rescale,
    warnings: &mut Vec<String>,
) -> Result<(Vec<u16>, ValueMap)> {
    let bad_rescale = || {
        ReadError::format(
            path,
            format!(
                "rescale slope {} / intercept {} must be finite with a non-zero slope, and \
                 keep every {} sample finite",
                rescale.slope,
                rescale.intercept,
                ty.name()
            ),
        )
    };
    let Some(type_min) = ty.narrow_integer_min() else {
        return read_wide(path, reader, ty, endian, count, rescale, warnings);
    };
    let map = ValueMap::new(rescale.slope, rescale.intercept + type_min * rescale.slope)
        .ok()
        .filter(|map| map.physical(u16::MAX).is_finite())
        .ok_or_else(bad_rescale)?;
    let mut voxels = vec![0u16; count];
    let mut bytes = vec![0u8; CHUNK_SAMPLES * ty.size()];
    for (chunk_index, out) in voxels.chunks_mut(CHUNK_SAMPLES).enumerate() {
        let buf = &mut bytes[..out.len() * ty.size()];
        read_exact_or_truncated(path, reader, buf, chunk_index * CHUNK_SAMPLES, count, ty)?;
        convert_narrow(buf, ty, endian, out);
    }
    Ok((voxels, map))
}

fn convert_narrow(bytes: &[u8], ty: ElementType, endian: Endian, out: &mut [u16]) {
    match ty {
        ElementType::U8 => out
            .iter_mut()
            .zip(bytes)
            .for_each(|(o, &b)| *o = u16::from(b)),
        ElementType::I8 => out
            .iter_mut()
            .zip(bytes)
            .for_each(|(o, &b)| *o = u16::from(b ^ 0x80)),
        ElementType::U16 | ElementType::I16 => {
            // Flipping the sign bit maps i16::MIN..=i16::MAX onto 0..=u16::MAX in order.
            let flip = if ty == ElementType::I16 { 0x8000 } else { 0 };
            for (o, pair) in out.iter_mut().zip(bytes.chunks_exact(2)) {
                let raw = match endian {
                    Endian::Little => u16::from_le_bytes([pair[0], pair[1]]),
                    Endian::Big => u16::from_be_bytes([pair[0], pair[1]]),
                };
                *o = raw ^ flip;
            }
        }
        _ => unreachable!("convert_narrow is only called for 8- and 16-bit types"),
    }
}

fn read_exact_or_truncated(
    path: &Path,
    reader: &mut dyn Read,
    buf: &mut [u8],
    samples_before: usize,
    count: usize,
    ty: ElementType,
) -> Result<()> {
    reader.read_exact(buf).map_err(|e| {
        if e.kind() == ErrorKind::UnexpectedEof {
            ReadError::format(
                path,
                format!(
                    "voxel data ends early: expected {count} {} samples ({} bytes), \
                     the data stops within samples {samples_before}..{}",
                    ty.name(),
                    count as u64 * ty.size() as u64,
                    samples_before + buf.len() / ty.size()
                ),
            )
        } else {
            ReadError::io(path, e)
        }
    })
}

fn decode_wide(bytes: &[u8], ty: ElementType, endian: Endian) -> f64 {
    let mut le = [0u8; 8];
    le[..bytes.len()].copy_from_slice(bytes);
    if endian == Endian::Big {
        le[..bytes.len()].reverse();
    }
    let le4 = [le[0], le[1], le[2], le[3]];
    match ty {
        ElementType::U32 => f64::from(u32::from_le_bytes(le4)),
        ElementType::I32 => f64::from(i32::from_le_bytes(le4)),
        ElementType::F32 => f64::from(f32::from_le_bytes(le4)),
        // 64-bit integers beyond 2^53 round to the nearest f64; they are quantised anyway.
        ElementType::U64 => u64::from_le_bytes(le) as f64,
        ElementType::I64 => i64::from_le_bytes(le) as f64,
        ElementType::F64 => f64::from_le_bytes(le),
        _ => unreachable!("decode_wide is only called for 32- and 64-bit types"),
    }
}

/// The value map for finite physical values in `[lo, hi]`, or a clear error when 16 bits
/// cannot span the range: wider than the largest `f64` (values of ±1e308, as a misread
/// datatype or byte order gives) or too narrow for a non-zero step.
fn wide_value_map(
    path: &Path,
    ty: ElementType,
    lo: f64,
    hi: f64,
    integral: bool,
) -> Result<ValueMap> {
    let problem = if !(hi - lo).is_finite() {
        "a range wider than the largest floating-point number, which 16-bit voxels cannot \
         represent (a wrong datatype or byte order in the header?)"
    } else {
        "a range too narrow for 16-bit voxels to resolve"
    };
    ValueMap::fitting(lo, hi, integral)
        .ok()
        .filter(|map| map.physical(u16::MAX).is_finite())
        .ok_or_else(|| {
            ReadError::format(
                path,
                format!(
                    "the {} sample values span [{lo:e}, {hi:e}]: {problem}",
                    ty.name()
                ),
            )
        })
}

fn read_wide(
    path: &Path,
    reader: &mut dyn Read,
    ty: ElementType,
    endian: Endian,
    count: usize,
    rescale: Rescale,
    warnings: &mut Vec<String>,
) -> Result<(Vec<u16>, ValueMap)> {
    let mut bytes = vec![0u8; count * ty.size()];
    read_exact_or_truncated(path, reader, &mut bytes, 0, count, ty)?;
    let physical = |raw: &[u8]| decode_wide(raw, ty, endian) * rescale.slope + rescale.intercept;
    let (mut lo, mut hi, mut non_finite) = (f64::INFINITY, f64::NEG_INFINITY, 0usize);
    let mut integral = true;
    for raw in bytes.chunks_exact(ty.size()) {
        let v = physical(raw);
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
            integral &= v.fract() == 0.0;
        } else {
            non_finite += 1;
        }
    }
    if lo > hi {
        return Err(ReadError::format(
            path,
            "no finite sample value: every voxel is NaN or infinite",
        ));
    }
    if non_finite > 0 {
        warnings.push(format!(
            "{}: {non_finite} NaN or infinite samples were set to the minimum {lo}",
            path.display()
        ));
    }
    let map = wide_value_map(path, ty, lo, hi, integral)?;
    if map.scale() != 1.0 {
        warnings.push(format!(
            "{}: {} values in [{lo}, {hi}] quantised to 16 bits (step {:.3e})",
            path.display(),
            ty.name(),
            map.scale()
        ));
    }
    let voxels = bytes
        .chunks_exact(ty.size())
        .map(|raw| {
            let v = physical(raw);
            map.quantize(if v.is_finite() { v } else { lo })
        })
        .collect();
    Ok((voxels, map))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(
        bytes: &[u8],
        ty: ElementType,
        endian: Endian,
        n: usize,
    ) -> Result<(Vec<u16>, ValueMap)> {
        let mut w = Vec::new();
        read_voxels(
            Path::new("t"),
            &mut &bytes[..],
            ty,
            endian,
            n,
            Rescale::IDENTITY,
            &mut w,
        )
    }

    #[test]
    fn signed_16_bit_both_endians_is_exact() {
        let values: [i16; 4] = [-1500, -1, 0, 2121];
        let le: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let be: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
        for (bytes, endian) in [(le, Endian::Little), (be, Endian::Big)] {
            let (vox, map) = read(&bytes, ElementType::I16, endian, 4).unwrap();
            let back: Vec<f64> = vox.iter().map(|&s| map.physical(s)).collect();
            assert_eq!(back, vec![-1500.0, -1.0, 0.0, 2121.0]);
        }
    }

    #[test]
    fn rescale_applies_to_narrow_types() {
        let bytes = [0u8, 0, 0xff, 0x0f]; // u16 LE 0 and 4095
        let mut w = Vec::new();
        let rescale = Rescale {
            slope: 1.0,
            intercept: -1024.0,
        };
        let (vox, map) = read_voxels(
            Path::new("t"),
            &mut &bytes[..],
            ElementType::U16,
            Endian::Little,
            2,
            rescale,
            &mut w,
        )
        .unwrap();
        assert_eq!(map.physical(vox[0]), -1024.0);
        assert_eq!(map.physical(vox[1]), 3071.0);
    }

    #[test]
    fn floats_quantise_and_warn() {
        let values = [0.0f32, 0.5, 1.0, f32::NAN];
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut w = Vec::new();
        let (vox, map) = read_voxels(
            Path::new("t"),
            &mut &bytes[..],
            ElementType::F32,
            Endian::Little,
            4,
            Rescale::IDENTITY,
            &mut w,
        )
        .unwrap();
        assert!((map.physical(vox[1]) - 0.5).abs() < 1e-4);
        assert_eq!(map.physical(vox[3]), 0.0);
        assert_eq!(w.len(), 2);
    }

    #[test]
    fn integral_wide_values_stay_exact() {
        let values = [-70_000i32, -69_000];
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
        let (vox, map) = read(&bytes, ElementType::I32, Endian::Big, 2).unwrap();
        assert_eq!(map.physical(vox[0]), -70_000.0);
        assert_eq!(map.physical(vox[1]), -69_000.0);
    }

    #[test]
    fn extreme_floats_are_a_clear_error() {
        let values = [-1e308f64, 0.0, 1e308];
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let err = read(&bytes, ElementType::F64, Endian::Little, 3)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("t: the float64 sample values span [-1e308, 1e308]"),
            "{err}"
        );
        let tiny = [0.0f64, 1e-320];
        let bytes: Vec<u8> = tiny.iter().flat_map(|v| v.to_le_bytes()).collect();
        let err = read(&bytes, ElementType::F64, Endian::Little, 2).unwrap_err();
        assert!(err.to_string().contains("too narrow"), "{err}");
        // Extreme but spanning less than f64::MAX: quantised, with a warning.
        let wide = [-1e307f64, 1.5e308];
        let bytes: Vec<u8> = wide.iter().flat_map(|v| v.to_le_bytes()).collect();
        let (vox, map) = read(&bytes, ElementType::F64, Endian::Little, 2).unwrap();
        assert_eq!(map.physical(vox[0]), -1e307);
        assert!((map.physical(vox[1]) / 1.5e308 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn truncation_and_bad_rescale_are_errors() {
        assert!(read(&[1, 2, 3], ElementType::U16, Endian::Little, 2).is_err());
        assert!(read(&[1, 2, 3], ElementType::F32, Endian::Little, 1).is_err());
        let mut w = Vec::new();
        let nan = Rescale {
            slope: f64::NAN,
            intercept: 0.0,
        };
        assert!(read_voxels(
            Path::new("t"),
            &mut &[0u8][..],
            ElementType::U8,
            Endian::Little,
            1,
            nan,
            &mut w
        )
        .is_err());
    }
}
