//! One compressed frame of an image, as the decoders of our own (RLE, JPEG-LS) take it.

use dicom_encoding::adapters::PixelDataObject;
use dicom_object::DefaultDicomObject;
use std::borrow::Cow;

/// The rows, the columns and the compressed bytes of frame `frame` of `object`.
pub(super) fn compressed_frame(
    object: &DefaultDicomObject,
    frame: u32,
) -> Result<(u16, u16, Cow<'_, [u8]>), String> {
    let (rows, columns) = match (object.rows(), object.cols()) {
        (Some(rows), Some(columns)) => (rows, columns),
        _ => return Err("Rows or Columns is missing".into()),
    };
    let data = object
        .frame_pixel_data(frame)
        .ok_or_else(|| format!("no compressed data for frame {frame}"))?;
    Ok((rows, columns, data))
}
