//! An overlay drawn with a scan: a DICOM segmentation's segments, or a dose grid's isodose
//! levels, as surfaces in a [`Scene`] (read by [`crate::dicom::read_overlay`]). The one place
//! the command line (`--overlay FILE[:LEVELS]`), the workstation and Python turn an overlay
//! into geometry, so all three draw the same surfaces in the same colours.

use crate::dicom::{read_overlay, OverlayKind, Segment};
use crate::error::ReadError;
use crate::Limits;
use endocast_core::isosurface::{isosurface, label_surface};
use endocast_core::navigate::LumenSide;
use endocast_core::scene::{Material, MeshError, Scene, TriangleMesh};
use endocast_core::Volume;
use std::path::Path;
use thiserror::Error;

/// The opacity of a segment's surface.
const SEGMENT_OPACITY: f32 = 1.0;
/// The opacity of an isodose surface (nested shells must show through one another).
const ISODOSE_OPACITY: f32 = 0.35;
/// The isodose levels drawn when none are given, as shares of the grid's maximum dose.
const DEFAULT_ISODOSE_SHARES: [f64; 3] = [0.5, 0.8, 0.95];
/// Colours of the isodose surfaces, lowest level first (then repeated).
const ISODOSE_COLOURS: [[f32; 3]; 3] = [[0.2, 0.4, 1.0], [0.2, 0.8, 0.3], [0.95, 0.2, 0.15]];

/// An overlay that cannot be drawn.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum OverlayError {
    /// The specification `FILE[:LEVELS]` is unusable.
    #[error("overlay {spec}: {message}")]
    Spec {
        /// The specification as given.
        spec: String,
        /// What is wrong with it.
        message: String,
    },
    /// The file cannot be read as an overlay.
    #[error("cannot read the overlay: {0}")]
    Read(#[from] ReadError),
    /// A surface cannot be made (the file and the segment or level are named).
    #[error("{what} of {file}: {message}")]
    Surface {
        /// The segment or isodose level.
        what: String,
        /// The overlay's file.
        file: String,
        /// Why.
        message: String,
    },
}

/// What [`add_overlay`] drew.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawn {
    /// A line saying what was added: each segment's label and volume, each isodose level, and
    /// why any was not drawn.
    pub summary: String,
    /// Whether every segment or level asked for was drawn.
    pub complete: bool,
}

/// Adds the surfaces of the overlay `spec` (`FILE`, or `FILE:LEVEL,LEVEL,…` for a dose grid,
/// levels in its dose units) to `scene`, and says what it drew.
pub fn add_overlay(scene: &mut Scene, spec: &str, limits: &Limits) -> Result<Drawn, OverlayError> {
    let (file, levels) = split_levels(spec)?;
    let overlay = read_overlay(Path::new(file), limits)?;
    let parts = match (&overlay.kind, levels) {
        (OverlayKind::Segmentation(segments), None) => {
            add_segments(scene, &overlay.volume, segments, file)?
        }
        (OverlayKind::Segmentation(_), Some(_)) => {
            return Err(spec_error(
                spec,
                "levels apply to a dose grid, not to a segmentation",
            ))
        }
        (OverlayKind::Dose { units }, levels) => {
            add_isodoses(scene, &overlay.volume, levels, units, file)?
        }
    };
    let complete = !parts.is_empty() && parts.iter().all(|(_, drawn)| *drawn);
    let drawn = if parts.is_empty() {
        "nothing to draw".to_string()
    } else {
        let texts: Vec<&str> = parts.iter().map(|(text, _)| text.as_str()).collect();
        texts.join(", ")
    };
    Ok(Drawn {
        summary: format!("overlay {file}: {drawn}"),
        complete,
    })
}

/// Adds each segment's surface; returns each segment's label and volume (and why it is not
/// drawn), and whether it is.
fn add_segments(
    scene: &mut Scene,
    volume: &Volume,
    segments: &[Segment],
    file: &str,
) -> Result<Vec<(String, bool)>, OverlayError> {
    let spacing = volume.geometry().spacing_mm();
    let voxel_ml = spacing.x * spacing.y * spacing.z / 1000.0;
    let mut parts = Vec::new();
    for segment in segments {
        let voxels = volume.voxels().iter().filter(|&&v| v == segment.number);
        let voxels = voxels.count();
        if voxels == 0 {
            continue;
        }
        let size = format!("{} {:.1} ml", segment.label, voxels as f64 * voxel_ml);
        let mesh = label_surface(volume, segment.number);
        let what = format!("segment {}", segment.number);
        let material = (segment.colour, SEGMENT_OPACITY);
        add_surface(scene, mesh, material, &what, file)?;
        parts.push((size, true));
    }
    Ok(parts)
}

/// Adds the isodose surfaces at `levels` (default shares of the maximum); returns each level
/// (and why it is not drawn), and whether it is.
fn add_isodoses(
    scene: &mut Scene,
    volume: &Volume,
    levels: Option<Vec<f64>>,
    units: &str,
    file: &str,
) -> Result<Vec<(String, bool)>, OverlayError> {
    let (_, max) = volume.physical_range();
    let levels = levels.unwrap_or_else(|| DEFAULT_ISODOSE_SHARES.map(|s| s * max).to_vec());
    let mut parts = Vec::new();
    for (n, &level) in levels.iter().enumerate() {
        if !(level > 0.0 && level < max) {
            parts.push((
                format!("{level} {units} (none: the grid's maximum is {max:.2})"),
                false,
            ));
            continue;
        }
        let mesh = isosurface(volume, level, LumenSide::Above);
        let colour = ISODOSE_COLOURS[n % ISODOSE_COLOURS.len()];
        let what = format!("isodose {level}");
        add_surface(scene, mesh, (colour, ISODOSE_OPACITY), &what, file)?;
        parts.push((format!("{level:.2} {units}"), true));
    }
    Ok(parts)
}

