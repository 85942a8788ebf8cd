//! NIfTI reader and writer: real scans, round trips, hand-made NIfTI-2 / big-endian / qform-only
//! files, and a corpus of bad headers that must fail cleanly.

// Helpers panic on failure like the tests that call them.
#![allow(clippy::unwrap_used)]

use crate::test_volumes::{assert_same_volume, oblique_ct, scaled_volume, sheared_ct};
use endocast_io::{nifti, open, Format, Limits, OpenOptions, ReadError};
use glam::DVec3;
use std::io::Write;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

fn read(path: &Path) -> Result<endocast_io::Loaded, ReadError> {
    nifti::read(path, &OpenOptions::default())
}

#[test]
fn brain_t1_is_ras_with_the_head_top_superior() {
    let Some(dir) = endocast_testdata::shared_data("brain-mri-t1") else {
        return;
    };
    let loaded = read(&dir.join("chris_t1.nii.gz")).unwrap();
    let v = &loaded.volume;
    let g = v.geometry();
    assert_eq!(v.dims(), [188, 256, 190]);
    assert!((g.spacing_mm() - DVec3::splat(0.88)).abs().max_element() < 1e-3);
    assert_eq!(v.physical_range(), (0.0, 255.0));
    assert_eq!(loaded.source.format, Format::Nifti);
    assert_eq!(loaded.source.stored_type, "uint8 (NIfTI-1, gzip)");
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    // The sform is a RAS diagonal: i runs towards the patient's right, j anterior, k superior.
    // In LPS that makes world x grow as i falls (towards the left) and z grow with k.
    assert_eq!(g.orientation_code(), "RAS");
    assert!((g.direction().x_axis - DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-9);
    assert!(
        (g.origin_mm() - DVec3::new(83.12, 118.12, -77.12))
            .abs()
            .max_element()
            < 1e-4
    );
    let world_x_of_i = |i: f64| g.world_of(DVec3::new(i, 0.0, 0.0)).x;
    assert!(
        world_x_of_i(0.0) > world_x_of_i(187.0),
        "voxel i = 0 lies on the patient's left"
    );

    // Anatomy: the head is cut through the neck at k = 0 and rounds off at the vertex, so the
    // most superior tissue (largest world z) is the highest slice that still holds any, and
    // the slices just below it hold far less than the cut at the bottom.
    let [ni, nj, nk] = v.dims();
    let tissue_in = |k: usize| {
        (0..nj)
            .flat_map(|j| (0..ni).map(move |i| (i, j)))
            .filter(|&(i, j)| v.physical(i, j, k).unwrap() > 30.0)
            .count()
    };
    let top = (0..nk).rev().find(|&k| tissue_in(k) > 0).unwrap();
    assert!(
        top > nk * 9 / 10,
        "the vertex is near the last slice, found {top}"
    );
    assert!(tissue_in(top - 3) * 5 < tissue_in(0));
    let z_of = |k: usize| g.world_of(DVec3::new(94.0, 128.0, k as f64)).z;
    assert!((0..top).all(|k| z_of(k) < z_of(top)));
}

#[test]
fn engine_ct_reads() {
    let Some(dir) = endocast_testdata::shared_data("classic-engine-ct") else {
        return;
    };
    let loaded = read(&dir.join("engine.nii.gz")).unwrap();
    let v = &loaded.volume;
    assert_eq!(v.dims(), [256, 256, 128]);
    assert_eq!(v.geometry().spacing_mm(), DVec3::ONE);
    assert_eq!(v.physical_range(), (0.0, 255.0));
    assert_eq!(v.value_map().scale(), 1.0);
    assert_eq!(
        v.geometry().origin_mm(),
        DVec3::new(127.0, 127.0, -64.0),
        "RAS qoffset (-127, -127, -64) negated in x and y"
    );
}

fn round_trip(
    volume: &endocast_core::Volume,
    name: &str,
) -> (endocast_io::Loaded, PathBuf, TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    nifti::write(&path, volume).unwrap();
    let loaded = open(&path, &OpenOptions::default()).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    (loaded, path, dir)
}

/// Little-endian header fields of a file the writer produced (uncompressed).
fn field_i16(bytes: &[u8], at: usize) -> i16 {
    i16::from_le_bytes([bytes[at], bytes[at + 1]])
}

fn field_f32(bytes: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

#[test]
fn oblique_ct_round_trips_through_nii_and_nii_gz() {
    let volume = oblique_ct();
    for name in ["ct.nii", "ct.nii.gz"] {
        let (loaded, path, _dir) = round_trip(&volume, name);
        assert_same_volume(&loaded.volume, &volume, 0.0);
        let bytes = std::fs::read(&path).unwrap();
        if name.ends_with(".gz") {
            assert_eq!(&bytes[..2], &[0x1f, 0x8b]);
            assert_eq!(loaded.source.stored_type, "int16 (NIfTI-1, gzip)");
            continue;
        }
        assert_eq!(loaded.source.stored_type, "int16 (NIfTI-1)");
        assert_eq!(field_i16(&bytes, 70), 4, "datatype int16");
        assert_eq!(field_f32(&bytes, 108), 352.0, "vox_offset");
        assert_eq!(field_f32(&bytes, 112), 1.0, "scl_slope");
        assert_eq!(field_f32(&bytes, 116), 0.0, "scl_inter");
        assert_eq!(bytes[123], 2, "xyzt_units mm");
        assert_eq!((field_i16(&bytes, 252), field_i16(&bytes, 254)), (1, 1));
        assert_eq!(&bytes[344..352], b"n+1\0\0\0\0\0");
        assert_eq!(bytes.len(), 352 + 2 * volume.voxels().len());
    }
}

#[test]
fn oblique_qform_alone_gives_the_same_geometry() {
    // Zero the sform code of a written file: the qform must then carry the same geometry.
    let volume = oblique_ct();
    let (_, path, _dir) = round_trip(&volume, "q.nii");
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[254..256].copy_from_slice(&0i16.to_le_bytes());
    std::fs::write(&path, &bytes).unwrap();
    let loaded = read(&path).unwrap();
    assert_same_volume(&loaded.volume, &volume, 0.0);
}

#[test]
fn sheared_grid_round_trips_through_the_sform() {
    let volume = sheared_ct();
    let (loaded, path, _dir) = round_trip(&volume, "sheared.nii");
    assert_same_volume(&loaded.volume, &volume, 0.0);
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(field_i16(&bytes, 252), 0, "no qform for a sheared grid");
    assert_eq!(field_i16(&bytes, 254), 1);
}

#[test]
fn scaled_values_round_trip_exactly_as_uint16_with_slope() {
    let volume = scaled_volume();
    let (loaded, _, _dir) = round_trip(&volume, "scaled.nii.gz");
    assert_same_volume(&loaded.volume, &volume, 0.0);
    assert_eq!(loaded.volume.value_map(), volume.value_map());
    assert_eq!(loaded.source.stored_type, "uint16 (NIfTI-1, gzip)");
}

/// A NIfTI header written field by field, in either byte order.
pub(crate) struct Hdr {
    pub(crate) bytes: Vec<u8>,
    big: bool,
}

impl Hdr {
    fn put(mut self, at: usize, le: &[u8]) -> Self {
        let mut raw = le.to_vec();
        if self.big {
            raw.reverse();
        }
        self.bytes[at..at + raw.len()].copy_from_slice(&raw);
        self
    }
    pub(crate) fn i16(self, at: usize, v: i16) -> Self {
        self.put(at, &v.to_le_bytes())
    }
    pub(crate) fn i32(self, at: usize, v: i32) -> Self {
        self.put(at, &v.to_le_bytes())
    }
    pub(crate) fn i64(self, at: usize, v: i64) -> Self {
        self.put(at, &v.to_le_bytes())
    }
    pub(crate) fn f32(self, at: usize, v: f32) -> Self {
        self.put(at, &v.to_le_bytes())
    }
    pub(crate) fn f64(self, at: usize, v: f64) -> Self {
        self.put(at, &v.to_le_bytes())
    }
    pub(crate) fn magic(mut self, at: usize, magic: &[u8]) -> Self {
        self.bytes[at..at + magic.len()].copy_from_slice(magic);
        self
    }

    /// A 3×2×2 int16 NIfTI-1 header with unit pixdim, vox_offset 352, no transform.
    pub(crate) fn nifti1(big: bool) -> Self {
        let h = Hdr {
            bytes: vec![0; 352],
            big,
        };
        let h = h.i32(0, 348).magic(344, b"n+1\0").i16(70, 4).i16(72, 16);
        let h = [3, 3, 2, 2, 1, 1, 1, 1]
            .iter()
            .enumerate()
            .fold(h, |h, (n, &d)| h.i16(40 + 2 * n, d));
        let h = (0..4).fold(h, |h, n| h.f32(76 + 4 * n, 1.0));
        h.f32(108, 352.0).i16(252, 0).i16(254, 0)
    }

    /// The same as a NIfTI-2 header (540 bytes + 4 extension bytes, vox_offset 544).
    pub(crate) fn nifti2(big: bool) -> Self {
        let h = Hdr {
            bytes: vec![0; 544],
            big,
        };
        let h = h
            .i32(0, 540)
            .magic(4, b"n+2\0\r\n\x1a\n")
            .i16(12, 4)
            .i16(14, 16);
        let h = [3, 3, 2, 2, 1, 1, 1, 1]
            .iter()
            .enumerate()
            .fold(h, |h, (n, &d)| h.i64(16 + 8 * n, d));
        let h = (0..4).fold(h, |h, n| h.f64(104 + 8 * n, 1.0));
        h.i64(168, 544)
    }

    /// Appends twelve int16 samples -6, -5, ... 5 in the header's byte order.
    pub(crate) fn with_samples(self) -> Vec<u8> {
        let mut out = self.bytes;
        for v in -6i16..6 {
            let b = if self.big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            };
            out.extend_from_slice(&b);
        }
        out
    }
}

/// A scratch directory for the files one test writes.
pub(crate) fn scratch() -> TempDir {
    tempfile::tempdir().unwrap()
}

pub(crate) fn write_temp(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

pub(crate) fn assert_samples(loaded: &endocast_io::Loaded) {
    let v = &loaded.volume;
    assert_eq!(v.dims(), [3, 2, 2]);
    assert_eq!(v.physical(0, 0, 0), Some(-6.0));
    assert_eq!(v.physical(1, 0, 0), Some(-5.0));
    assert_eq!(v.physical(0, 1, 0), Some(-3.0));
    assert_eq!(v.physical(2, 1, 1), Some(5.0));
}

#[test]
fn nifti2_both_byte_orders_with_an_sform() {
    let dir = scratch();
    for big in [false, true] {
        // sform: 2 mm voxels, RAS axes, origin (10, 20, 30) RAS.
        let h = Hdr::nifti2(big)
            .i32(348, 1)
            .f64(400, 2.0)
            .f64(424, 10.0)
            .f64(440, 2.0)
            .f64(456, 20.0)
            .f64(480, 2.0)
            .f64(488, 30.0);
        let path = write_temp(&dir, "two.nii", &h.with_samples());
        let loaded = read(&path).unwrap();
        assert_samples(&loaded);
        let g = loaded.volume.geometry();
        assert_eq!(g.spacing_mm(), DVec3::splat(2.0));
        assert_eq!(g.origin_mm(), DVec3::new(-10.0, -20.0, 30.0));
        assert_eq!(g.orientation_code(), "RAS");
        let expected = if big {
            "int16 (NIfTI-2, big-endian)"
        } else {
            "int16 (NIfTI-2)"
        };
        assert_eq!(loaded.source.stored_type, expected);
    }
}

#[test]
fn big_endian_nifti1_with_scaling() {
    let dir = scratch();
    let h = Hdr::nifti1(true).f32(112, 2.0).f32(116, 1.0).i16(254, 1);
    let h = h.f32(280, 1.0).f32(300, 1.0).f32(320, 1.0);
    let path = write_temp(&dir, "be.nii", &h.with_samples());
    let loaded = read(&path).unwrap();
    assert_eq!(loaded.volume.physical(0, 0, 0), Some(-11.0));
    assert_eq!(loaded.volume.physical(2, 1, 1), Some(11.0));
    assert_eq!(loaded.source.stored_type, "int16 (NIfTI-1, big-endian)");
}

#[test]
fn qform_only_quaternion_and_qfac() {
    let dir = scratch();
    // A 90° turn about z: i runs anterior, j towards the left (RAS −x); qfac −1 flips k.
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let h = Hdr::nifti1(false).i16(252, 1).f32(264, s).f32(76, -1.0);
    let h = h.f32(80, 0.5).f32(84, 0.75).f32(88, 2.0);
    let h = h.f32(268, 5.0).f32(272, -6.0).f32(276, 7.0);
    let loaded = read(&write_temp(&dir, "q.nii", &h.with_samples())).unwrap();
    assert_samples(&loaded);
    let g = loaded.volume.geometry();
    assert_eq!(g.orientation_code(), "ALI");
    assert!(
        (g.spacing_mm() - DVec3::new(0.5, 0.75, 2.0))
            .abs()
            .max_element()
            < 1e-6
    );
    assert_eq!(g.origin_mm(), DVec3::new(-5.0, 6.0, 7.0));
}

#[test]
fn missing_transforms_warn_and_use_pixdim() {
    let dir = scratch();
    let h = Hdr::nifti1(false).f32(80, 0.5);
    let loaded = read(&write_temp(&dir, "p.nii", &h.with_samples())).unwrap();
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert_eq!(
        loaded.volume.geometry().spacing_mm(),
        DVec3::new(0.5, 1.0, 1.0)
    );
}

#[test]
fn four_d_series_reads_the_first_volume_with_a_warning() {
    let dir = scratch();
    let h = Hdr::nifti1(false).i16(40, 4).i16(46, 1).i16(48, 2);
    let mut bytes = h.with_samples();
    bytes.extend_from_slice(&[0xff; 24]);
    let loaded = read(&write_temp(&dir, "4d.nii", &bytes)).unwrap();
    assert_eq!(loaded.volume.dims(), [3, 2, 1]);
    assert_eq!(
        loaded.warnings.len(),
        2,
        "4-D and no transform: {:?}",
        loaded.warnings
    );
}

fn assert_fails(dir: &TempDir, name: &str, bytes: &[u8]) -> ReadError {
    let path = write_temp(dir, name, bytes);
    match read(&path) {
        Err(e) => {
            eprintln!("{name}: {e}");
            assert_eq!(e.path(), path);
            e
        }
        Ok(_) => panic!("{name} should not read"),
    }
}

pub(crate) fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(bytes).unwrap();
    gz.finish().unwrap()
}

#[test]
fn bad_files_are_errors() {
    let dir = scratch();
    let good = Hdr::nifti1(false).with_samples();
    assert_fails(&dir, "empty.nii", &[]);
    assert_fails(&dir, "short-header.nii", &good[..200]);
    assert_fails(&dir, "short-header.nii.gz", &gzip(&good[..200]));
    assert_fails(&dir, "short-data.nii", &good[..good.len() - 1]);
    assert_fails(&dir, "short-data.nii.gz", &gzip(&good[..good.len() - 1]));
    assert_fails(&dir, "not-nifti.nii", &[7u8; 400]);
    assert_fails(
        &dir,
        "garbage.nii.gz",
        &[0x1f, 0x8b, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10],
    );
    let bad_headers = [
        ("zero-dim", Hdr::nifti1(false).i16(44, 0)),
        ("negative-dim", Hdr::nifti1(false).i16(42, -3)),
        ("rank-zero", Hdr::nifti1(false).i16(40, 0)),
        ("rank-nine", Hdr::nifti1(false).i16(40, 9)),
        ("nan-pixdim", Hdr::nifti1(false).f32(80, f32::NAN)),
        ("inf-pixdim", Hdr::nifti1(false).f32(84, f32::INFINITY)),
        ("vox-offset-beyond", Hdr::nifti1(false).f32(108, 1.0e6)),
        ("vox-offset-in-header", Hdr::nifti1(false).f32(108, 100.0)),
        ("vox-offset-nan", Hdr::nifti1(false).f32(108, f32::NAN)),
        ("pair", Hdr::nifti1(false).magic(344, b"ni1\0")),
        ("bad-magic", Hdr::nifti1(false).magic(344, b"xyz\0")),
        (
            "nan-sform",
            Hdr::nifti1(false).i16(254, 1).f32(280, f32::NAN),
        ),
        ("flat-sform", Hdr::nifti1(false).i16(254, 1).f32(280, 1.0)),
        (
            "nan-quaternion",
            Hdr::nifti1(false).i16(252, 1).f32(256, f32::NAN),
        ),
    ];
    for (name, h) in bad_headers {
        let bytes = h.with_samples();
        assert_fails(&dir, &format!("{name}.nii"), &bytes);
        assert_fails(&dir, &format!("{name}.nii.gz"), &gzip(&bytes));
    }
    for code in [128i16, 32, 1, 9999] {
        let e = assert_fails(
            &dir,
            "rgb.nii",
            &Hdr::nifti1(false).i16(70, code).with_samples(),
        );
        assert!(matches!(e, ReadError::Unsupported { .. }), "{e}");
        assert!(e.to_string().contains(&code.to_string()), "{e}");
    }
}

/// A `.hdr` (magic `ni1`, vox_offset 0) and the `.img` holding its samples read like the single
/// file, plain or gzip, whatever the case of the names; without its `.img` it is an error
/// naming the `.img`.
#[test]
fn header_and_image_pairs_read_like_single_files() {
    let dir = scratch();
    let single = Hdr::nifti1(false).with_samples();
    let header = &Hdr::nifti1(false).magic(344, b"ni1\0").f32(108, 0.0).bytes[..348];
    let samples = &single[352..];
    for (hdr, img, pack) in [
        ("a.hdr", "a.img", false),
        ("B.HDR", "B.IMG", false),
        ("c.hdr.gz", "c.img.gz", true),
    ] {
        let pack = |bytes: &[u8]| if pack { gzip(bytes) } else { bytes.to_vec() };
        write_temp(&dir, img, &pack(samples));
        let path = write_temp(&dir, hdr, &pack(header));
        let loaded = open(&path, &OpenOptions::default()).unwrap();
        assert_samples(&loaded);
    }
    std::fs::remove_file(dir.path().join("a.img")).unwrap();
    let e = read(&dir.path().join("a.hdr")).unwrap_err();
    assert!(e.to_string().contains("a.img"), "{e}");
}

#[test]
fn huge_dims_hit_the_limit_before_allocating() {
    let dir = scratch();
    let h = Hdr::nifti1(false)
        .i16(42, 30000)
        .i16(44, 30000)
        .i16(46, 30000);
    let path = write_temp(&dir, "huge.nii", &h.with_samples());
    let mut options = OpenOptions::default();
    options.limits = Limits::with_max_voxels(1_000_000);
    let e = nifti::read(&path, &options).unwrap_err();
    assert!(matches!(e, ReadError::Limit { .. }), "{e}");
    let h = Hdr::nifti2(false).i64(24, i64::MAX).i64(32, i64::MAX);
    let e = nifti::read(&write_temp(&dir, "huge2.nii", &h.with_samples()), &options).unwrap_err();
    assert!(matches!(e, ReadError::Limit { .. }), "{e}");
    // Within the limit but far larger than the file: refused before the voxels are allocated.
    let h = Hdr::nifti1(false).i16(42, 1000).i16(44, 1000);
    let e = read(&write_temp(&dir, "lying.nii", &h.with_samples())).unwrap_err();
    assert!(matches!(e, ReadError::Format { .. }), "{e}");
}
