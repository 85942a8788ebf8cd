//! One level's array, read through `zarrs`: its shape and chunks checked against the
//! [`Limits`] and its files checked before any chunk is decoded, then its samples streamed a
//! slab of chunks at a time into [`read_voxels`].

use crate::error::{ReadError, Result};
use crate::limits::Limits;
use crate::samples::{read_voxels, ElementType, Endian, Rescale};
use endocast_core::ValueMap;
use std::io::Read;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;
use zarrs::array::{data_type, Array, ArrayBytes, DataType};
use zarrs::filesystem::FilesystemStore;

/// Files and folders looked at in an array's folder beyond one per chunk (metadata).
const EXTRA_ENTRIES: u64 = 64;

/// Folder depth looked at in an array's folder (`c/0/0/0` and nested v2 keys).
const MAX_DEPTH: usize = 8;

/// A level's array, opened and checked.
pub(super) struct LevelArray {
    array: Array<FilesystemStore>,
    element: ElementType,
    /// Samples of the whole array.
    count: usize,
}

/// The sample types read, by their Zarr data types.
fn element_types() -> [(DataType, ElementType); 10] {
    [
        (data_type::uint8(), ElementType::U8),
        (data_type::int8(), ElementType::I8),
        (data_type::uint16(), ElementType::U16),
        (data_type::int16(), ElementType::I16),
        (data_type::uint32(), ElementType::U32),
        (data_type::int32(), ElementType::I32),
        (data_type::uint64(), ElementType::U64),
        (data_type::int64(), ElementType::I64),
        (data_type::float32(), ElementType::F32),
        (data_type::float64(), ElementType::F64),
    ]
}

impl LevelArray {
    /// Opens the array `name` of the group at `root`: refuses a sample type other than 8- to
    /// 64-bit integers and 32- and 64-bit floats, and, before anything is decoded, an array or
    /// a chunk of more voxels than `limits` allow and an array folder holding anything but
    /// folders and regular files of at most a chunk's size (twice, for codecs that expand).
    pub(super) fn open(root: &Path, name: &str, limits: &Limits) -> Result<Self> {
        let folder = root.join(name);
        let store =
            FilesystemStore::new(root).map_err(|e| ReadError::format(root, e.to_string()))?;
        let array = Array::open(Arc::new(store), &format!("/{}", name.trim_matches('/')))
            .map_err(|e| ReadError::format(&folder, format!("not a readable Zarr array: {e}")))?;
        let element = element_types()
            .into_iter()
            .find(|(zarr, _)| zarr == array.data_type())
            .map(|(_, element)| element)
            .ok_or_else(|| {
                ReadError::unsupported(
                    &folder,
                    format!(
                        "Zarr data type {} (read: 8- to 64-bit integers, float32, float64)",
                        array.data_type()
                    ),
                )
            })?;
        let count = limits.check_dims(&folder, array.shape())?;
        let chunk = array
            .chunk_shape(&vec![0; array.dimensionality()])
            .map_err(|e| ReadError::format(&folder, e.to_string()))?;
        let chunk: Vec<u64> = chunk.iter().map(|d| d.get()).collect();
        let chunk_voxels = limits.check_dims(&folder.join("(one chunk)"), &chunk)?;
        let chunks: u64 = array.chunk_grid_shape().iter().product();
        let file_bytes =
            (chunk_voxels as u64 * element.size() as u64).saturating_mul(2) + (1 << 20);
        check_files(&folder, file_bytes, chunks.saturating_add(EXTRA_ENTRIES))?;
        Ok(Self {
            array,
            element,
            count,
        })
    }

    /// The array's shape, slowest axis first.
    pub(super) fn shape(&self) -> &[u64] {
        self.array.shape()
    }

    /// The sample type, e.g. `int16`.
    pub(super) fn element(&self) -> ElementType {
        self.element
    }

