//! Writing a volume as an OME-Zarr 0.5 store (Zarr v3) with a small pyramid.

use super::metadata::{is_zarr, ENDOCAST_KEY};
use super::pyramid::halved;
use super::Extra;
use crate::atomic::TemporaryFolder;
use crate::encode::SampleEncoding;
use crate::error::{ReadError, Result};
use crate::samples::ElementType;
use endocast_core::{Modality, ValueMap, Volume};
use serde_json::{json, Map, Value};
use std::borrow::Cow;
use std::path::Path;
use std::sync::Arc;
use zarrs::array::codec::ZstdCodec;
use zarrs::array::{data_type, ArrayBuilder, ArrayBytes, FillValue};
use zarrs::filesystem::FilesystemStore;
use zarrs::group::GroupBuilder;

/// Chunk edge, voxels: 64³ `int16` chunks are 512 KiB, a few of them per ray segment.
const CHUNK: u64 = 64;

/// Most levels written: the full resolution and up to three halvings.
const MAX_LEVELS: usize = 4;

/// zstd level: fast, as the other writers' gzip level is.
const ZSTD_LEVEL: i32 = 3;

/// Writes `volume` to the folder `path` (atomically: a temporary folder beside it, renamed
/// into place) as OME-Zarr 0.5: a Zarr v3 group whose `ome.multiscales` lists level `0` (the
/// volume) and halvings `1`, `2`, ... while the last is larger than a chunk (at most
/// [`MAX_LEVELS`]), each an array `z, y, x` in millimetres with its `scale` and
/// `translation`, in 64³ chunks compressed with zstd.
///
/// Values: `uint8` for 8-bit data, `int16` physical values where they are exact (CT in HU),
/// else the stored `uint16` values with the rescale in endocast's attribute (see [`Samples`]).
/// Geometry: the physical frame is the grid's own (its axes along the index axes, so that
/// every OME-Zarr reader places the voxels at their true spacing and origin); endocast's attribute adds the LPS direction of those axes
/// and the exact origin. An existing folder is replaced only when it is itself a Zarr store
/// or empty; any other folder, or a file, is refused.
pub fn write(path: &Path, volume: &Volume) -> Result<()> {
    refuse_other_folders(path)?;
    let folder = TemporaryFolder::create(path)?;
    write_store(folder.path(), volume).map_err(|why| ReadError::format(path, why))?;
    folder.commit()
}

/// Refuses to replace a non-empty folder that is not a Zarr store (a user's folder named by
/// mistake).
fn refuse_other_folders(path: &Path) -> Result<()> {
    let Ok(mut entries) = std::fs::read_dir(path) else {
        return Ok(());
    };
    if entries.next().is_none() || is_zarr(path) {
        return Ok(());
    }
    Err(ReadError::format(
        path,
        "is a folder that holds other files and is not a Zarr store: refusing to replace it",
    ))
}

/// Writes the group and its levels into the (new, empty) folder `dir`.
fn write_store(dir: &Path, volume: &Volume) -> std::result::Result<(), String> {
    let store = Arc::new(FilesystemStore::new(dir).map_err(|e| e.to_string())?);
    let encoding = Samples::of(volume);
    let mut levels = vec![Cow::Borrowed(volume)];
    while let Some(last) = levels
        .last()
        .filter(|l| levels.len() < MAX_LEVELS && is_larger_than_a_chunk(l))
    {
        match halved(last) {
            Some(coarser) => levels.push(Cow::Owned(coarser)),
            None => break,
        }
    }
    let mut datasets = Vec::new();
    for (index, level) in levels.iter().enumerate() {
        write_level(&store, index, level, encoding)?;
        datasets.push(dataset(index, level));
    }
    let attributes = group_attributes(volume, encoding, &datasets);
    let group = GroupBuilder::new()
        .attributes(attributes)
        .build(store, "/")
        .map_err(|e| e.to_string())?;
    group.store_metadata().map_err(|e| e.to_string())
}

fn is_larger_than_a_chunk(volume: &Volume) -> bool {
    volume.dims().iter().any(|&d| d as u64 > CHUNK)
}

/// How a store's samples hold the volume's values: chosen so that endocast reads back the
/// same stored voxels and value map (and so renders the same image) as from the source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Samples {
    /// `uint8`: the stored values themselves, for an identity value map and values up to 255.
    U8,
    /// 16 bits: `int16` physical values (HU) where exact, else `uint16` stored values (the
    /// physical values themselves under an identity value map).
    Wide(SampleEncoding),
}

