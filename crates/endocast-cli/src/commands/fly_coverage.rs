//! The coverage report of `endocast fly --coverage`: the wall seen flying forward, and forward
//! plus backward (the same path flown back), printed and written beside the video; the image
//! and the mask show both passes, named.

use anyhow::{Context, Result};
use endocast_core::flight::{WallSeen, MASK_LABELS};
use endocast_core::navigate::Lumen;
use endocast_core::Geometry;
use serde_json::json;
use std::path::{Path, PathBuf};

/// Size of the coverage overview image, pixels.
const OVERVIEW_PX: usize = 512;

/// Prints the forward and merged figures of `seen` (unless `quiet`: `--json` prints them) and
/// writes, beside `output`, `OUT.coverage.json` (the figures and the mask's labels),
/// `OUT.coverage.png` (the lumen with the wall never seen in red, the wall seen only flying back
/// in orange) and `OUT.coverage.nii.gz` (the mask: 1 seen flying forward, 2 seen only flying
/// back, 3 never seen). Returns the figures.
pub fn report(
    output: &Path,
    geometry: &Geometry,
    lumen: &Lumen,
    seen: &WallSeen,
    quiet: bool,
) -> Result<serde_json::Value> {
    if !quiet {
        println!(
            "coverage: {:.1} % of {} wall voxels seen flying forward, {:.1} % forward + backward",
            100.0 * seen.fraction_forward(),
            seen.wall_voxels(),
            100.0 * seen.fraction_forward_backward()
        );
    }
    let json = json!({
        "wall_voxels": seen.wall_voxels(),
        "seen_forward": seen.seen_forward(),
        "seen_forward_backward": seen.seen_forward_backward(),
        "fraction_forward": seen.fraction_forward(),
        "fraction_forward_backward": seen.fraction_forward_backward(),
        "mask_labels": MASK_LABELS
            .iter()
            .map(|(label, meaning)| (label.to_string(), json!(meaning)))
            .collect::<serde_json::Map<_, _>>(),
        "image": "red: never seen; orange: seen only flying back",
    });
    let text = serde_json::to_string_pretty(&json)?;
    endocast_io::atomic::write_file(&beside(output, "json"), |w| w.write_all(text.as_bytes()))
        .context("cannot write the coverage report")?;
    let overview = seen.overview(lumen, geometry, [OVERVIEW_PX; 2])?;
    let image = &overview.image;
    endocast_io::image_out::write_png_rgb8(
        &beside(output, "png"),
        image.width() as u32,
        image.height() as u32,
        image.rgb(),
    )
    .context("cannot write the coverage image")?;
    let mask = seen.mask_volume()?;
    endocast_io::write(&beside(output, "nii.gz"), &mask)
        .context("cannot write the coverage mask")?;
    Ok(json)
}

/// `OUT.coverage.EXT` beside the output (OUT without its ending).
fn beside(output: &Path, ending: &str) -> PathBuf {
    let mut name = output.with_extension("").into_os_string();
    name.push(format!(".coverage.{ending}"));
    PathBuf::from(name)
}
