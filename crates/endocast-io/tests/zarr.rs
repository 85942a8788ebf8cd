//! OME-Zarr (issue 37, item 3): endocast's own stores read back exactly; stores as other
//! tools write them (v0.4 / Zarr v2 written here byte by byte) read with their transforms,
//! units and levels; hostile stores give a clear error naming the file, never a panic, a hang
//! or a huge allocation.

use crate::test_volumes::{oblique_ct, scaled_volume, sheared_ct};
use endocast_io::{open, write, Format, Limits, OpenOptions, ReadError};
use glam::DVec3;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Opens `path` on another thread, failing the test after 10 s (a hang would stall the suite).
fn open_within(path: &Path) -> Result<endocast_io::Loaded, ReadError> {
    let path = path.to_path_buf();
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut options = OpenOptions::default();
        options.limits = Limits::with_max_voxels(1 << 24);
        let _ = send.send(open(&path, &options));
    });
    receive
        .recv_timeout(Duration::from_secs(10))
        .expect("the read returns within 10 s")
}

#[test]
fn stores_endocast_writes_read_back_as_their_nifti_twin() {
    let dir = tempfile::tempdir().unwrap();
    for (n, original) in [oblique_ct(), sheared_ct(), scaled_volume()]
        .iter()
        .enumerate()
    {
        let path = dir.path().join(format!("v{n}.zarr"));
        write(&path, original).unwrap();
        let loaded = open(&path, &OpenOptions::default()).unwrap();
        assert_eq!(loaded.source.format, Format::OmeZarr);
        assert!(loaded.source.orientation_declared);
        assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
        // The samples and their value map as the NIfTI reader gives them (int16 HU, or the
        // stored values with their rescale), the geometry exactly.
        let twin = dir.path().join(format!("v{n}.nii"));
        write(&twin, original).unwrap();
        let twin = open(&twin, &OpenOptions::default()).unwrap().volume;
        let (a, e) = (&loaded.volume, original);
        assert_eq!(a.voxels(), twin.voxels(), "{n}");
        assert_eq!(a.value_map(), twin.value_map(), "{n}");
        assert_eq!(a.modality(), e.modality());
        assert_eq!(a.physical(6, 4, 3), e.physical(6, 4, 3));
        assert_eq!(a.geometry().origin_mm(), e.geometry().origin_mm(), "{n}");
        assert_eq!(a.geometry().spacing_mm(), e.geometry().spacing_mm(), "{n}");
        assert!(a
            .geometry()
            .direction()
            .abs_diff_eq(e.geometry().direction(), 1e-12));
    }
}

