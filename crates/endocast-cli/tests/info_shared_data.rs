//! Every scan in `../shared/data` loads through `endocast info` with the dimensions, spacing
//! and value range its README gives.

use crate::common::{info_json, numbers};
use endocast_testdata::shared_data;

/// One dataset and what its README says.
struct Expected {
    path: &'static str,
    /// Dimensions; `0` where the reader may legitimately change it (resampled uneven slices).
    dims: [usize; 3],
    spacing_mm: [f64; 3],
    /// Smallest and largest physical value, each with a tolerance.
    min: (f64, f64),
    max: (f64, f64),
}

const EXPECTED: &[Expected] = &[
    Expected {
        path: "head-ct-stanford-cthead/CThead.nhdr",
        dims: [256, 256, 113],
        spacing_mm: [1.0, 1.0, 2.0],
        min: (0.0, 0.0),
        max: (3272.0, 0.0),
    },
    Expected {
        path: "abdomen-ct-pancreas-dicom",
        dims: [512, 512, 134],
        spacing_mm: [1.0742, 1.0742, 3.0],
        min: (-1000.0, 0.0),
        max: (1988.0, 0.0),
    },
    Expected {
        path: "chest-ct-airways-dicom",
        dims: [512, 512, 72],
        spacing_mm: [0.9766, 0.9766, 2.0],
        min: (-1024.0, 0.0),
        max: (2976.0, 150.0),
    },
    Expected {
        path: "aorta-stent-cta/stent.nrrd",
        dims: [128, 128, 256],
        spacing_mm: [1.0, 1.0, 1.0],
        min: (0.0, 0.0),
        max: (2000.0, 0.0),
    },
    Expected {
        path: "brain-mri-t1/chris_t1.nii.gz",
        dims: [188, 256, 190],
        spacing_mm: [0.88, 0.88, 0.88],
        min: (0.0, 0.0),
        max: (255.0, 0.0),
    },
    Expected {
        path: "brain-mri-flair-nrrd/FLAIR.nrrd",
        dims: [124, 160, 140],
        spacing_mm: [1.0, 1.0, 1.0],
        min: (0.0, 0.0),
        max: (255.0, 0.0),
    },
    Expected {
        path: "knee-mri/knee3D_dataT.mha",
        dims: [128, 64, 128],
        spacing_mm: [1.0, 0.96875, 1.0],
        min: (0.0, 2.0),
        max: (199.0, 10.0),
    },
    Expected {
        path: "knee-mri/knee3D_dataR.mha",
        dims: [128, 64, 128],
        spacing_mm: [1.0, 0.96875, 1.0],
        min: (0.0, 2.0),
        max: (199.0, 10.0),
    },
    Expected {
        path: "classic-vtk-headsq/quarter.nhdr",
        dims: [64, 64, 93],
        spacing_mm: [3.2, 3.2, 1.5],
        min: (0.0, 0.0),
        max: (3926.0, 0.0),
    },
    Expected {
        path: "classic-vtk-headsq/quarter_nospace.nhdr",
        dims: [64, 64, 93],
        spacing_mm: [3.2, 3.2, 1.5],
        min: (0.0, 0.0),
        max: (3926.0, 0.0),
    },
    Expected {
        path: "classic-engine-ct/engine.nii.gz",
        dims: [256, 256, 128],
        spacing_mm: [1.0, 1.0, 1.0],
        min: (0.0, 0.0),
        max: (255.0, 0.0),
    },
    Expected {
        path: "dicom-transfer-syntaxes/1.dcm",
        dims: [64, 64, 35],
        spacing_mm: [3.25, 3.25, 3.6],
        min: (0.0, 0.0),
        max: (2362.0, 0.0),
    },
    // Gantry tilt with uneven gaps: the reader resamples along the stack, so the slice count and
    // the stack step are its own; the padding (-1500) is replaced by the lowest real value, and
    // interpolated interior slices blend the brightest voxel (2121 HU) down a little.
    Expected {
        path: "head-ct-ge-gantry-tilt",
        dims: [512, 512, 0],
        spacing_mm: [0.488, 0.488, 0.0],
        min: (-1250.0, 250.0),
        max: (2121.0, 60.0),
    },
];

#[test]
fn every_shared_scan_matches_its_readme() {
    let Some(root) = shared_data("") else { return };
    for e in EXPECTED {
        let path = root.join(e.path);
        let report = info_json(path.to_str().expect("utf-8 path"), &[]);
        let dims = numbers(&report["dimensions"]);
        let spacing = numbers(&report["spacing_mm"]);
        let range = numbers(&report["value_range"]);
        for axis in 0..3 {
            if e.dims[axis] != 0 {
                assert_eq!(
                    dims[axis], e.dims[axis] as f64,
                    "{}: dimension {axis}",
                    e.path
                );
            }
            if e.spacing_mm[axis] != 0.0 {
                assert!(
                    (spacing[axis] - e.spacing_mm[axis]).abs() < 1e-3,
                    "{}: spacing {axis} is {}",
                    e.path,
                    spacing[axis]
                );
            }
        }
        assert!(
            (range[0] - e.min.0).abs() <= e.min.1,
            "{}: min {}",
            e.path,
            range[0]
        );
        assert!(
            (range[1] - e.max.0).abs() <= e.max.1,
            "{}: max {}",
            e.path,
            range[1]
        );
    }
}

#[test]
fn dicom_ct_reports_modality_series_and_hounsfield_units() {
    let Some(root) = shared_data("") else { return };
    let report = info_json(
        root.join("abdomen-ct-pancreas-dicom").to_str().unwrap(),
        &[],
    );
    assert_eq!(report["format"], "DICOM");
    assert_eq!(report["modality"], "CT");
    assert_eq!(report["value_unit"], "HU");
    assert!(report["series_uid"]
        .as_str()
        .is_some_and(|uid| !uid.is_empty()));
}

#[test]
fn gantry_tilt_is_reported_not_silenced() {
    let Some(root) = shared_data("") else { return };
    let report = info_json(root.join("head-ct-ge-gantry-tilt").to_str().unwrap(), &[]);
    assert_eq!(
        report["orthogonal"], false,
        "the tilted stack keeps its shear"
    );
    let warnings = report["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .any(|w| w.as_str().unwrap().to_lowercase().contains("tilt")),
        "warnings: {warnings:?}"
    );
}

/// A folder of one DICOM image and a note: `info` and `render` print the "skipped" note once,
/// and `info`'s numbers carry no padding zeros, negative zeros or "+ -" offsets.
#[test]
fn the_skipped_note_appears_once_and_info_numbers_read_cleanly() {
    let Some(source) = shared_data("dicom-transfer-syntaxes/1.dcm") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(&source, dir.path().join("1.dcm")).unwrap();
    std::fs::write(dir.path().join("notes.txt"), "not an image").unwrap();
    let folder = dir.path().to_str().unwrap();
    let png = dir.path().join("v.png");
    for args in [
        vec!["info", folder],
        vec![
            "render",
            folder,
            "--size",
            "16x16",
            "-o",
            png.to_str().unwrap(),
        ],
    ] {
        let out = crate::common::endocast(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let all = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            all.matches("skipped 1 file that is").count(),
            1,
            "{args:?}: {all}"
        );
        if args[0] == "info" {
            assert!(
                !all.contains(".0000") && !all.contains("+ -") && !all.contains("-0,"),
                "{all}"
            );
            assert!(all.contains("physical = stored\n"), "{all}");
        }
    }
}
