//! Decoding the frames of one file straight into their slots of the volume's voxel buffer.
//!
//! Every stored sample word goes through one lookup table built per series ([`SampleMap`]):
//! shift by HighBit, mask to BitsStored, sign-extend, optionally invert (MONOCHROME1), then
//! offset by the type minimum so that the `u16` voxel holds the raw value exactly
//! (`raw = stored + type_min`). The table is 128 KiB for 16-bit data and makes the inner loop
//! one load per voxel.

use super::frame::compressed_frame;
use super::open::{self, chain};
use super::scan::{ImageFile, PixelLayout};
use super::{jpeg12, jpegls, rle, stream_size};
use crate::error::{ReadError, Result};
use crate::guard;
use dicom_core::value::DicomValueType;
use dicom_core::{DicomValue, PrimitiveValue};
use dicom_dictionary_std::tags;
use dicom_encoding::adapters::PixelDataObject;
use dicom_encoding::transfer_syntax::TransferSyntaxIndex;
use dicom_object::DefaultDicomObject;
use dicom_pixeldata::PixelDecoder;
use dicom_transfer_syntax_registry::TransferSyntaxRegistry;
use rayon::prelude::*;
use std::path::Path;

/// The name of transfer syntax `uid` when its pixel data can be decoded here, otherwise
/// [`ReadError::Unsupported`] naming the UID (and the name, when known).
pub(super) fn transfer_syntax_name(path: &Path, uid: &str) -> Result<&'static str> {
    let Some(ts) = TransferSyntaxRegistry.get(uid) else {
        return Err(ReadError::unsupported(
            path,
            format!("transfer syntax {uid} (not a transfer syntax this reader knows)"),
        ));
    };
    if !ts.can_decode_all() && !jpegls::is_jpeg_ls(uid) {
        return Err(ReadError::unsupported(
            path,
            format!(
                "transfer syntax {uid} ({}): no decoder for its pixel data",
                ts.name()
            ),
        ));
    }
    Ok(ts.name())
}

/// How the stored sample words of one series become `u16` voxels.
#[derive(Debug, Clone)]
pub(super) struct SampleMap {
    /// Voxel value of every possible sample word (256 or 65 536 entries).
    table: Vec<u16>,
    /// Voxel value of PixelPaddingValue, when the series declares one.
    padding: Option<u16>,
    /// Raw value of voxel 0: −2^(BitsAllocated−1) for signed samples, else 0.
    type_min: i32,
    /// 1 or 2.
    bytes_per_sample: usize,
}

impl SampleMap {
    /// The map for `layout`; `invert` flips MONOCHROME1 samples so that bright is high.
    /// Refuses colour images and sample sizes other than 8 and 16 bits.
    pub(super) fn new(
        path: &Path,
        layout: &PixelLayout,
        padding: Option<i32>,
        invert: bool,
    ) -> Result<Self> {
        let bits = validate(path, layout)?;
        let allocated = u32::from(layout.bits_allocated);
        let lut = layout.modality_lut.as_ref();
        // A Modality LUT's outputs are unsigned: they are the voxels themselves.
        let type_min = if layout.signed && lut.is_none() {
            -(1i32 << (allocated - 1))
        } else {
            0
        };
        let voxel = |raw| match lut {
            Some(lut) => lut.apply(raw),
            None => bits.voxel(raw, invert, type_min),
        };
        let table = (0..1u32 << allocated)
            .map(|word| voxel(bits.raw(word)))
            .collect();
        let padding = padding.filter(|&p| bits.representable(p)).map(voxel);
        Ok(Self {
            table,
            padding,
            type_min,
            bytes_per_sample: usize::from(layout.bits_allocated / 8),
        })
    }

    /// The largest sample word the table maps (255 for 8-bit samples).
    fn max_word(&self) -> u16 {
        (self.table.len() - 1) as u16
    }

    /// Raw value of voxel value 0: `raw = stored + type_min`.
    pub(super) fn type_min(&self) -> f64 {
        f64::from(self.type_min)
    }

    /// Voxel value that marks padding, if any.
    pub(super) fn padding(&self) -> Option<u16> {
        self.padding
    }

    /// Maps `words` into `out` and measures the result.
    fn convert(&self, words: impl Iterator<Item = u16>, out: &mut [u16]) -> FrameStats {
        for (slot, word) in out.iter_mut().zip(words) {
            *slot = self.table[usize::from(word)];
        }
        self.measure(out)
    }

