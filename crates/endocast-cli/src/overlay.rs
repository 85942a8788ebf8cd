//! `--overlay FILE[:LEVELS]`: a DICOM segmentation's segments, or a dose grid's isodose
//! levels, as surfaces in the scene (see [`endocast_io::dicom::read_overlay`]).

use anyhow::{bail, Context, Result};
use endocast_core::isosurface::{isosurface, label_surface};
use endocast_core::navigate::LumenSide;
use endocast_core::scene::{Material, Scene};
use endocast_io::dicom::{read_overlay, OverlayKind};
use endocast_io::Limits;
use std::path::Path;

/// The opacity of a segment's surface.
const SEGMENT_OPACITY: f32 = 1.0;
/// The opacity of an isodose surface (nested shells must show through one another).
const ISODOSE_OPACITY: f32 = 0.35;
/// The isodose levels drawn without `:LEVELS`, as shares of the grid's maximum dose.
const DEFAULT_ISODOSE_SHARES: [f64; 3] = [0.5, 0.8, 0.95];
/// Colours of the isodose surfaces, lowest level first (then repeated).
const ISODOSE_COLOURS: [[f32; 3]; 3] = [[0.2, 0.4, 1.0], [0.2, 0.8, 0.3], [0.95, 0.2, 0.15]];

/// Adds the surfaces of the overlay `spec` (`FILE`, or `FILE:LEVEL,LEVEL,…` for a dose grid,
/// levels in its dose units) to `scene`; returns a line saying what was added.
pub fn add_overlay(scene: &mut Scene, spec: &str) -> Result<String> {
    let (file, levels) = split_levels(spec)?;
    let overlay =
        read_overlay(Path::new(file), &Limits::default()).context("cannot read the overlay")?;
    let volume = &overlay.volume;
    let spacing = volume.geometry().spacing_mm();
    let voxel_ml = spacing.x * spacing.y * spacing.z / 1000.0;
    let mut parts = Vec::new();
    match &overlay.kind {
        OverlayKind::Segmentation(segments) => {
            if levels.is_some() {
                bail!("--overlay {spec}: levels apply to a dose grid, not to a segmentation");
            }
            for segment in segments {
                let voxels = volume
                    .voxels()
                    .iter()
                    .filter(|&&v| v == segment.number)
                    .count();
                if voxels == 0 {
                    continue;
                }
                let mesh = label_surface(volume, segment.number)
                    .with_context(|| format!("segment {} of {file}", segment.number))?;
                scene.add_mesh(&mesh, Material::new(segment.colour, SEGMENT_OPACITY)?);
                parts.push(format!(
                    "{} {:.1} ml",
                    segment.label,
                    voxels as f64 * voxel_ml
                ));
            }
        }
        OverlayKind::Dose { units } => {
            let (_, max) = volume.physical_range();
            let levels = levels.unwrap_or_else(|| DEFAULT_ISODOSE_SHARES.map(|s| s * max).to_vec());
            for (n, &level) in levels.iter().enumerate() {
                if !(level > 0.0 && level < max) {
                    parts.push(format!(
                        "{level} {units} (none: the grid's maximum is {max:.2})"
                    ));
                    continue;
                }
                let mesh = isosurface(volume, level, LumenSide::Above)
                    .with_context(|| format!("isodose {level} of {file}"))?;
                let colour = ISODOSE_COLOURS[n % ISODOSE_COLOURS.len()];
                scene.add_mesh(&mesh, Material::new(colour, ISODOSE_OPACITY)?);
                parts.push(format!("{level:.2} {units}"));
            }
        }
    }
    Ok(format!(
        "overlay {file}: {}",
        if parts.is_empty() {
            "nothing to draw".into()
        } else {
            parts.join(", ")
        }
    ))
}

/// `FILE` and, after the last `:`, dose levels when what follows is a list of numbers.
fn split_levels(spec: &str) -> Result<(&str, Option<Vec<f64>>)> {
    let Some((file, tail)) = spec.rsplit_once(':') else {
        return Ok((spec, None));
    };
    let levels: Option<Vec<f64>> = tail
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok())
        .collect();
    match levels {
        Some(levels) if levels.iter().all(|l| l.is_finite()) => Ok((file, Some(levels))),
        Some(_) => bail!("--overlay {spec}: the levels must be finite numbers"),
        None => Ok((spec, None)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
