//! Analyze 7.5 pairs (`.hdr` without NIfTI's magic + `.img`) read as nibabel reads them: both
//! byte orders, SPM's scale factor and origin, the `.mat` beside them, and bad pairs refused
//! naming the file. crates/endocast-py/tests/test_analyze.py compares with nibabel itself.

use crate::nifti::{assert_samples, gzip, scratch, write_temp, Hdr};
use endocast_io::{open, Format, Limits, Loaded, OpenOptions, ReadError};
use glam::{DAffine3, DMat3, DVec3};
use std::path::PathBuf;
use tempfile::TempDir;

/// A 3×2×2 int16 Analyze header with unit voxels (the NIfTI-1 test header without its magic,
/// `vox_offset` 0).
fn analyze(big: bool) -> Hdr {
    Hdr::nifti1(big).magic(344, b"\0\0\0\0").f32(108, 0.0)
}

/// Writes `name.hdr` and `name.img` (the samples −6..5) into `dir`; returns the `.hdr`.
fn write_pair(dir: &TempDir, name: &str, header: Hdr) -> PathBuf {
    let bytes = header.with_samples();
    write_temp(dir, &format!("{name}.img"), &bytes[352..]);
    write_temp(dir, &format!("{name}.hdr"), &bytes[..348])
}

fn read(path: &std::path::Path) -> Result<Loaded, ReadError> {
    open(path, &OpenOptions::default())
}

/// nibabel's affine (RAS from voxel) of `loaded`.
fn ras_of(loaded: &Loaded) -> DAffine3 {
    DAffine3::from_scale(DVec3::new(-1.0, -1.0, 1.0)) * loaded.volume.geometry().world_from_voxel()
}

#[test]
fn both_byte_orders_read_radiological_through_the_centre_with_a_warning() {
    let dir = scratch();
    for big in [false, true] {
        let loaded = read(&write_pair(&dir, "plain", analyze(big))).unwrap();
        assert_samples(&loaded);
        assert_eq!(loaded.source.format, Format::Analyze);
        let order = if big { ", big-endian" } else { "" };
        assert_eq!(
            loaded.source.stored_type,
            format!("int16 (Analyze 7.5{order})")
        );
        // nibabel: diag(-1, 1, 1), the centre voxel (1, 0.5, 0.5) at 0.
        let ras = ras_of(&loaded);
        assert_eq!(
            ras.matrix3,
            DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0))
        );
        assert_eq!(ras.translation, DVec3::new(1.0, -0.5, -0.5));
        assert_eq!(loaded.volume.geometry().orientation_code(), "LAS");
        let [warning] = &loaded.warnings[..] else {
            panic!("{:?}", loaded.warnings)
        };
        assert!(
            warning.contains("Analyze 7.5") && warning.contains("LAS"),
            "{warning}"
        );
    }
}

#[test]
fn spm_scale_intercept_and_origin_apply() {
    let dir = scratch();
    let h = analyze(true)
        .f32(80, 0.7)
        .f32(84, 0.9)
        .f32(88, 1.3)
        .f32(112, 2.0)
        .f32(116, 1.0)
        .i16(253, 2)
        .i16(255, 1)
        .i16(257, 1);
    let loaded = read(&write_pair(&dir, "spm", h)).unwrap();
    let v = &loaded.volume;
    assert_eq!(v.physical(0, 0, 0), Some(-11.0));
    assert_eq!(v.physical(2, 1, 1), Some(11.0));
    // Voxel origin − 1 = (1, 0, 0) at 0 mm, the product taken in float32 as nibabel does.
    let ras = ras_of(&loaded);
    let zooms = DVec3::from([-0.7f32, 0.9, 1.3].map(f64::from));
    assert_eq!(ras.matrix3, DMat3::from_diagonal(zooms));
    assert_eq!(ras.translation, DVec3::new(f64::from(0.7f32), 0.0, 0.0));
}

#[test]
fn dim0_decides_the_byte_order_as_nibabel_guesses_it() {
    let dir = scratch();
    let mut h = analyze(true);
    h.bytes[..4].copy_from_slice(&348i32.to_le_bytes());
    let loaded = read(&write_pair(&dir, "mixed", h)).unwrap();
    assert_samples(&loaded);
}