/// Adds `mesh` in `(colour, opacity)`; an error names `what` of `file`.
fn add_surface(
    scene: &mut Scene,
    mesh: Result<TriangleMesh, MeshError>,
    (colour, opacity): ([f32; 3], f32),
    what: &str,
    file: &str,
) -> Result<(), OverlayError> {
    let error = |message: String| OverlayError::Surface {
        what: what.to_string(),
        file: file.to_string(),
        message,
    };
    let mesh = mesh.map_err(|e| error(e.to_string()))?;
    let material = Material::new(colour, opacity).map_err(|e| error(e.to_string()))?;
    scene.add_mesh(&mesh, material);
    Ok(())
}

/// [`OverlayError::Spec`] for `spec`.
fn spec_error(spec: &str, message: &str) -> OverlayError {
    OverlayError::Spec {
        spec: spec.to_string(),
        message: message.to_string(),
    }
}

/// `FILE` and, after the last `:`, dose levels when what follows is a list of numbers.
fn split_levels(spec: &str) -> Result<(&str, Option<Vec<f64>>), OverlayError> {
    let Some((file, tail)) = spec.rsplit_once(':') else {
        return Ok((spec, None));
    };
    let levels: Option<Vec<f64>> = tail
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok())
        .collect();
    match levels {
        Some(levels) if levels.iter().all(|l| l.is_finite()) => Ok((file, Some(levels))),
        Some(_) => Err(spec_error(spec, "the levels must be finite numbers")),
        None => Ok((spec, None)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use endocast_testdata::overlays::{write_dose, write_segmentation, Grid, SegFrame};

    #[test]
    fn levels_follow_the_last_colon() {
        assert_eq!(split_levels("dose.dcm").unwrap(), ("dose.dcm", None));
        assert_eq!(
            split_levels("dose.dcm:20,40.5").unwrap(),
            ("dose.dcm", Some(vec![20.0, 40.5]))
        );
        assert_eq!(split_levels("c:/x.dcm").unwrap(), ("c:/x.dcm", None));
        assert!(split_levels("dose.dcm:NaN").is_err());
    }

    /// A 4 × 4 × 3 mm grid of 1 mm voxels at the origin.
    const GRID: Grid = Grid {
        origin: [0.0, 0.0, 0.0],
        spacing: [1.0, 1.0],
        size: [4, 4],
    };

    #[test]
    fn a_segment_becomes_one_surface_named_with_its_volume() {
        let dir = tempfile::tempdir().unwrap();
        let seg = dir.path().join("seg.dcm");
        let pixels: Vec<(usize, usize)> =
            (1..3).flat_map(|r| (1..3).map(move |c| (r, c))).collect();
        let frames: Vec<SegFrame> = (0..3)
            .map(|z| SegFrame {
                segment: 1,
                z: f64::from(z),
                pixels: pixels.clone(),
            })
            .collect();
        write_segmentation(&seg, &GRID, &[(1, "node", [34865, 53485, 50171])], &frames);
        let mut scene = Scene::new();
        let said = add_overlay(&mut scene, seg.to_str().unwrap(), &Limits::default()).unwrap();
        assert!(
            said.complete && said.summary.ends_with("node 0.0 ml"),
            "{said:?}"
        );
        assert!(!scene.is_empty());
        let levels = format!("{}:5", seg.display());
        let refused = add_overlay(&mut Scene::new(), &levels, &Limits::default()).unwrap_err();
        assert!(
            refused.to_string().contains("levels apply to a dose grid"),
            "{refused}"
        );
        // One voxel wide: still a surface.
        let thin = dir.path().join("thin.dcm");
        let line: Vec<SegFrame> = (0..3)
            .map(|z| SegFrame {
                segment: 2,
                z: f64::from(z),
                pixels: vec![(1, 1)],
            })
            .collect();
        write_segmentation(&thin, &GRID, &[(2, "line", [34865, 53485, 50171])], &line);
        let mut scene = Scene::new();
        let said = add_overlay(&mut scene, thin.to_str().unwrap(), &Limits::default()).unwrap();
        assert!(
            said.complete && said.summary.ends_with("line 0.0 ml"),
            "{said:?}"
        );
        assert!(!scene.is_empty());
    }

    #[test]
    fn a_dose_grid_draws_the_levels_inside_its_range_and_names_the_others() {
        let dir = tempfile::tempdir().unwrap();
        let dose = dir.path().join("dose.dcm");
        // A peak of 10 Gy in the middle of three frames of 4 × 4.
        let samples: Vec<u32> = (0..48)
            .map(|i| {
                if [21, 22, 25, 26].contains(&i) {
                    100
                } else {
                    0
                }
            })
            .collect();
        write_dose(&dose, &GRID, &[0.0, 1.0, 2.0], 0.1, &samples);
        let mut scene = Scene::new();
        let spec = format!("{}:5,20", dose.display());
        let said = add_overlay(&mut scene, &spec, &Limits::default()).unwrap();
        assert!(
            !said.complete && said.summary.contains("5.00 GY"),
            "{said:?}"
        );
        let none = "20 GY (none: the grid's maximum is 10.00)";
        assert!(said.summary.contains(none), "{said:?}");
        assert!(!scene.is_empty());
    }

    #[test]
    fn a_missing_file_is_named() {
        let error = add_overlay(&mut Scene::new(), "/no/such/seg.dcm", &Limits::default());
        let message = error.unwrap_err().to_string();
        assert!(message.contains("/no/such/seg.dcm"), "{message}");
    }
}
