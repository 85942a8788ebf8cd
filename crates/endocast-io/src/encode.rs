//! How writers store a volume's values: the sample type a file gets and the conversion from
//! the volume's `u16` voxels. Shared by the NIfTI and MetaImage writers.

use crate::samples::ElementType;
use endocast_core::Volume;
use std::io::{self, Write};

/// Voxels converted per chunk: large enough to amortise the writes, small enough for the cache.
const CHUNK_SAMPLES: usize = 1 << 16;

/// The sample type a writer stores, and what the samples mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SampleEncoding {
    /// Physical values as `int16`: exact, for unit scale, an integral offset and a range
    /// inside `int16` (CT in Hounsfield units). `offset` is the value map's offset.
    I16Physical { offset: i32 },
    /// Physical values as `uint16`: exact, as above for a range inside `uint16`.
    U16Physical { offset: i32 },
    /// The stored `u16` values; the file must carry the value map as its rescale.
    U16Stored,
    /// Physical values as `float32` (rounded to float precision).
    F32Physical,
}

impl SampleEncoding {
    /// The exact integer encoding of `volume`'s physical values (`int16` preferred), when the
    /// value map has unit scale and an integral offset and the physical range fits.
    pub(crate) fn exact_integer(volume: &Volume) -> Option<Self> {
        let map = volume.value_map();
        if map.scale() != 1.0 || map.offset().fract() != 0.0 {
            return None;
        }
        let (lo, hi) = volume.stored_range();
        // |offset| is bounded before the cast so that the range arithmetic cannot overflow.
        if map.offset().abs() > f64::from(1u32 << 20) {
            return None;
        }
        let offset = map.offset() as i32;
        let (lo, hi) = (i32::from(lo) + offset, i32::from(hi) + offset);
        let within = |min: i32, max: i32| min <= lo && hi <= max;
        if within(i16::MIN.into(), i16::MAX.into()) {
            Some(Self::I16Physical { offset })
        } else if within(0, u16::MAX.into()) {
            Some(Self::U16Physical { offset })
        } else {
            None
        }
    }

    /// `int16` physical values where they are exact (see [`Self::exact_integer`]), the
    /// stored `u16` values otherwise: for formats that carry a rescale (NIfTI, OME-Zarr).
    pub(crate) fn int16_or_stored(volume: &Volume) -> Self {
        match Self::exact_integer(volume) {
            Some(e @ Self::I16Physical { .. }) => e,
            _ => Self::U16Stored,
        }
    }

    /// The type of the samples in the file.
    pub(crate) fn element_type(self) -> ElementType {
        match self {
            Self::I16Physical { .. } => ElementType::I16,
            Self::U16Physical { .. } | Self::U16Stored => ElementType::U16,
            Self::F32Physical => ElementType::F32,
        }
    }

    /// Writes every voxel of `volume` (`i` fastest), little-endian.
    pub(crate) fn write_voxels(self, volume: &Volume, w: &mut dyn Write) -> io::Result<()> {
        let map = volume.value_map();
        let mut bytes = Vec::with_capacity(CHUNK_SAMPLES * self.element_type().size());
        for chunk in volume.voxels().chunks(CHUNK_SAMPLES) {
            bytes.clear();
            // `exact_integer` checked that stored + offset stays inside the target type, so
            // the narrowing casts below are exact.
            match self {
                Self::I16Physical { offset } => bytes.extend(
                    chunk
                        .iter()
                        .flat_map(|&s| ((i32::from(s) + offset) as i16).to_le_bytes()),
                ),
                Self::U16Physical { offset } => bytes.extend(
                    chunk
                        .iter()
                        .flat_map(|&s| ((i32::from(s) + offset) as u16).to_le_bytes()),
                ),
                Self::U16Stored => bytes.extend(chunk.iter().flat_map(|&s| s.to_le_bytes())),
                Self::F32Physical => bytes.extend(
                    chunk
                        .iter()
                        .flat_map(|&s| (map.physical(s) as f32).to_le_bytes()),
                ),
            }
            w.write_all(&bytes)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use endocast_core::{Geometry, Modality, ValueMap};
    use glam::DVec3;

    fn volume(voxels: Vec<u16>, map: ValueMap) -> Volume {
        let g = Geometry::axis_aligned([voxels.len(), 1, 1], DVec3::ONE, DVec3::ZERO).unwrap();
        Volume::new(g, voxels, map, Modality::Ct).unwrap()
    }

    #[test]
    fn picks_the_narrowest_exact_type() {
        let ct = volume(vec![0, 4095], ValueMap::new(1.0, -1024.0).unwrap());
        assert_eq!(
            SampleEncoding::exact_integer(&ct),
            Some(SampleEncoding::I16Physical { offset: -1024 })
        );
        let wide = volume(vec![0, 65535], ValueMap::IDENTITY);
        assert_eq!(
            SampleEncoding::exact_integer(&wide),
            Some(SampleEncoding::U16Physical { offset: 0 })
        );
        let scaled = volume(vec![0, 1], ValueMap::new(0.5, 0.0).unwrap());
        assert_eq!(SampleEncoding::exact_integer(&scaled), None);
        let shifted = volume(vec![0, 65535], ValueMap::new(1.0, -40000.0).unwrap());
        assert_eq!(SampleEncoding::exact_integer(&shifted), None);
    }

    #[test]
    fn writes_little_endian_physical_values() {
        let ct = volume(vec![0, 1000], ValueMap::new(1.0, -1024.0).unwrap());
        let mut out = Vec::new();
        SampleEncoding::I16Physical { offset: -1024 }
            .write_voxels(&ct, &mut out)
            .unwrap();
        assert_eq!(
            out,
            [(-1024i16).to_le_bytes(), (-24i16).to_le_bytes()].concat()
        );
    }
}