#[test]
fn gzip_pairs_read_like_plain_ones() {
    let dir = scratch();
    let bytes = analyze(false).with_samples();
    write_temp(&dir, "g.img.gz", &gzip(&bytes[352..]));
    let loaded = read(&write_temp(&dir, "g.hdr.gz", &gzip(&bytes[..348]))).unwrap();
    assert_samples(&loaded);
    assert_eq!(loaded.source.stored_type, "int16 (Analyze 7.5, gzip)");
}

/// A level 4 MAT-file holding one little-endian 4×4 double matrix `name` (rows given).
fn mat4(name: &str, rows: [[f64; 4]; 4]) -> Vec<u8> {
    let mut out = Vec::new();
    for v in [0, 4, 4, 0, name.len() as i32 + 1] {
        out.extend(v.to_le_bytes());
    }
    out.extend(name.bytes().chain([0]));
    for col in 0..4 {
        out.extend(rows.iter().flat_map(|row| row[col].to_le_bytes()));
    }
    out
}

#[test]
fn the_mat_beside_the_pair_gives_the_geometry() {
    let dir = scratch();
    let path = write_pair(&dir, "m", analyze(false));
    let mat = [
        [0.0, -2.0, 0.0, 10.0],
        [3.0, 0.0, 0.0, -5.0],
        [0.0, 0.0, 1.0, 7.0],
        [0.0, 0.0, 0.0, 1.0],
    ];
    write_temp(&dir, "m.mat", &mat4("mat", mat));
    let loaded = read(&path).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    // MATLAB's voxel (1, 1, 1) is voxel 0: the translation moves by the sum of the columns.
    let ras = ras_of(&loaded);
    assert_eq!(ras.matrix3.row(0), DVec3::new(0.0, -2.0, 0.0));
    assert_eq!(ras.translation, DVec3::new(8.0, -2.0, 8.0));
    // SPM's M lacks the x flip nibabel adds.
    write_temp(&dir, "m.mat", &mat4("M", mat));
    let loaded = read(&path).unwrap();
    assert_eq!(ras_of(&loaded).translation, DVec3::new(-8.0, -2.0, 8.0));
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    // A MAT-file endocast cannot read: the header's geometry, and a warning naming the .mat.
    write_temp(&dir, "m.mat", b"MATLAB 5.0 MAT-file, Platform: GLNXA64");
    let loaded = read(&path).unwrap();
    assert_eq!(ras_of(&loaded).translation, DVec3::new(1.0, -0.5, -0.5));
    assert!(
        loaded.warnings.iter().any(|w| w.contains("m.mat")),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn bad_pairs_are_refused_naming_the_file() {
    let dir = scratch();
    let path = write_pair(&dir, "short", analyze(false));
    let img = dir.path().join("short.img");
    std::fs::write(&img, [0u8; 23]).unwrap();
    let e = read(&path).unwrap_err();
    assert_eq!(e.path(), img, "{e}");
    assert!(e.to_string().contains("ends early"), "{e}");
    std::fs::remove_file(&img).unwrap();
    assert!(read(&path).unwrap_err().to_string().contains("short.img"));
    // A dim far beyond the .img is refused before anything that size is allocated.
    let e = read(&write_pair(&dir, "lying", analyze(false).i16(42, 30000))).unwrap_err();
    assert!(matches!(e, ReadError::Format { .. }), "{e}");
    let mut options = OpenOptions::default();
    options.limits = Limits::with_max_voxels(1000);
    let huge = write_pair(&dir, "huge", analyze(false).i16(42, 30000).i16(44, 30000));
    let e = open(&huge, &options).unwrap_err();
    assert!(matches!(e, ReadError::Limit { .. }), "{e}");
    let e = read(&write_pair(&dir, "rgb", analyze(false).i16(70, 128))).unwrap_err();
    assert!(matches!(e, ReadError::Unsupported { .. }), "{e}");
    assert!(e.to_string().contains("Analyze 7.5 datatype 128"), "{e}");
    let e = read(&write_pair(&dir, "rank", analyze(false).i16(40, 0))).unwrap_err();
    assert!(e.to_string().contains("dim[0]"), "{e}");
    // Without NIfTI's magic a header is Analyze, whose voxels are in a .img: a .nii is refused.
    let single = analyze(false).with_samples();
    let e = read(&write_temp(&dir, "no-magic.nii", &single)).unwrap_err();
    assert!(e.to_string().contains(".hdr"), "{e}");
}
