//! The coverage report of `endocast fly --coverage`: the wall seen flying forward, and forward
//! plus backward (the same path flown back), printed and written beside the video.

use super::fly::{wall_coverage, FlyArgs};
use crate::progress::Progress;
use anyhow::{Context, Result};
use endocast_core::coverage::Coverage;
use endocast_core::flight::{lumen_overview, Flight, FlightOptions, Layout, Route};
use endocast_core::navigate::Lumen;
use endocast_core::render::{RenderSettings, Renderer};
use endocast_core::views::slices::Window;
use endocast_core::{Modality, ValueMap, Volume};
use serde_json::json;
use std::path::PathBuf;
use std::sync::Arc;

/// Size of the coverage overview image, pixels.
const OVERVIEW_PX: usize = 512;

/// Flies the route backward for coverage, then prints and writes the forward and merged figures.
pub fn report(
    args: &FlyArgs,
    renderer: &Arc<Renderer>,
    route: &Route,
    settings: &RenderSettings,
    lumen: Option<&Lumen>,
    forward: &Coverage,
) -> Result<()> {
    let lumen = lumen.context("coverage needs the lumen")?;
    let geometry = renderer.volume().geometry();
    let mut both = forward.clone();
    if let Some(back) = route.reversed(0.5) {
        let back = back.context("cannot reverse the path")?;
        let backward = fly_for_coverage(
            args,
            renderer,
            &back,
            settings,
            wall_coverage(lumen, geometry)?,
        )?;
        both.merge(&backward)?;
    }
    println!(
        "coverage: {:.1} % of {} wall voxels seen flying forward, {:.1} % forward + backward",
        100.0 * forward.seen_fraction(),
        forward.total(),
        100.0 * both.seen_fraction()
    );
    let json = json!({
        "wall_voxels": forward.total(),
        "seen_forward": forward.seen_count(),
        "seen_forward_backward": both.seen_count(),
        "fraction_forward": forward.seen_fraction(),
        "fraction_forward_backward": both.seen_fraction(),
    });
    let text = serde_json::to_string_pretty(&json)?;
    endocast_io::atomic::write_file(&beside(args, "json"), |w| w.write_all(text.as_bytes()))
        .context("cannot write the coverage report")?;
    let mut overview = lumen_overview(lumen, geometry, [OVERVIEW_PX; 2])?;
    forward.tint_unseen(
        &mut overview.image,
        &overview.camera,
        &overview.depth_mm,
        [230, 40, 40],
        0.8,
    )?;
    let image = &overview.image;
    endocast_io::image_out::write_png_rgb8(
        &beside(args, "png"),
        image.width() as u32,
        image.height() as u32,
        image.rgb(),
    )
    .context("cannot write the coverage image")?;
    let mask = mask_volume(renderer.volume(), forward)?;
    endocast_io::write(&beside(args, "nii.gz"), &mask).context("cannot write the coverage mask")?;
    Ok(())
}

/// Flies `route` with the endoscope only, recording into `coverage`.
fn fly_for_coverage(
    args: &FlyArgs,
    renderer: &Arc<Renderer>,
    route: &Route,
    settings: &RenderSettings,
    coverage: Coverage,
) -> Result<Coverage> {
    let shots = route.shots(args.frame_step, args.look_ahead)?;
    let options = FlightOptions {
        size: args.size,
        fov_deg: args.fov,
        layout: Layout::Endoscope,
        window: Window::AIR_TISSUE,
    };
    let mut flight = Flight::new(Arc::clone(renderer), options).with_coverage(coverage);
    let mut progress = Progress::new("backward", shots.len());
    for (n, shot) in shots.iter().enumerate() {
        flight.frame(n, shot, settings)?;
        progress.step();
    }
    progress.finish();
    flight.into_coverage().context("coverage was not tracked")
}

/// `OUT.coverage.EXT` beside the output (OUT without its ending).
fn beside(args: &FlyArgs, ending: &str) -> PathBuf {
    let mut name = args.output.with_extension("").into_os_string();
    name.push(format!(".coverage.{ending}"));
    PathBuf::from(name)
}

/// The coverage mask as a volume on the scan's grid: 1 seen, 2 unseen wall, 0 elsewhere.
fn mask_volume(scan: &Volume, coverage: &Coverage) -> Result<Volume> {
    let voxels = coverage.mask().into_iter().map(u16::from).collect();
    let map = ValueMap::new(1.0, 0.0)?;
    Ok(Volume::new(
        *scan.geometry(),
        voxels,
        map,
        Modality::Unknown,
    )?)
}
