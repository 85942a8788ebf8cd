//! Scans stored in slices other than axial, for the finders that read axial slices. The index
//! axes nearest the patient's superior–inferior and left–right axes ([`BodyAxes`]), and an
//! axially stored copy of a scan ([`AxialCopy`]) whose lumens map back to the scan's voxels: a
//! chest stored in sagittal slices, or with its slices along `i`, is searched as the same chest.

use super::lumen::Lumen;
use crate::Volume;

/// The index axes (0 `i`, 1 `j`, 2 `k`) of a volume nearest the patient's axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct BodyAxes {
    /// Nearest superior–inferior (world z): the axial slices are across it.
    pub(crate) superior: usize,
    /// Nearest left–right (world x) of the other two.
    pub(crate) left_right: usize,
}

impl BodyAxes {
    /// The axes of `volume`, from its direction matrix.
    pub(crate) fn of(volume: &Volume) -> Self {
        let d = volume.geometry().direction();
        let along = |a: usize, world: usize| d.col(a)[world].abs();
        let superior = (0..3)
            .max_by(|&a, &b| along(a, 2).total_cmp(&along(b, 2)))
            .unwrap_or(2);
        let left_right = (0..3)
            .filter(|&a| a != superior)
            .max_by(|&a, &b| along(a, 0).total_cmp(&along(b, 0)))
            .unwrap_or(0);
        Self {
            superior,
            left_right,
        }
    }

    /// The two in-slice axes, lower first.
    pub(crate) fn in_slice(self) -> [usize; 2] {
        match self.superior {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        }
    }
}

/// A scan's voxels stored again as axial slices: the copy's `k` is the scan's axis nearest
/// superior–inferior, its `i` the one nearest left–right. Its geometry places every voxel where
/// the scan's did, so world positions found in the copy hold for the scan. It holds a second
/// copy of the voxels while a finder searches it (made only for scans not stored axially).
pub(crate) struct AxialCopy {
    volume: Volume,
    /// The scan's axis behind each of the copy's axes.
    order: [usize; 3],
}

impl AxialCopy {
    /// The copy of `volume`, or `None` when its slices are already axial (`k` nearest
    /// superior–inferior) and it can be searched as it is.
    pub(crate) fn of(volume: &Volume) -> Option<Self> {
        let axes = BodyAxes::of(volume);
        if axes.superior == 2 {
            return None;
        }
        let other = 3 - axes.superior - axes.left_right;
        let order = [axes.left_right, other, axes.superior];
        let volume = volume.with_axes(order)?;
        Some(Self { volume, order })
    }

    /// The axially stored copy.
    pub(crate) fn volume(&self) -> &Volume {
        &self.volume
    }

    /// A lumen found in the copy, on the scan's voxels.
    pub(crate) fn lumen_back(&self, lumen: &Lumen) -> Lumen {
        let mut back = [0; 3];
        for (n, &a) in self.order.iter().enumerate() {
            back[a] = n;
        }
        lumen.with_axes(back)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::navigate::LumenSide;
    use crate::Geometry;
    use glam::{DMat3, DVec3};

    #[test]
    fn a_sagittally_stored_scan_is_copied_as_axial_slices_and_its_lumens_map_back() {
        // 4 × 5 × 6 voxels: `i` superior, `j` left, `k` anterior (flipped); value = index.
        let direction = DMat3::from_cols(DVec3::Z, DVec3::X, DVec3::NEG_Y);
        let g =
            Geometry::new([4, 5, 6], DVec3::new(3.0, 1.0, 2.0), DVec3::ZERO, direction).unwrap();
        let voxels: Vec<u16> = (0..120).collect();
        let map = crate::ValueMap::new(1.0, 0.0).unwrap();
        let volume = Volume::new(g, voxels, map, crate::Modality::Ct).unwrap();
        assert_eq!(BodyAxes::of(&volume).superior, 0);
        let copy = AxialCopy::of(&volume).unwrap();
        let c = copy.volume();
        assert_eq!(c.dims(), [5, 6, 4]);
        assert!(AxialCopy::of(c).is_none());
        assert!(volume.with_axes([0, 0, 1]).is_none());
        // Every voxel of the copy holds the scan's voxel at the same world position.
        for (k, j, i) in [(0, 0, 0), (3, 5, 4), (1, 2, 3), (2, 4, 1)] {
            let at = DVec3::new(i as f64, j as f64, k as f64);
            let world = c.geometry().world_of(at);
            let v = volume.geometry().voxel_from_world().transform_point3(world);
            let [a, b, d] = [v.x, v.y, v.z].map(|x| x.round() as usize);
            assert!((v - DVec3::new(a as f64, b as f64, d as f64)).length() < 1e-9);
            assert_eq!(c.stored(i, j, k), volume.stored(a, b, d));
        }
        // A lumen grown in the copy is the same voxels of the scan.
        let lumen = Lumen::from_seed(c, [0, 0, 0], 30.0, LumenSide::Below).unwrap();
        let back = copy.lumen_back(&lumen);
        let direct = Lumen::from_seed(&volume, [0, 0, 0], 30.0, LumenSide::Below).unwrap();
        assert_eq!(back.voxel_count(), 30);
        assert_eq!(back.volume_dims(), volume.dims());
        assert_eq!(
            back.voxels().collect::<Vec<_>>(),
            direct.voxels().collect::<Vec<_>>()
        );
    }
}