    /// The statistics of mapped `voxels`.
    pub(super) fn measure(&self, voxels: &[u16]) -> FrameStats {
        let mut stats = FrameStats::EMPTY;
        let padding = self.padding.map_or(u32::MAX, u32::from);
        for &value in voxels {
            if u32::from(value) == padding {
                stats.padding += 1;
            } else {
                stats.min = stats.min.min(value);
                stats.max = stats.max.max(value);
            }
        }
        stats
    }

    /// Maps little-endian sample bytes (as decoders return them) into `out`.
    fn convert_bytes(&self, bytes: &[u8], out: &mut [u16]) -> FrameStats {
        if self.bytes_per_sample == 1 {
            self.convert(bytes.iter().map(|&b| u16::from(b)), out)
        } else {
            let words = bytes
                .chunks_exact(2)
                .map(|pair| u16::from_le_bytes([pair[0], pair[1]]));
            self.convert(words, out)
        }
    }
}

/// BitsStored, HighBit and signedness, validated.
#[derive(Debug, Clone, Copy)]
struct SampleBits {
    stored: u32,
    shift: u32,
    signed: bool,
}

impl SampleBits {
    /// The raw sample value held in `word`.
    fn raw(self, word: u32) -> i32 {
        let mask = (1u32 << self.stored) - 1;
        let value = (word >> self.shift) & mask;
        if self.signed {
            // Move the sign bit to bit 31 and shift back arithmetically.
            let unused = 32 - self.stored;
            ((value << unused) as i32) >> unused
        } else {
            value as i32
        }
    }

    /// Whether `raw` is a value BitsStored can hold.
    fn representable(self, raw: i32) -> bool {
        let (lo, hi) = if self.signed {
            (
                -(1i64 << (self.stored - 1)),
                (1i64 << (self.stored - 1)) - 1,
            )
        } else {
            (0, (1i64 << self.stored) - 1)
        };
        (lo..=hi).contains(&i64::from(raw))
    }

    /// The voxel value of raw sample `raw`, inverted within the BitsStored range if asked.
    fn voxel(self, raw: i32, invert: bool, type_min: i32) -> u16 {
        let raw = match (invert, self.signed) {
            (false, _) => raw,
            (true, true) => -1 - raw,
            (true, false) => ((1i32 << self.stored) - 1) - raw,
        };
        // In range by construction: raw lies within the BitsAllocated range.
        (raw - type_min) as u16
    }
}

fn validate(path: &Path, layout: &PixelLayout) -> Result<SampleBits> {
    if layout.samples_per_pixel != 1 {
        return Err(ReadError::unsupported(
            path,
            format!(
                "SamplesPerPixel {} ({}): only grey-scale images (1 sample per pixel) are volumes",
                layout.samples_per_pixel, layout.photometric
            ),
        ));
    }
    if !matches!(layout.bits_allocated, 8 | 16) {
        return Err(ReadError::unsupported(
            path,
            format!(
                "BitsAllocated {}: only 8- and 16-bit samples are read",
                layout.bits_allocated
            ),
        ));
    }
    if !matches!(
        layout.photometric.as_str(),
        "" | "MONOCHROME1" | "MONOCHROME2"
    ) {
        return Err(ReadError::unsupported(
            path,
            format!(
                "PhotometricInterpretation {}: only MONOCHROME1 and MONOCHROME2 are read",
                layout.photometric
            ),
        ));
    }
    let (allocated, stored, high) = (layout.bits_allocated, layout.bits_stored, layout.high_bit);
    if stored == 0 || stored > allocated || high >= allocated || high + 1 < stored {
        return Err(ReadError::format(
            path,
            format!(
                "BitsStored {stored} / HighBit {high} do not fit BitsAllocated {allocated} \
                 (expected 0 < BitsStored ≤ HighBit + 1 ≤ BitsAllocated)"
            ),
        ));
    }
    Ok(SampleBits {
        stored: u32::from(stored),
        shift: u32::from(high + 1 - stored),
        signed: layout.signed,
    })
}

