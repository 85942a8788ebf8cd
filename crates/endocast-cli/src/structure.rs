//! `--show-structure FILE.png` of `render` and `path`: the structure the preset found, tinted
//! on the three slices through the camera.

use anyhow::{bail, Context, Result};
use endocast_core::study::Study;
use endocast_core::views::slices::SliceOptions;
use endocast_core::views::structure::structure_slices;
use endocast_core::Volume;
use std::path::Path;

/// Edge of each of the three slices, pixels.
const SLICE_PX: usize = 384;

/// Writes the structure `study` found (see [`structure_slices`]) to `path`, through its start,
/// in its slice window. An error when no structure was found (the user placed the camera, or
/// the study frames the object from outside).
pub fn write(path: &Path, volume: &Volume, study: &Study) -> Result<()> {
    let Some(lumen) = study.structure() else {
        bail!(
            "--show-structure shows the structure a --preset finds: give an endoscopic preset \
             and no --eye/--from (no structure was found to show)"
        );
    };
    let pose = study.start_pose();
    let mut options = SliceOptions::default();
    options.size_px = SLICE_PX;
    options.window = study.window();
    let forward = (pose.look_at_mm - pose.eye_mm).normalize_or_zero();
    let sheet = structure_slices(
        volume,
        |v| lumen.contains(v),
        pose.eye_mm,
        forward,
        &options,
    )
    .context("cannot draw the structure's slices")?;
    endocast_io::image_out::write_png_rgb8(
        path,
        sheet.width() as u32,
        sheet.height() as u32,
        sheet.rgb(),
    )
    .with_context(|| format!("cannot write --show-structure {}", path.display()))?;
    eprintln!("structure shown on the slices: {}", path.display());
    Ok(())
}
