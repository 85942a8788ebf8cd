//! The volume's faces are where the scan was cut, not walls: a camera near one sees the flat
//! cut plane across its view. Starts keep [`FACE_MARGIN_MM`] from every face where the
//! structure allows.

use crate::Volume;

/// How far a start keeps from the volume's faces, mm, where the structure reaches that deep.
pub const FACE_MARGIN_MM: f64 = 10.0;

/// Distances of voxels from the faces of one volume.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Faces {
    dims: [usize; 3],
    spacing_mm: [f64; 3],
}

impl Faces {
    /// The faces of `volume`.
    pub(crate) fn of(volume: &Volume) -> Self {
        Self {
            dims: volume.dims(),
            spacing_mm: volume.geometry().spacing_mm().to_array(),
        }
    }

    /// Distance (mm) from voxel `v`'s centre to the centre of the nearest voxel on a face of
    /// the volume, along the index axes (on a sheared grid, along the slices' stacking axis as
    /// if it were orthogonal).
    pub(crate) fn distance_mm(&self, v: [usize; 3]) -> f64 {
        (0..3)
            .map(|a| v[a].min(self.dims[a] - 1 - v[a]) as f64 * self.spacing_mm[a])
            .fold(f64::INFINITY, f64::min)
    }

    /// At least [`FACE_MARGIN_MM`] from every face.
    pub(crate) fn clear(&self, v: [usize; 3]) -> bool {
        self.distance_mm(v) >= FACE_MARGIN_MM
    }
}