/// HighBit above BitsStored − 1 (the standard's value): in compressed data an error, since
/// decoders return samples from bit 0 and shifting them would corrupt every value; in
/// uncompressed data the samples are taken where HighBit says (as some old scanners stored
/// them), with a warning, since a corrupt header looks the same. (A HighBit below is refused by
/// [`SampleMap::new`].)
pub(super) fn check_high_bit(file: &ImageFile, warnings: &mut Vec<String>) -> Result<()> {
    let (stored, high) = (file.layout.bits_stored, file.layout.high_bit);
    if u32::from(high) + 1 == u32::from(stored) {
        return Ok(());
    }
    let found = format!(
        "HighBit {high} with BitsStored {stored} (expected HighBit {})",
        stored.saturating_sub(1)
    );
    let compressed = TransferSyntaxRegistry
        .get(&file.transfer_syntax)
        .is_some_and(|ts| ts.is_encapsulated_pixel_data());
    if compressed {
        return Err(ReadError::format(
            &file.path,
            format!("{found}: compressed samples start at bit 0, so the header is wrong (correct HighBit or BitsStored)"),
        ));
    }
    warnings.push(format!(
        "{}: {found}: the samples were taken from bits {}–{high}; if the values look wrong, \
         the header is",
        file.path.display(),
        (high + 1).saturating_sub(stored)
    ));
    Ok(())
}

/// What one decoded frame holds, in voxel values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct FrameStats {
    /// Smallest non-padding voxel value (`u16::MAX` when every voxel is padding).
    pub min: u16,
    /// Largest non-padding voxel value (0 when every voxel is padding).
    pub max: u16,
    /// Number of padding voxels.
    pub padding: usize,
}

impl FrameStats {
    const EMPTY: Self = Self {
        min: u16::MAX,
        max: 0,
        padding: 0,
    };

    /// Whether the frame has any voxel that is not padding.
    pub(super) fn has_values(&self) -> bool {
        self.min <= self.max
    }
}

/// Reads `file` whole and decodes each `(frame number, slot)` into its slot, in parallel for
/// compressed multi-frame files. Returns the statistics of each frame, in the order given, and
/// a warning when the pixel data carried trailing zero padding.
pub(super) fn decode_file(
    file: &ImageFile,
    ts_name: &str,
    frames: Vec<(u32, &mut [u16])>,
    map: &SampleMap,
) -> Result<(Vec<FrameStats>, Option<String>)> {
    let path = file.path.as_path();
    let object = open::open(path, false, file.body)?;
    let pixel_data = object
        .get(tags::PIXEL_DATA)
        .ok_or_else(|| ReadError::format(path, "expected a PixelData element, found none"))?;
    match pixel_data.value() {
        DicomValue::Primitive(value) => {
            let padded = check_native_length(file, value, map)?;
            let stats = frames
                .into_iter()
                .map(|(frame, out)| native_frame(path, value, frame, out, map))
                .collect::<Result<_>>()?;
            Ok((stats, padded))
        }
        DicomValue::PixelSequence(sequence) => {
            check_fragment_count(file, sequence.fragments().len())?;
            let uid = object.meta().transfer_syntax();
            let decode = if jpegls::is_jpeg_ls(uid) {
                jpeg_ls_frame
            } else if rle::is_rle(uid) {
                rle_frame
            } else {
                registry_frame
            };
            let stats = frames
                .into_par_iter()
                .map(|(frame, out)| {
                    decode(&object, frame, out, map).map_err(|e| match e {
                        FrameError::Decode(cause) => ReadError::format(
                            path,
                            format!("cannot decode frame {frame} ({ts_name}): {cause}"),
                        ),
                        FrameError::Short { needed, found } => {
                            short_frame(path, frame, needed, found)
                        }
                    })
                })
                .collect::<Result<_>>()?;
            Ok((stats, None))
        }
        DicomValue::Sequence(_) => Err(ReadError::format(
            path,
            "expected PixelData to hold samples, found a sequence of items",
        )),
    }
}

