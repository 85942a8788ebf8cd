//! `endocast.save_png`: an image array to a PNG file, written as the CLI writes its images
//! (so a script needs no imaging package to save what `render` and `fly` return).

use crate::errors::{error, to_py};
use numpy::{PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::path::PathBuf;

/// Writes an RGB or RGBA uint8 image (height, width, 3 or 4) to `path` as an 8-bit PNG; any
/// view of one (`rgba[..., :3]`) will do.
#[pyfunction]
#[allow(clippy::needless_pass_by_value)] // PyO3 hands arguments over by value.
pub fn save_png(path: PathBuf, image: PyReadonlyArray3<'_, u8>) -> PyResult<()> {
    let &[height, width, channels] = image.shape() else {
        return Err(error("the image must have 3 dimensions"));
    };
    // A view (`rgba[..., :3]`, a transposed or flipped image) is copied into row order.
    let owned;
    let pixels = match image.as_slice() {
        Ok(pixels) => pixels,
        Err(_) => {
            owned = image.as_array().iter().copied().collect::<Vec<u8>>();
            &owned
        }
    };
    let (w, h) = (width as u32, height as u32);
    match channels {
        3 => endocast_io::write_png_rgb8(&path, w, h, pixels),
        4 => endocast_io::write_png_rgba8(&path, w, h, pixels),
        n => {
            return Err(error(format!(
                "the image has {n} channels; PNG takes 3 or 4"
            )))
        }
    }
    .map_err(to_py)
}
