//! The structure a command found, shown on the slices: the axial, coronal and sagittal planes
//! through the camera side by side, the structure's voxels tinted, the camera drawn. A glance
//! tells whether the aorta, the colon or the ventricle was found, and not the spine or the lung.

use super::slices::{reformat, Plane, Slice, SliceOptions, SlicePlane};
use super::{Image, Rgb, ViewError};
use crate::Volume;
use glam::DVec3;

/// Colour of the structure's tint.
pub const STRUCTURE_COLOR: Rgb = [40, 220, 90];
/// Strength of the tint, 0–1.
const TINT: f32 = 0.45;

/// The three standard slices through `eye_mm` (each `options.size_px` square, side by side),
/// the voxels `inside` holds (voxel index of `volume`) tinted in [`STRUCTURE_COLOR`], and the
/// camera at `eye_mm` looking along `forward` drawn.
pub fn structure_slices(
    volume: &Volume,
    inside: impl Fn([usize; 3]) -> bool,
    eye_mm: DVec3,
    forward: DVec3,
    options: &SliceOptions,
) -> Result<Image, ViewError> {
    let size = options.size_px;
    let mut sheet = Image::new(3 * size, size, [0, 0, 0])?;
    for (n, plane) in [Plane::Axial, Plane::Coronal, Plane::Sagittal]
        .into_iter()
        .enumerate()
    {
        let mut slice = reformat(volume, &SlicePlane::standard(plane, eye_mm)?, options)?;
        tint(&mut slice, volume, &inside);
        slice.draw_camera(eye_mm, forward);
        sheet.blit(slice.image(), (n * size) as i64, 0);
    }
    Ok(sheet)
}

/// Tints the pixels of `slice` whose nearest voxel `inside` holds.
fn tint(slice: &mut Slice, volume: &Volume, inside: &impl Fn([usize; 3]) -> bool) {
    let to_voxel = volume.geometry().voxel_from_world();
    let dims = volume.dims();
    let (w, h) = (slice.image().width(), slice.image().height());
    let mut marked = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let v = to_voxel
                .transform_point3(slice.world_at(x as f64 + 0.5, y as f64 + 0.5))
                .round();
            let in_grid = (0..3).all(|a| v[a] >= 0.0 && v[a] < dims[a] as f64);
            if in_grid && inside([v.x as usize, v.y as usize, v.z as usize]) {
                marked.push((x as i64, y as i64));
            }
        }
    }
    let image = slice.image_mut();
    for (x, y) in marked {
        image.blend(x, y, STRUCTURE_COLOR, TINT);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};

    #[test]
    fn the_structure_is_tinted_where_it_is_and_nowhere_else() {
        let (volume, _) = phantom::straight_tube(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        let options = SliceOptions {
            size_px: 64,
            labels: false,
            ..SliceOptions::default()
        };
        let lumen = |v: [usize; 3]| {
            volume
                .physical(v[0], v[1], v[2])
                .is_some_and(|x| x < -480.0)
        };
        let sheet = structure_slices(&volume, lumen, DVec3::ZERO, DVec3::Z, &options).unwrap();
        assert_eq!((sheet.width(), sheet.height()), (192, 64));
        let green = |x: usize, y: usize| {
            let [r, g, b] = sheet.pixel(x, y).unwrap();
            g > r.saturating_add(40) && g > b.saturating_add(40)
        };
        // The axial slice's corner is tissue; the coronal slice's middle column, away from the
        // camera marker at its centre, is the tube.
        assert!(!green(2, 2));
        assert!(green(64 + 32, 6) && green(64 + 32, 58));
        assert!(!green(64 + 2, 32));
    }
}