/// Uncompressed pixel data must hold exactly the frames the header declares (plus the pad byte
/// of an odd length): fewer would leave slices unread, more means the header is wrong about
/// the image (its size, sample width or NumberOfFrames) — unless every surplus byte is zero,
/// which some writers append as padding (pydicom reads such files too): that is ignored, and
/// the returned warning says how many bytes were.
fn check_native_length(
    file: &ImageFile,
    value: &PrimitiveValue,
    map: &SampleMap,
) -> Result<Option<String>> {
    let found = match value {
        PrimitiveValue::U8(bytes) => bytes.len(),
        PrimitiveValue::U16(words) => words.len() * 2,
        PrimitiveValue::I16(words) => words.len() * 2,
        // Another type: refused, naming it, by the frame conversion.
        _ => return Ok(None),
    };
    let layout = &file.layout;
    let (rows, columns, frames) = (layout.rows, layout.columns, file.frames.len());
    let expected = usize::from(rows) * usize::from(columns) * frames * map.bytes_per_sample;
    if found == expected || (expected % 2 == 1 && found == expected + 1) {
        return Ok(None);
    }
    if found > expected && surplus_is_zero(value, expected) {
        return Ok(Some(format!(
            "{}: PixelData (7FE0,0010) ends with {} bytes of zeros beyond Rows × Columns × \
             NumberOfFrames ({expected} bytes); they were taken as padding and ignored",
            file.path.display(),
            found - expected
        )));
    }
    Err(ReadError::inconsistent(
        &file.path,
        format!(
            "PixelData (7FE0,0010) holds {found} bytes, but Rows × Columns × NumberOfFrames × \
             BitsAllocated/8 = {rows} × {columns} × {frames} × {} = {expected}: the header does \
             not describe these pixels (a truncated file, or a wrong Rows, Columns, \
             NumberOfFrames or BitsAllocated)",
            map.bytes_per_sample
        ),
    ))
}

/// Whether every byte of `value` from byte `from` on is zero.
fn surplus_is_zero(value: &PrimitiveValue, from: usize) -> bool {
    match value {
        PrimitiveValue::U8(bytes) => bytes[from..].iter().all(|&b| b == 0),
        PrimitiveValue::U16(words) => words[from / 2..].iter().all(|&w| w == 0),
        PrimitiveValue::I16(words) => words[from / 2..].iter().all(|&w| w == 0),
        _ => false,
    }
}

/// Compressed pixel data hold at least one fragment a frame: fewer means frames are missing
/// (which would go unnoticed when the frames share one position and all but one are dropped as
/// duplicates).
fn check_fragment_count(file: &ImageFile, fragments: usize) -> Result<()> {
    let frames = file.frames.len();
    if fragments >= frames {
        return Ok(());
    }
    Err(ReadError::inconsistent(
        &file.path,
        format!(
            "NumberOfFrames (0028,0008) declares {frames} frames, but the compressed pixel data \
             hold {fragments} fragment(s): frames are missing (a truncated file, or a wrong \
             NumberOfFrames)"
        ),
    ))
}

/// Why a compressed frame could not be converted.
enum FrameError {
    /// The decoder's message.
    Decode(String),
    /// The decoded frame has `found` bytes where `needed` are.
    Short { needed: usize, found: usize },
}

/// Decodes frame `frame` through dicom-rs's registry of decoders into `out`, once the size
/// the stream declares (JPEG, JPEG 2000) is known to be Rows × Columns.
fn registry_frame(
    object: &DefaultDicomObject,
    frame: u32,
    out: &mut [u16],
    map: &SampleMap,
) -> std::result::Result<FrameStats, FrameError> {
    check_stream_size(object, frame)?;
    if let Ok((rows, columns, data)) = compressed_frame(object, frame) {
        if jpeg12::is_12_bit(&data) {
            return jpeg12_frame(&data, rows, columns, out, map);
        }
    }
    let decoded = guarded(|| object.decode_pixel_data_frame(frame))
        .and_then(|decoded| decoded.map_err(|e| chain(&e)))
        .map_err(FrameError::Decode)?;
    converted(decoded.data(), out, map)
}

/// Decodes a 12-bit JPEG frame (which dicom-rs's decoder refuses) through [`jpeg12`].
fn jpeg12_frame(
    data: &[u8],
    rows: u16,
    columns: u16,
    out: &mut [u16],
    map: &SampleMap,
) -> std::result::Result<FrameStats, FrameError> {
    let samples = jpeg12::decode(data, rows, columns).map_err(FrameError::Decode)?;
    if samples.iter().any(|&s| s > map.max_word()) {
        return Err(FrameError::Decode(
            "the 12-bit JPEG stream holds samples wider than BitsAllocated allows".into(),
        ));
    }
    if samples.len() < out.len() {
        return Err(FrameError::Short {
            needed: out.len() * map.bytes_per_sample,
            found: samples.len() * map.bytes_per_sample,
        });
    }
    Ok(map.convert(samples.into_iter(), out))
}

