//! The Modality LUT (ModalityLUTSequence, 0028,3000): a table from stored sample values to
//! output values, which takes the place of RescaleSlope/Intercept when a file has one (PS3.3
//! C.11.1). Its outputs are unsigned 8- or 16-bit numbers, so the volume keeps them exactly:
//! each stored sample is mapped through the table into the `u16` voxel, under an identity
//! value map. Stored values below the first mapped value take the first entry, values past the
//! last take the last entry (as pydicom and DCMTK do).

use crate::error::{ReadError, Result};
use dicom_core::PrimitiveValue;
use dicom_dictionary_std::tags;
use dicom_object::InMemDicomObject;
use std::path::Path;
use std::sync::Arc;

/// A Modality LUT: `output = data[clamp(stored − first, 0, len − 1)]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct ModalityLut {
    /// The stored sample value that the first entry maps.
    first: i32,
    /// The output values, one per stored value from `first` on (at least one).
    data: Arc<[u16]>,
}

impl ModalityLut {
    /// The LUT of the first item of `object`'s ModalityLUTSequence, `None` when it has none.
    /// `signed` (PixelRepresentation 1) says how to read the first mapped value, which an
    /// implicit-VR file may give as an unsigned number. Refuses a descriptor that does not
    /// match its data.
    pub(super) fn read(
        path: &Path,
        object: &InMemDicomObject,
        signed: bool,
    ) -> Result<Option<Self>> {
        let Some(item) = object
            .get(tags::MODALITY_LUT_SEQUENCE)
            .and_then(|e| e.items())
            .and_then(<[_]>::first)
        else {
            return Ok(None);
        };
        let bad = |found: String| {
            ReadError::format(
                path,
                format!(
                    "ModalityLUTSequence (0028,3000): expected a LUTDescriptor of 3 numbers \
                     (entries, first stored value, bits 8 or 16) and as many LUTData entries, \
                     found {found}; correct or remove the LUT"
                ),
            )
        };
        let descriptor: Vec<i64> = item
            .get(tags::LUT_DESCRIPTOR)
            .and_then(|e| e.value().primitive())
            .and_then(|value| match lut_words(value, 16) {
                Some(words) => Some(words.into_iter().map(i64::from).collect()),
                None => value.to_multi_int::<i64>().ok(),
            })
            .unwrap_or_default();
        let [entries, first, bits] = descriptor[..] else {
            return Err(bad(format!("LUTDescriptor {descriptor:?}")));
        };
        let entries = if entries == 0 { 65_536 } else { entries };
        let first = if signed && first > i64::from(i16::MAX) {
            first - 65_536
        } else {
            first
        };
        let data = item
            .get(tags::LUT_DATA)
            .and_then(|e| lut_words(e.value().primitive()?, bits))
            .unwrap_or_default();
        let entries = usize::try_from(entries).unwrap_or(usize::MAX);
        if !(8..=16).contains(&bits) || data.len() < entries || entries > 65_536 {
            return Err(bad(format!(
                "LUTDescriptor {descriptor:?} with {} LUTData entries",
                data.len()
            )));
        }
        Ok(Some(Self {
            first: i32::try_from(first).map_err(|_| bad(format!("first value {first}")))?,
            data: data[..entries].into(),
        }))
    }

    /// The output value of stored sample `raw`.
    pub(super) fn apply(&self, raw: i32) -> u16 {
        let last = self.data.len() - 1;
        let index = usize::try_from(i64::from(raw) - i64::from(self.first)).unwrap_or(0);
        self.data[index.min(last)]
    }
}

/// LUTData (or LUTDescriptor) as 16-bit numbers: words as they are, bytes as one entry each
/// for an 8-bit table or little-endian pairs for a 16-bit one (how an implicit-VR value of an
/// ambiguous VR arrives); `None` for other types (a signed descriptor, read by the caller).
fn lut_words(value: &PrimitiveValue, bits: i64) -> Option<Vec<u16>> {
    match value {
        PrimitiveValue::U16(words) => Some(words.to_vec()),
        PrimitiveValue::U8(bytes) if bits <= 8 => {
            Some(bytes.iter().map(|&b| u16::from(b)).collect())
        }
        PrimitiveValue::U8(bytes) => Some(
            bytes
                .chunks_exact(2)
                .map(|pair| u16::from_le_bytes([pair[0], pair[1]]))
                .collect(),
        ),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamps_below_and_above_the_table() {
        let lut = ModalityLut {
            first: -2,
            data: vec![10, 20, 30].into(),
        };
        let out: Vec<u16> = [-5, -2, -1, 0, 9]
            .into_iter()
            .map(|r| lut.apply(r))
            .collect();
        assert_eq!(out, vec![10, 10, 20, 30, 30]);
    }
}
