//! JPEG-LS frames (transfer syntaxes 1.2.840.10008.1.2.4.80 lossless and .81 near-lossless)
//! through `pure_jpegls`, a pure-Rust T.87 decoder: dicom-rs decodes JPEG-LS only through
//! CharLS, whose build needs cmake, and the workspace builds with a Rust toolchain and a C
//! compiler alone. Only single-component (grey-scale) streams are decoded, which is all a
//! volume can hold.

use super::frame::compressed_frame;
use dicom_object::DefaultDicomObject;

/// JPEG-LS Lossless and JPEG-LS Lossy (Near-Lossless).
const UIDS: [&str; 2] = ["1.2.840.10008.1.2.4.80", "1.2.840.10008.1.2.4.81"];

/// Whether `uid` (trailing padding allowed) names a JPEG-LS transfer syntax.
pub(super) fn is_jpeg_ls(uid: &str) -> bool {
    UIDS.contains(&uid.trim_end_matches(['\0', ' ']))
}

/// The samples of frame `frame` of `object`, row by row. `max_sample` is the largest value the
/// voxel map accepts (255 for 8-bit samples), so a stream of wider samples than the file
/// declares is an error, not an out-of-range lookup.
pub(super) fn decode_frame(
    object: &DefaultDicomObject,
    frame: u32,
    max_sample: u16,
) -> Result<Vec<u16>, String> {
    let (rows, columns, data) = compressed_frame(object, frame)?;
    // The decoder refuses a stream whose size differs from the one given.
    let (samples, _, _) =
        jpegls::decode(&data, u32::from(columns), u32::from(rows)).map_err(|e| e.to_string())?;
    if let Some(&wide) = samples.iter().find(|&&s| s > max_sample) {
        return Err(format!(
            "the JPEG-LS stream holds sample {wide}, wider than BitsAllocated allows"
        ));
    }
    Ok(samples)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_both_jpeg_ls_syntaxes_and_nothing_else() {
        assert!(is_jpeg_ls("1.2.840.10008.1.2.4.80"));
        assert!(is_jpeg_ls("1.2.840.10008.1.2.4.81\0"));
        assert!(!is_jpeg_ls("1.2.840.10008.1.2.4.70"));
        assert!(!is_jpeg_ls("1.2.840.10008.1.2.4.8"));
    }
}
