//! Siemens mosaics: the slices of a volume tiled in one image (ImageType MOSAIC), row by row
//! from the top left, `ceil(sqrt(N))` tiles a side, as dcm2niix and nibabel's `nicom` unpack
//! them.

use crate::error::{ReadError, Result};
use glam::DVec3;
use std::path::Path;

/// How the slices of one mosaic are tiled in its stored image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Mosaic {
    /// Rows and columns of the stored (tiled) image.
    pub stored: [u16; 2],
    /// Rows and columns of one tile (one slice).
    pub tile: [u16; 2],
    /// Tiles along each side.
    pub per_side: u16,
    /// NumberOfImagesInMosaic: the tiles that hold slices (the others are blank).
    pub count: u16,
}

impl Mosaic {
    /// The tiling of `count` slices in an image of `rows` × `columns`. Refuses (naming `path`
    /// and `source`, the field `count` came from) a count of 0 and an image that is not a
    /// whole number of tiles a side.
    pub(super) fn new(
        path: &Path,
        [rows, columns]: [u16; 2],
        count: u16,
        source: &str,
    ) -> Result<Self> {
        let per_side = (1..=count).find(|side| u32::from(*side).pow(2) >= u32::from(count));
        let Some(per_side) = per_side.filter(|side| rows % side == 0 && columns % side == 0) else {
            return Err(ReadError::inconsistent(
                path,
                format!(
                    "a Siemens mosaic of {count} slices ({source}) in an image of {rows} rows × \
                     {columns} columns: the image is not a whole number of tiles a side, so \
                     the slices cannot be cut out (a wrong NumberOfImagesInMosaic, Rows or \
                     Columns)"
                ),
            ));
        };
        Ok(Self {
            stored: [rows, columns],
            tile: [rows / per_side, columns / per_side],
            per_side,
            count,
        })
    }

    /// Samples in the stored image.
    pub(super) fn stored_len(&self) -> usize {
        usize::from(self.stored[0]) * usize::from(self.stored[1])
    }

    /// The position of the first pixel of the first slice, from the mosaic's
    /// ImagePositionPatient `position` (that of the tiled image's first pixel), its
    /// `orientation` (row, column cosines) and PixelSpacing `spacing` (between rows, between
    /// columns): moved by half the difference between the image and a tile (dcm2niix's and
    /// nibabel's correction), since the scanner writes the position of a slice as large as the
    /// whole image, centred on the true one.
    pub(super) fn first_position(
        &self,
        position: DVec3,
        [row, column]: [DVec3; 2],
        [between_rows, between_columns]: [f64; 2],
    ) -> DVec3 {
        let half = |image: u16, tile: u16| f64::from(image - tile) / 2.0;
        position
            + row * between_columns * half(self.stored[1], self.tile[1])
            + column * between_rows * half(self.stored[0], self.tile[0])
    }

    /// Copies tile `index` (row by row from the top left) of the stored image `whole` into
    /// `out` (one tile's samples). Refuses (as `None`) an index or buffer sizes that do not
    /// fit this tiling.
    pub(super) fn copy_tile(&self, whole: &[u16], index: u32, out: &mut [u16]) -> Option<()> {
        let [rows, columns] = self.tile.map(usize::from);
        let side = usize::from(self.per_side);
        let index = usize::try_from(index).ok()?;
        let stored_columns = usize::from(self.stored[1]);
        if index >= usize::from(self.count)
            || whole.len() != self.stored_len()
            || out.len() != rows * columns
        {
            return None;
        }
        let (top, left) = ((index / side) * rows, (index % side) * columns);
        for (r, out_row) in out.chunks_exact_mut(columns).enumerate() {
            let start = (top + r) * stored_columns + left;
            out_row.copy_from_slice(whole.get(start..start + columns)?);
        }
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_are_cut_row_by_row_from_the_top_left() {
        // 3 slices of 2 rows × 3 columns in 2 × 2 tiles: an image of 4 rows × 6 columns.
        let mosaic = Mosaic::new(Path::new("m"), [4, 6], 3, "test").unwrap();
        assert_eq!((mosaic.tile, mosaic.per_side), ([2, 3], 2));
        let whole: Vec<u16> = (0..24).collect();
        let mut out = [0u16; 6];
        let tiles = [
            [0, 1, 2, 6, 7, 8],
            [3, 4, 5, 9, 10, 11],
            [12, 13, 14, 18, 19, 20],
        ];
        for (index, tile) in tiles.iter().enumerate() {
            mosaic.copy_tile(&whole, index as u32, &mut out).unwrap();
            assert_eq!(&out, tile);
        }
        assert_eq!(mosaic.copy_tile(&whole, 3, &mut out), None);
        assert_eq!(mosaic.copy_tile(&whole[1..], 0, &mut out), None);
    }

    #[test]
    fn counts_that_do_not_tile_the_image_are_refused() {
        for (size, count) in [([4, 6], 0), ([4, 6], 5), ([5, 6], 2), ([2, 2], 9)] {
            assert!(Mosaic::new(Path::new("m"), size, count, "test").is_err());
        }
        assert_eq!(
            Mosaic::new(Path::new("m"), [4, 4], 1, "t").unwrap().tile,
            [4, 4]
        );
    }

    #[test]
    fn the_first_slice_is_moved_to_the_centre_of_the_image() {
        let mosaic = Mosaic::new(Path::new("m"), [4, 6], 4, "test").unwrap();
        let first = mosaic.first_position(DVec3::ZERO, [DVec3::X, DVec3::Y], [0.5, 2.0]);
        // (6 − 3) / 2 columns of 2 mm along x, (4 − 2) / 2 rows of 0.5 mm along y.
        assert_eq!(first, DVec3::new(3.0, 0.5, 0.0));
    }
}