    /// Every sample (missing chunks are the fill value) as `u16` voxels and their value map,
    /// `rescale` taking stored samples to physical values.
    pub(super) fn read(
        &self,
        folder: &Path,
        rescale: Rescale,
        warnings: &mut Vec<String>,
    ) -> Result<(Vec<u16>, ValueMap)> {
        let mut slabs = Slabs::new(&self.array);
        let endian = if cfg!(target_endian = "big") {
            Endian::Big
        } else {
            Endian::Little
        };
        let read = read_voxels(
            folder,
            &mut slabs,
            self.element,
            endian,
            self.count,
            rescale,
            warnings,
        );
        match slabs.failure {
            Some(failure) => Err(ReadError::format(folder, failure)),
            None => read,
        }
    }
}

/// The samples of an array as a byte stream, decoded one slab of chunks (along the slowest
/// space axis) at a time.
struct Slabs<'a> {
    array: &'a Array<FilesystemStore>,
    /// The next slab's first index along `z`.
    next_z: u64,
    /// The slab's thickness: a chunk's.
    step: u64,
    bytes: Vec<u8>,
    position: usize,
    /// Why a slab could not be decoded (the reader sees only an I/O error).
    failure: Option<String>,
}

impl<'a> Slabs<'a> {
    fn new(array: &'a Array<FilesystemStore>) -> Self {
        let z_axis = array.dimensionality() - 3;
        let step = array
            .chunk_shape(&vec![0; array.dimensionality()])
            .map_or(1, |c| c[z_axis].get());
        Self {
            array,
            next_z: 0,
            step,
            bytes: Vec::new(),
            position: 0,
            failure: None,
        }
    }

    /// Decodes the next slab; false after the last one.
    fn fill(&mut self) -> std::io::Result<bool> {
        let shape = self.array.shape();
        let z_axis = shape.len() - 3;
        if self.next_z >= shape[z_axis] {
            return Ok(false);
        }
        let end = (self.next_z + self.step).min(shape[z_axis]);
        let mut ranges: Vec<Range<u64>> = shape.iter().map(|&n| 0..n).collect();
        ranges[z_axis] = self.next_z..end;
        let slab = self
            .array
            .retrieve_array_subset::<ArrayBytes<'static>>(&ranges)
            .map_err(|e| format!("z {}..{end}: {e}", self.next_z))
            .and_then(|b| b.into_fixed().map_err(|e| e.to_string()));
        match slab {
            Ok(bytes) => {
                self.bytes = bytes.into_owned();
                self.position = 0;
                self.next_z = end;
                Ok(true)
            }
            Err(why) => {
                self.failure = Some(format!("cannot decode the chunks at {why}"));
                Err(std::io::Error::other("chunk decoding failed"))
            }
        }
    }
}

impl Read for Slabs<'_> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        if self.position == self.bytes.len() && !self.fill()? {
            return Ok(0);
        }
        let n = out.len().min(self.bytes.len() - self.position);
        out[..n].copy_from_slice(&self.bytes[self.position..self.position + n]);
        self.position += n;
        Ok(n)
    }
}

/// Refuses an array folder holding more than `max_entries` entries, or anything but folders
/// and regular files of at most `max_file_bytes` (a FIFO would block a read, a huge file
/// would be read whole into memory).
fn check_files(folder: &Path, max_file_bytes: u64, max_entries: u64) -> Result<()> {
    let mut pending = vec![(folder.to_path_buf(), 0usize)];
    let mut seen = 0u64;
    while let Some((dir, depth)) = pending.pop() {
        let entries = std::fs::read_dir(&dir).map_err(|e| ReadError::io(&dir, e))?;
        for entry in entries {
            let path = entry.map_err(|e| ReadError::io(&dir, e))?.path();
            seen += 1;
            if seen > max_entries {
                return Err(ReadError::Limit {
                    path: folder.to_path_buf(),
                    what: "files in the array's folder".into(),
                    requested: seen,
                    limit: max_entries,
                });
            }
            let meta = std::fs::symlink_metadata(&path).map_err(|e| ReadError::io(&path, e))?;
            if meta.is_dir() && depth < MAX_DEPTH {
                pending.push((path, depth + 1));
            } else if !meta.is_file() {
                return Err(ReadError::format(
                    &path,
                    "is not a regular file or a folder",
                ));
            } else if meta.len() > max_file_bytes {
                return Err(ReadError::Limit {
                    path,
                    what: "a chunk file (bytes)".into(),
                    requested: meta.len(),
                    limit: max_file_bytes,
                });
            }
        }
    }
    Ok(())
}
