//! Issue 32, item 5: DICOM segmentations and dose grids read as overlays, in their own
//! geometry, values and positions exact; damaged ones refused with the file named.

use endocast_io::dicom::{read_overlay, OverlayKind};
use endocast_io::Limits;
use endocast_testdata::overlays::{write_dose, write_segmentation, Grid, SegFrame};
use glam::DVec3;

fn grid() -> Grid {
    Grid {
        origin: [1.0, 2.0, 10.0],
        spacing: [0.25, 0.5],
        size: [8, 6],
    }
}

#[test]
fn a_segmentation_becomes_labelled_voxels_on_its_stack() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("seg.dcm");
    let cube: Vec<(usize, usize)> = (1..3).flat_map(|r| (2..5).map(move |c| (r, c))).collect();
    let frames = [
        SegFrame {
            segment: 1,
            z: 10.0,
            pixels: cube.clone(),
        },
        SegFrame {
            segment: 1,
            z: 12.0,
            pixels: cube,
        },
        // No frame at z = 14: that slice is empty, the stack keeps its step.
        SegFrame {
            segment: 2,
            z: 16.0,
            pixels: vec![(4, 6)],
        },
    ];
    let segments = [
        (1, "cube", [34865, 53485, 50171]),
        (2, "dot", [65535, 32896, 32896]),
    ];
    write_segmentation(&path, &grid(), &segments, &frames);
    let overlay = read_overlay(&path, &Limits::default()).unwrap();
    let volume = &overlay.volume;
    assert_eq!(volume.dims(), [8, 6, 4]);
    let g = volume.geometry();
    assert_eq!(g.spacing_mm(), DVec3::new(0.25, 0.5, 2.0));
    assert_eq!(g.origin_mm(), DVec3::new(1.0, 2.0, 10.0));
    let at = |i: usize, j: usize, k: usize| volume.voxels()[i + 8 * (j + 6 * k)];
    assert_eq!(
        (at(2, 1, 0), at(4, 2, 1), at(5, 2, 1), at(2, 1, 2)),
        (1, 1, 0, 0)
    );
    assert_eq!(at(6, 4, 3), 2);
    assert_eq!(volume.voxels().iter().filter(|&&v| v > 0).count(), 13);
    let OverlayKind::Segmentation(segments) = &overlay.kind else {
        panic!("{:?}", overlay.kind)
    };
    assert_eq!(segments.len(), 2);
    assert_eq!(segments[0].label, "cube");
    assert!(segments[0].colour[0] > 0.9 && segments[0].colour[1] < 0.1);
}

#[test]
fn a_dose_grid_keeps_its_doses_and_offsets() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dose.dcm");
    let g = Grid {
        origin: [0.0, 0.0, -5.0],
        spacing: [2.0, 2.0],
        size: [4, 3],
    };
    let samples: Vec<u32> = (0..3u32)
        .flat_map(|f| (0..12u32).map(move |p| 1000 * (f + 1) * (p + 1)))
        .collect();
    write_dose(&path, &g, &[0.0, 3.0, 6.0], 0.001, &samples);
    let overlay = read_overlay(&path, &Limits::default()).unwrap();
    assert!(matches!(&overlay.kind, OverlayKind::Dose { units } if units == "GY"));
    let volume = &overlay.volume;
    assert_eq!(volume.dims(), [4, 3, 3]);
    assert_eq!(volume.geometry().spacing_mm().z, 3.0);
    let map = volume.value_map();
    for (n, &s) in samples.iter().enumerate() {
        let dose = map.physical(volume.voxels()[n]);
        assert!((dose - f64::from(s) * 0.001).abs() < 1e-9, "{n}: {dose}");
    }
    // Samples beyond 16 bits are scaled into them, to 1/65535 of the maximum.
    let big: Vec<u32> = samples.iter().map(|s| s * 1000).collect();
    write_dose(&path, &g, &[0.0, 3.0, 6.0], 1e-6, &big);
    let overlay = read_overlay(&path, &Limits::default()).unwrap();
    let (_, max) = overlay.volume.physical_range();
    assert!((max - 36.0).abs() < 36.0 / 65535.0, "{max}");
    // Given as a scan, it is refused with what to do instead.
    let e = endocast_io::open(&path, &endocast_io::OpenOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("dose grid (RTDOSE)") && e.contains("--overlay"),
        "{e}"
    );
}

#[test]
fn damaged_overlays_are_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dose.dcm");
    let g = grid();
    // Offsets off a regular stack.
    write_dose(&path, &g, &[0.0, 3.0, 7.0], 0.001, &vec![1; 3 * 48]);
    let e = read_overlay(&path, &Limits::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("dose.dcm") && e.contains("off the regular stack"),
        "{e}"
    );
    // Fewer samples than the frames declare.
    write_dose(&path, &g, &[0.0, 3.0, 6.0], 0.001, &vec![1; 2 * 48]);
    let e = read_overlay(&path, &Limits::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("PixelData holds"), "{e}");
    // A grid beyond the limit is refused before it is allocated.
    write_dose(&path, &g, &[0.0, 3.0, 6.0], 0.001, &vec![1; 3 * 48]);
    let e = read_overlay(&path, &Limits::with_max_voxels(100))
        .unwrap_err()
        .to_string();
    assert!(e.contains("limit"), "{e}");
    // A scan is no overlay.
    let ct = dir.path().join("ct.nii");
    std::fs::write(&ct, b"not dicom").unwrap();
    assert!(read_overlay(&ct, &Limits::default()).is_err());
}