impl Samples {
    fn of(volume: &Volume) -> Self {
        if volume.value_map() != ValueMap::IDENTITY {
            return Self::Wide(SampleEncoding::int16_or_stored(volume));
        }
        if volume.stored_range().1 <= u16::from(u8::MAX) {
            Self::U8
        } else {
            Self::Wide(SampleEncoding::U16Stored)
        }
    }

    /// The samples of `volume` in the machine's byte order (as zarrs takes them).
    fn bytes(self, volume: &Volume) -> std::io::Result<Vec<u8>> {
        let Self::Wide(encoding) = self else {
            // stored_range ≤ 255: exact.
            return Ok(volume.voxels().iter().map(|&v| v as u8).collect());
        };
        let mut bytes = Vec::with_capacity(volume.voxels().len() * 2);
        encoding.write_voxels(volume, &mut bytes)?;
        if cfg!(target_endian = "big") {
            // write_voxels writes little-endian.
            bytes.chunks_exact_mut(2).for_each(|pair| pair.swap(0, 1));
        }
        Ok(bytes)
    }
}

/// Writes one level's array `/{index}`.
fn write_level(
    store: &Arc<FilesystemStore>,
    index: usize,
    volume: &Volume,
    encoding: Samples,
) -> std::result::Result<(), String> {
    let [nx, ny, nz] = volume.dims().map(|d| d as u64);
    let shape = vec![nz, ny, nx];
    let chunk: Vec<u64> = shape.iter().map(|&d| d.min(CHUNK)).collect();
    let (zarr_type, fill) = match encoding {
        Samples::U8 => (data_type::uint8(), FillValue::from(0u8)),
        Samples::Wide(e) if e.element_type() == ElementType::I16 => {
            (data_type::int16(), FillValue::from(0i16))
        }
        Samples::Wide(_) => (data_type::uint16(), FillValue::from(0u16)),
    };
    let array = ArrayBuilder::new(shape.clone(), chunk, zarr_type, fill)
        .bytes_to_bytes_codecs(vec![Arc::new(ZstdCodec::new(ZSTD_LEVEL, false))])
        .dimension_names(["z", "y", "x"].into())
        .build(store.clone(), &format!("/{index}"))
        .map_err(|e| e.to_string())?;
    array.store_metadata().map_err(|e| e.to_string())?;
    let bytes = encoding.bytes(volume).map_err(|e| e.to_string())?;
    let ranges: Vec<_> = shape.iter().map(|&n| 0..n).collect();
    array
        .store_array_subset(&ranges, ArrayBytes::new_flen(bytes))
        .map_err(|e| e.to_string())
}

/// The `datasets` entry of a level: its path, `scale` and `translation` (`z, y, x`, mm) in
/// the grid's own frame (the LPS origin turned back by the direction).
fn dataset(index: usize, volume: &Volume) -> Value {
    let geometry = volume.geometry();
    let direction = geometry.direction();
    let back = if geometry.is_orthogonal() {
        direction.transpose()
    } else {
        direction.inverse()
    };
    let origin = back * geometry.origin_mm();
    let spacing = geometry.spacing_mm();
    json!({
        "path": index.to_string(),
        "coordinateTransformations": [
            {"type": "scale", "scale": [spacing.z, spacing.y, spacing.x]},
            {"type": "translation", "translation": [origin.z, origin.y, origin.x]},
        ],
    })
}

/// The group's attributes: `ome` (version 0.5, one multiscale) and endocast's own.
fn group_attributes(volume: &Volume, encoding: Samples, datasets: &[Value]) -> Map<String, Value> {
    let axes: Vec<Value> = ["z", "y", "x"]
        .iter()
        .map(|name| json!({"name": name, "type": "space", "unit": "millimeter"}))
        .collect();
    let map = volume.value_map();
    let extra = Extra {
        direction: Some(volume.geometry().direction().to_cols_array_2d()),
        origin: Some(volume.geometry().origin_mm().to_array()),
        rescale: (encoding == Samples::Wide(SampleEncoding::U16Stored)
            && map != ValueMap::IDENTITY)
            .then(|| [map.scale(), map.offset()]),
        modality: match volume.modality() {
            Modality::Unknown => None,
            known => Some(known.name().to_owned()),
        },
    };
    let mut attributes = Map::new();
    attributes.insert(
        "ome".into(),
        json!({
            "version": "0.5",
            "multiscales": [{"name": "image", "axes": axes, "datasets": datasets}],
        }),
    );
    attributes.insert(
        ENDOCAST_KEY.into(),
        serde_json::to_value(extra).unwrap_or(Value::Null),
    );
    attributes
}