/// Writes a Zarr v2 OME-Zarr 0.4 image by hand: `.zattrs` holding `attributes`, and one
/// uncompressed `int16` array per entry of `levels` (`(path, shape, samples)`, one chunk).
fn v2_store(dir: &Path, attributes: &Value, levels: &[(&str, Vec<u64>, Vec<i16>)]) -> PathBuf {
    let root = dir.join("image.zarr");
    std::fs::create_dir_all(&root).unwrap();
    std::fs::write(root.join(".zgroup"), br#"{"zarr_format": 2}"#).unwrap();
    std::fs::write(root.join(".zattrs"), attributes.to_string()).unwrap();
    for (path, shape, samples) in levels {
        let folder = root.join(path);
        std::fs::create_dir_all(&folder).unwrap();
        let zarray = json!({
            "zarr_format": 2, "shape": shape, "chunks": shape, "dtype": "<i2",
            "compressor": null, "fill_value": -7, "order": "C", "filters": null,
        });
        std::fs::write(folder.join(".zarray"), zarray.to_string()).unwrap();
        let key = vec!["0"; shape.len()].join(".");
        let bytes: Vec<u8> = samples.iter().flat_map(|s| s.to_le_bytes()).collect();
        std::fs::write(folder.join(key), bytes).unwrap();
    }
    root
}

/// OME-Zarr 0.4 attributes with axes `t, c, z, y, x` (space in micrometres) and two levels.
fn attributes_04() -> Value {
    let axes = json!([
        {"name": "t", "type": "time", "unit": "second"},
        {"name": "c", "type": "channel"},
        {"name": "z", "type": "space", "unit": "micrometer"},
        {"name": "y", "type": "space", "unit": "micrometer"},
        {"name": "x", "type": "space", "unit": "micrometer"},
    ]);
    let level = |path: &str, s: f64, shift: f64| {
        json!({"path": path, "coordinateTransformations": [
            {"type": "scale", "scale": [1.0, 1.0, 3000.0 * s, 2000.0 * s, 1000.0 * s]},
            {"type": "translation", "translation": [0.0, 0.0, shift, shift, shift]},
        ]})
    };
    json!({"multiscales": [{
        "version": "0.4",
        "axes": axes,
        "datasets": [level("0", 1.0, 0.0), level("1", 2.0, 500.0)],
        "coordinateTransformations": [
            {"type": "scale", "scale": [1.0, 1.0, 2.0, 2.0, 2.0]},
            {"type": "translation", "translation": [0.0, 0.0, 10000.0, 20000.0, 30000.0]},
        ],
    }]})
}

/// Level 0: 2 × 3 × 4 samples `z·100 + y·10 + x`; level 1: one sample.
fn levels_04() -> Vec<(&'static str, Vec<u64>, Vec<i16>)> {
    let samples = (0..2)
        .flat_map(|z| (0..3).flat_map(move |y| (0..4).map(move |x| z * 100 + y * 10 + x)))
        .collect();
    vec![
        ("0", vec![1, 1, 2, 3, 4], samples),
        ("1", vec![1, 1, 1, 2, 2], vec![1, 2, 3, 4]),
    ]
}

#[test]
fn an_ome_zarr_04_store_reads_with_its_transforms_units_and_levels() {
    let dir = tempfile::tempdir().unwrap();
    let root = v2_store(dir.path(), &attributes_04(), &levels_04());
    let loaded = open_within(&root).unwrap();
    let volume = &loaded.volume;
    assert_eq!(loaded.source.format, Format::OmeZarr);
    assert!(
        loaded.source.stored_type.contains("OME-Zarr 0.4"),
        "{}",
        loaded.source.stored_type
    );
    assert_eq!(volume.dims(), [4, 3, 2]);
    // Level scale then the multiscale's: 1, 2, 3 µm·1000 = mm, doubled; the translations
    // (µm) scaled by the multiscale's 2 and shifted by its own.
    let g = volume.geometry();
    assert_eq!(g.spacing_mm(), DVec3::new(2.0, 4.0, 6.0));
    assert_eq!(g.origin_mm(), DVec3::new(30.0, 20.0, 10.0));
    assert_eq!(volume.physical(3, 2, 1), Some(123.0));
    assert_eq!(volume.physical(1, 0, 1), Some(101.0));
    assert!(!loaded.source.orientation_declared);
    assert!(loaded
        .warnings
        .iter()
        .any(|w| w.contains("no patient orientation")));
    // Level 1 by its folder: twice the spacing, its own translation (0.5 mm × 2).
    let level = open_within(&root.join("1")).unwrap();
    let g = level.volume.geometry();
    assert_eq!(level.volume.dims(), [2, 2, 1]);
    assert_eq!(g.spacing_mm(), DVec3::new(4.0, 8.0, 12.0));
    assert_eq!(g.origin_mm(), DVec3::new(31.0, 21.0, 11.0));
}

#[test]
fn an_affine_transformation_is_applied() {
    let dir = tempfile::tempdir().unwrap();
    let mut attributes = attributes_04();
    // The 0.6 affine over t, c, z, y, x in place of the level's scale and translation: swap
    // nothing, scale z by 5 and shift x by 7 (before the multiscale's ×2 and shift).
    let mut rows = vec![vec![0.0; 6]; 5];
    for (r, row) in rows.iter_mut().enumerate() {
        row[r] = 1.0;
    }
    rows[2][2] = 5.0;
    rows[4][5] = 7.0;
    attributes["multiscales"][0]["datasets"][0]["coordinateTransformations"] =
        json!([{"type": "affine", "affine": rows}]);
    let root = v2_store(dir.path(), &attributes, &levels_04());
    let g = *open_within(&root).unwrap().volume.geometry();
    // Units: micrometres.
    assert!(g
        .spacing_mm()
        .abs_diff_eq(DVec3::new(0.002, 0.002, 0.01), 1e-15));
    assert!(g
        .origin_mm()
        .abs_diff_eq(DVec3::new(30.014, 20.0, 10.0), 1e-12));
}

/// Asserts that opening `path` fails with a message naming `name` and holding every word.
fn refused(path: &Path, name: &str, words: &[&str]) {
    let message = match open_within(path) {
        Ok(_) => panic!("{} was read", path.display()),
        Err(e) => e.to_string(),
    };
    assert!(message.contains(name), "{message:?} does not name {name}");
    for word in words {
        assert!(message.contains(word), "{message:?} does not say {word:?}");
    }
}

/// A v0.4 store made by `levels_04` after `change` edits its attributes and `spoil` its files.
fn spoiled(dir: &Path, change: impl FnOnce(&mut Value), spoil: impl FnOnce(&Path)) -> PathBuf {
    let mut attributes = attributes_04();
    change(&mut attributes);
    let root = v2_store(dir, &attributes, &levels_04());
    spoil(&root);
    root
}

fn edit_zarray(root: &Path, change: impl FnOnce(&mut Value)) {
    let path = root.join("0/.zarray");
    let mut zarray: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    change(&mut zarray);
    std::fs::write(path, zarray.to_string()).unwrap();
}

/// A hostile store: an edit of the attributes, one of the files, the name the error must give
/// and the words it must hold.
type Case = (
    Box<dyn Fn(&mut Value)>,
    Box<dyn Fn(&Path)>,
    &'static str,
    Vec<&'static str>,
);

#[test]
fn hostile_metadata_is_refused_with_the_file_and_the_problem() {
    let no_change = |_: &mut Value| {};
    let cases: Vec<Case> = vec![
        (
            Box::new(no_change),
            Box::new(|r| std::fs::write(r.join(".zattrs"), b"{\"multiscales\": [").unwrap()),
            ".zattrs",
            vec!["bad JSON"],
        ),
        (
            Box::new(|a| {
                a["multiscales"][0]["datasets"][0]["coordinateTransformations"][0]["scale"][2] =
                    json!("NaN")
            }),
            Box::new(|_| {}),
            ".zattrs",
            vec!["multiscales"],
        ),
        (
            Box::new(|a| {
                a["multiscales"][0]["coordinateTransformations"][0]["scale"][3] = json!(0.0)
            }),
            Box::new(|_| {}),
            ".zattrs",
            vec!["scale of axis 3 is 0"],
        ),
        (
            Box::new(|a| a["multiscales"][0]["axes"][0]["type"] = json!("space")),
            Box::new(|_| {}),
            ".zattrs",
            vec!["unsupported", "axes"],
        ),
        (
            Box::new(|a| a["multiscales"][0]["axes"][4]["unit"] = json!("parsec")),
            Box::new(|_| {}),
            ".zattrs",
            vec!["unit \"parsec\""],
        ),
        (
            Box::new(no_change),
            Box::new(|r| edit_zarray(r, |z| z["shape"] = json!([1, 1, 100_000, 100_000, 100_000]))),
            "image.zarr/0",
            vec!["voxels", "limit"],
        ),
        (
            Box::new(no_change),
            Box::new(|r| {
                edit_zarray(r, |z| {
                    z["chunks"] = json!([1, 1, 1 << 20, 1 << 20, 1 << 20])
                })
            }),
            "chunk",
            vec!["limit"],
        ),
        (
            Box::new(no_change),
            Box::new(|r| edit_zarray(r, |z| z["dtype"] = json!("<c8"))),
            "image.zarr/0",
            vec!["<c8"],
        ),
        (
            Box::new(no_change),
            Box::new(|r| std::fs::write(r.join("0/0.0.0.0.0"), [1u8, 2, 3]).unwrap()),
            "image.zarr/0",
            vec!["cannot decode the chunks"],
        ),
        (
            Box::new(no_change),
            Box::new(|r| {
                edit_zarray(r, |z| z["compressor"] = json!({"id": "gzip", "level": 1}));
            }),
            "image.zarr/0",
            vec!["cannot decode the chunks"],
        ),
        (
            Box::new(no_change),
            Box::new(|r| std::fs::write(r.join("0/0.0.0.0.0"), vec![0u8; 3 << 20]).unwrap()),
            "0.0.0.0.0",
            vec!["chunk file", "limit"],
        ),
    ];
    for (change, spoil, name, words) in cases {
        let dir = tempfile::tempdir().unwrap();
        let root = spoiled(dir.path(), change, spoil);
        refused(&root, name, &words);
    }
}

#[test]
fn a_missing_chunk_is_the_fill_value() {
    let dir = tempfile::tempdir().unwrap();
    let root = spoiled(
        dir.path(),
        |_| {},
        |r| std::fs::remove_file(r.join("0/0.0.0.0.0")).unwrap(),
    );
    let volume = open_within(&root).unwrap().volume;
    assert_eq!(volume.physical_range(), (-7.0, -7.0));
}

#[cfg(unix)]
#[test]
fn a_fifo_in_a_store_is_refused_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let root = spoiled(
        dir.path(),
        |_| {},
        |r| {
            let chunk = r.join("0/0.0.0.0.0");
            std::fs::remove_file(&chunk).unwrap();
            let made = std::process::Command::new("mkfifo").arg(&chunk).status();
            assert!(made.unwrap().success());
        },
    );
    refused(&root, "0.0.0.0.0", &["not a regular file"]);
}
