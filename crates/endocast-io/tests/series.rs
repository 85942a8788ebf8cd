//! Assembling a DICOM series into a stack (issue 32): a localiser among the slices is set aside,
//! unevenly spaced slices keep every real slice exactly, a missing slice is refused unless the
//! caller asks to fill it. Small synthetic series of 4×4 CT slices, one value each.

use crate::dicom_bytes::{element, Image, EXPLICIT_LE};
use endocast_io::{dicom, Loaded, OpenOptions, ReadError};
use glam::DVec3;
use std::path::Path;

const AXIAL: &str = "1\\0\\0\\0\\1\\0";

/// A 4×4 slice at `z` (mm) in `orientation`, every sample `value` (HU = value − 1024).
fn slice(z: f64, orientation: &str, value: u16) -> Vec<u8> {
    let pixels: Vec<u8> = std::iter::repeat_n(value.to_le_bytes(), 16)
        .flatten()
        .collect();
    let mut image = Image::ct(4, 4);
    image
        .text((0x20, 0x32), b"DS", &format!("0\\0\\{z}"))
        .text((0x20, 0x37), b"DS", orientation)
        .set((0x7FE0, 0x10), element((0x7FE0, 0x10), b"OW", &pixels));
    image.bytes(EXPLICIT_LE)
}

/// A folder of axial slices at `zs`, slice `k` holding `100 × (k + 1)`, named `s0.dcm`, ...
fn series(zs: &[f64]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (k, &z) in zs.iter().enumerate() {
        let bytes = slice(z, AXIAL, 100 * (k as u16 + 1));
        std::fs::write(dir.path().join(format!("s{k}.dcm")), bytes).unwrap();
    }
    dir
}

fn read(dir: &Path, fill_missing: bool) -> Result<Loaded, ReadError> {
    let mut options = OpenOptions::default();
    options.fill_missing_slices = fill_missing;
    dicom::read(dir, &options)
}

/// The plane of `loaded` at `z` mm: its index, after checking that it holds `value` exactly.
fn plane_at(loaded: &Loaded, z: f64, value: u16) -> usize {
    let volume = &loaded.volume;
    let [_, _, count] = volume.dims();
    let g = volume.geometry();
    let k = (0..count)
        .find(|&k| (g.world_of(DVec3::new(0.0, 0.0, k as f64)).z - z).abs() < 1e-6)
        .unwrap_or_else(|| panic!("no plane at z = {z}: {:?}", loaded.warnings));
    let voxels = &volume.voxels()[k * 16..(k + 1) * 16];
    let physical = volume.value_map().physical(voxels[0]);
    assert!(
        voxels.iter().all(|&v| v == voxels[0]),
        "plane {k} is not one value"
    );
    assert_eq!(physical, f64::from(value) - 1024.0, "plane {k} at z = {z}");
    k
}

#[test]
fn uneven_slices_keep_every_real_slice_exactly() {
    // Gaps 1, 1.5, 1.5 mm: a 0.5 mm grid holds every slice where it was.
    let zs = [0.0, 1.0, 2.5, 4.0];
    let dir = series(&zs);
    let loaded = read(dir.path(), false).unwrap();
    assert_eq!(loaded.volume.dims(), [4, 4, 9]);
    for (k, &z) in zs.iter().enumerate() {
        plane_at(&loaded, z, 100 * (k as u16 + 1));
    }
    let warning = loaded.warnings.join("\n");
    assert!(warning.contains("uneven gaps") && warning.contains("moved at most 0.000 mm"));
    // Gaps 1, 1.4, 1 mm fit no grid of a whole fraction of 1 mm: planes 0.85 mm apart, each
    // slice copied onto its nearest plane, the move named.
    let dir = series(&[0.0, 1.0, 2.4, 3.4]);
    let loaded = read(dir.path(), false).unwrap();
    assert_eq!(loaded.volume.dims(), [4, 4, 5]);
    for (k, z) in [0.0, 0.85, 2.55, 3.4].iter().enumerate() {
        plane_at(&loaded, *z, 100 * (k as u16 + 1));
    }
    let warning = loaded.warnings.join("\n");
    assert!(
        warning.contains("slice 2 (s1.dcm, 1.00 mm along the stack) by -0.150 mm"),
        "{warning}"
    );
}

#[test]
fn a_missing_slice_is_refused_unless_asked_and_then_named() {
    let dir = series(&[0.0, 2.0, 4.0, 8.0, 10.0, 12.0]);
    let error = read(dir.path(), false).unwrap_err().to_string();
    for words in [
        "1 slice(s) missing",
        "slice 3 (s2.dcm, 4.00 mm along the stack) and slice 4 (s3.dcm, 8.00 mm",
        "missing at (0.00, 0.00, 6.00) mm",
        "--fill-missing-slices",
    ] {
        assert!(error.contains(words), "{error:?} does not say {words:?}");
    }
    let loaded = read(dir.path(), true).unwrap();
    assert_eq!(loaded.volume.dims(), [4, 4, 7]);
    for (k, z) in [0.0, 2.0, 4.0, 8.0, 10.0, 12.0].iter().enumerate() {
        plane_at(&loaded, *z, 100 * (k as u16 + 1));
    }
    // The synthesised plane is the mean of its neighbours (300 and 400).
    assert_eq!(plane_at(&loaded, 6.0, 350), 3);
    let warning = loaded.warnings.join("\n");
    assert!(
        warning.contains("(0.00, 0.00, 6.00)") && warning.contains("synthesised"),
        "{warning}"
    );
}

#[test]
fn a_truncated_slice_file_leaves_a_missing_slice_that_is_refused() {
    let dir = series(&[0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
    let cut = dir.path().join("s3.dcm");
    let bytes = std::fs::read(&cut).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() - 10]).unwrap();
    let error = read(dir.path(), false).unwrap_err().to_string();
    assert!(
        error.contains("1 slice(s) missing") && error.contains("(0.00, 0.00, 6.00)"),
        "{error}"
    );
    let loaded = read(dir.path(), true).unwrap();
    assert_eq!(loaded.volume.dims(), [4, 4, 6]);
    let warnings = loaded.warnings.join("\n");
    assert!(
        warnings.contains("s3.dcm") && warnings.contains("synthesised"),
        "{warnings}"
    );
}

#[test]
fn a_localiser_in_the_series_is_set_aside_and_named() {
    let dir = series(&[0.0, 2.0, 4.0, 6.0, 8.0]);
    let localiser = slice(0.0, "1\\0\\0\\0\\0\\-1", 50);
    std::fs::write(dir.path().join("localiser.dcm"), localiser).unwrap();
    let loaded = read(dir.path(), false).unwrap();
    assert_eq!(loaded.volume.dims(), [4, 4, 5]);
    plane_at(&loaded, 8.0, 500);
    let warning = loaded.warnings.join("\n");
    for words in [
        "main stack of 5 images (axial",
        "set aside 1 image(s)",
        "1 coronal (row 1,0,0, column 0,0,-1), 4×4",
        "localiser.dcm",
    ] {
        assert!(
            warning.contains(words),
            "{warning:?} does not say {words:?}"
        );
    }
}