/// Refuses a compressed frame whose stream declares another size than Rows × Columns.
fn check_stream_size(
    object: &DefaultDicomObject,
    frame: u32,
) -> std::result::Result<(), FrameError> {
    let declared = object
        .frame_pixel_data(frame)
        .and_then(|data| stream_size::declared_size(&data));
    let (Some((columns, rows)), Some(header_rows), Some(header_columns)) =
        (declared, object.rows(), object.cols())
    else {
        return Ok(());
    };
    if (rows, columns) == (u32::from(header_rows), u32::from(header_columns)) {
        return Ok(());
    }
    Err(FrameError::Decode(format!(
        "the compressed stream holds {rows} rows × {columns} columns, but Rows × Columns \
         (0028,0010/0011) declare {header_rows} × {header_columns}: the header is wrong (the \
         missing pixels would read as 0)"
    )))
}

/// Decodes RLE frame `frame` through [`rle`] into `out`.
fn rle_frame(
    object: &DefaultDicomObject,
    frame: u32,
    out: &mut [u16],
    map: &SampleMap,
) -> std::result::Result<FrameStats, FrameError> {
    let bytes =
        rle::decode_frame(object, frame, map.bytes_per_sample).map_err(FrameError::Decode)?;
    converted(&bytes, out, map)
}

/// Maps decoded little-endian sample `bytes` into `out`; too few bytes are an error.
fn converted(
    bytes: &[u8],
    out: &mut [u16],
    map: &SampleMap,
) -> std::result::Result<FrameStats, FrameError> {
    let needed = out.len() * map.bytes_per_sample;
    if bytes.len() < needed {
        return Err(FrameError::Short {
            needed,
            found: bytes.len(),
        });
    }
    Ok(map.convert_bytes(bytes, out))
}

/// Decodes JPEG-LS frame `frame` through the pure-Rust decoder into `out`.
fn jpeg_ls_frame(
    object: &DefaultDicomObject,
    frame: u32,
    out: &mut [u16],
    map: &SampleMap,
) -> std::result::Result<FrameStats, FrameError> {
    let samples = guarded(|| jpegls::decode_frame(object, frame, map.max_word()))
        .and_then(|decoded| decoded)
        .map_err(FrameError::Decode)?;
    if samples.len() < out.len() {
        return Err(FrameError::Short {
            needed: out.len() * map.bytes_per_sample,
            found: samples.len() * map.bytes_per_sample,
        });
    }
    Ok(map.convert(samples.into_iter(), out))
}

/// Runs a third-party decoder. Decoders have been seen to panic on corrupt data (dicom-rs
/// 0.10's RLE decoder indexes past its buffer), so a panic there is caught, quietly (see
/// [`guard`]), and becomes an error about the file instead of taking the program down.
fn guarded<T>(decode: impl FnOnce() -> T) -> std::result::Result<T, String> {
    guard::quietly(decode).map_err(|panicked| panicked.to_string())
}

/// Converts frame `frame` of uncompressed pixel data. dicom-rs has already put 16-bit words
/// into native order (byte-swapping big-endian files), so words are taken as they are.
fn native_frame(
    path: &Path,
    value: &PrimitiveValue,
    frame: u32,
    out: &mut [u16],
    map: &SampleMap,
) -> Result<FrameStats> {
    let samples = out.len();
    let range = |unit: usize| {
        let start = usize::try_from(frame)
            .ok()?
            .checked_mul(samples)?
            .checked_mul(unit)?;
        Some(start..start.checked_add(samples.checked_mul(unit)?)?)
    };
    let missing = |have: usize, unit: usize| {
        let needed = range(unit).map_or(usize::MAX, |r| r.end);
        short_frame(path, frame, needed, have * unit)
    };
    match (value, map.bytes_per_sample) {
        (PrimitiveValue::U16(words), 2) => {
            let words = range(1)
                .and_then(|r| words.get(r))
                .ok_or_else(|| missing(words.len(), 2))?;
            Ok(map.convert(words.iter().copied(), out))
        }
        (PrimitiveValue::I16(words), 2) => {
            let words = range(1)
                .and_then(|r| words.get(r))
                .ok_or_else(|| missing(words.len(), 2))?;
            Ok(map.convert(words.iter().map(|&w| w as u16), out))
        }
        (PrimitiveValue::U8(bytes), unit) => {
            let bytes = range(unit)
                .and_then(|r| bytes.get(r))
                .ok_or_else(|| missing(bytes.len(), 1))?;
            Ok(map.convert_bytes(bytes, out))
        }
        (other, _) => Err(ReadError::format(
            path,
            format!(
                "expected PixelData of {}-bit samples, found values of type {:?}",
                map.bytes_per_sample * 8,
                other.value_type()
            ),
        )),
    }
}

fn short_frame(path: &Path, frame: u32, needed: usize, found: usize) -> ReadError {
    ReadError::format(
        path,
        format!("pixel data ends early: frame {frame} needs {needed} bytes, found {found}"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(allocated: u16, stored: u16, signed: bool) -> PixelLayout {
        PixelLayout {
            rows: 1,
            columns: 4,
            samples_per_pixel: 1,
            bits_allocated: allocated,
            bits_stored: stored,
            high_bit: stored - 1,
            signed,
            photometric: "MONOCHROME2".into(),
            modality_lut: None,
        }
    }

    fn map(layout: &PixelLayout, padding: Option<i32>, invert: bool) -> SampleMap {
        SampleMap::new(Path::new("t"), layout, padding, invert).unwrap()
    }

    fn raw_values(map: &SampleMap, words: &[u16]) -> (Vec<i32>, FrameStats) {
        let mut out = vec![0u16; words.len()];
        let stats = map.convert(words.iter().copied(), &mut out);
        let raw = out.iter().map(|&v| i32::from(v) + map.type_min).collect();
        (raw, stats)
    }

    #[test]
    fn unsigned_12_bit_masks_unused_high_bits() {
        let m = map(&layout(16, 12, false), None, false);
        let (raw, stats) = raw_values(&m, &[0xF000 | 2362, 0, 4095, 0x1001]);
        assert_eq!(raw, vec![2362, 0, 4095, 1]);
        assert_eq!((stats.min, stats.max, stats.padding), (0, 4095, 0));
    }

    #[test]
    fn signed_12_bit_sign_extends() {
        let m = map(&layout(16, 12, true), None, false);
        // 0x0800 is −2048 in 12-bit two's complement; 0x0FFF is −1.
        let (raw, _) = raw_values(&m, &[0x0800, 0x0FFF, 0x07FF, 0xF005]);
        assert_eq!(raw, vec![-2048, -1, 2047, 5]);
    }

    #[test]
    fn high_bit_shifts_samples_down() {
        let mut l = layout(16, 8, false);
        l.high_bit = 11;
        let m = map(&l, None, false);
        let (raw, _) = raw_values(&m, &[0x0AB0, 0xFFFF]);
        assert_eq!(raw, vec![0xAB, 0xFF]);
    }

    #[test]
    fn signed_padding_is_counted_and_excluded() {
        let m = map(&layout(16, 16, true), Some(-1500), false);
        let pad = (-1500i16) as u16;
        let (raw, stats) = raw_values(&m, &[pad, 5, pad, (-20i16) as u16]);
        assert_eq!(raw, vec![-1500, 5, -1500, -20]);
        assert_eq!(stats.padding, 2);
        assert_eq!(i32::from(stats.min) + m.type_min, -20);
    }

    #[test]
    fn monochrome1_inverts_within_bits_stored() {
        let m = map(&layout(16, 12, false), None, true);
        let (raw, _) = raw_values(&m, &[0, 4095, 100]);
        assert_eq!(raw, vec![4095, 0, 3995]);
        let m = map(&layout(8, 8, true), None, true);
        let (raw, _) = raw_values(&m, &[0x80, 0x7F]);
        assert_eq!(raw, vec![127, -128]);
    }

    #[test]
    fn refuses_colour_and_odd_sizes() {
        let mut l = layout(16, 12, false);
        l.samples_per_pixel = 3;
        assert!(matches!(
            SampleMap::new(Path::new("t"), &l, None, false),
            Err(ReadError::Unsupported { .. })
        ));
        let l = layout(32, 32, false);
        assert!(matches!(
            SampleMap::new(Path::new("t"), &l, None, false),
            Err(ReadError::Unsupported { .. })
        ));
        let mut l = layout(16, 12, false);
        l.bits_stored = 17;
        assert!(SampleMap::new(Path::new("t"), &l, None, false).is_err());
    }
}
