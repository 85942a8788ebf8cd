//! `endocast coverage`: the review of what a flight missed. The route (a path file, or the
//! study's automatic path as `endocast path` plans it) is flown forward, and back unless
//! `--forward-only`; the wall never seen is split into patches, each listed with its area,
//! centroid and a camera that sees it; a view of each is rendered (written with `--views`) and
//! added to the coverage, which is given before and after the review.

use crate::commands::fly::lumen_at_start;
use crate::commands::path::plan;
use crate::input::InputArgs;
use crate::look::{set_threads, LookArgs, ScanLook};
use crate::lumen::LumenArgs;
use crate::optics::LensArgs;
use crate::parse::parse_size;
use crate::progress::Progress;
use crate::study_report;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::flight::{
    review, FlightOptions, Layout, PatchView, Review, ReviewRequest, Route, DEFAULT_MIN_AREA_MM2,
    REVIEW_AREA_MM2, REVIEW_STEP_MM,
};
use endocast_core::path::SmoothOptions;
use endocast_core::render::Renderer;
use endocast_core::study::LOOK_AHEAD_MM;
use endocast_core::views::Image;
use endocast_io::review_json;
use endocast_io::route_file::read_route;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Arguments of `endocast coverage`.
#[derive(Args, Debug)]
pub struct CoverageArgs {
    #[command(flatten)]
    input: InputArgs,
    /// The route, as for `endocast fly`; without it, the automatic path through the structure
    /// the preset finds (as `endocast path` plans it).
    #[arg(long = "path", value_name = "FILE")]
    route: Option<PathBuf>,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    lumen: LumenArgs,
    #[command(flatten)]
    lens: LensArgs,
    /// Vertical field of view of the flight, degrees (default: the preset's, else 90); each
    /// patch's view has the field that holds the patch (30–120°).
    #[arg(long = "fov", value_name = "DEG")]
    fov_deg: Option<f64>,
    /// Distance between the flight's frames along the route, mm.
    #[arg(long, value_name = "MM", default_value_t = REVIEW_STEP_MM)]
    frame_step: f64,
    /// How far ahead on the path the camera looks, mm.
    #[arg(long, value_name = "MM", default_value_t = LOOK_AHEAD_MM)]
    look_ahead: f64,
    /// Image size of the flight's frames and the patches' views, pixels.
    #[arg(long, value_name = "WxH", default_value = "256x256", value_parser = parse_size)]
    size: [usize; 2],
    /// Smallest patch listed and reviewed, mm² (how many reach 300 mm², the size Pickhardt et
    /// al. review, is said too).
    #[arg(long, value_name = "MM2", default_value_t = DEFAULT_MIN_AREA_MM2)]
    min_area: f64,
    /// Fly the route forward only (default: forward and back, a two-way flight).
    #[arg(long)]
    forward_only: bool,
    /// Write each patch's view here as patch_NNN.png (in the list's order), in the preset's look.
    #[arg(long, value_name = "DIR")]
    views: Option<PathBuf>,
    /// Print the patches and the coverage as JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `endocast coverage`.
pub fn run(args: &CoverageArgs) -> Result<()> {
    set_threads(args.look.threads)?;
    check(args)?;
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let volume = loaded.volume;
    let given = args
        .route
        .as_deref()
        .map(|p| read_route(p).context("cannot read the path"))
        .transpose()?;
    let first = given
        .as_ref()
        .map(|r| r.shots(args.frame_step, args.look_ahead))
        .transpose()
        .context("cannot sample the route")?
        .and_then(|shots| shots.first().map(|s| s.pose));
    let ScanLook {
        settings,
        study,
        look,
    } = args
        .look
        .on_scan(&volume, &args.lumen, first, args.fov_deg)?;
    study_report::say(&study);
    let route = match given {
        Some(route) => route,
        None => {
            // `endocast path`'s smoothing without `--smoothing`: the defaults.
            let options = SmoothOptions::default();
            Route::Path(plan(&volume, &study, None, None, &options)?.planned.path)
        }
    };
    let start = route.points_mm(1.0)?[0];
    let lumen = lumen_at_start(&study, &volume, start)?;
    let (lo, hi) = volume.geometry().world_bounds();
    let optics = args.lens.optics(
        study.preset(),
        look.as_ref(),
        args.fov_deg,
        0.0,
        (hi - lo).length(),
    )?;
    let request = ReviewRequest {
        settings,
        look,
        flight: FlightOptions {
            size: args.size,
            optics,
            stereo: None,
            layout: Layout::Endoscope,
            window: study.window(),
        },
        step_mm: args.frame_step,
        look_ahead_mm: args.look_ahead,
        both_ways: !args.forward_only,
        min_area_mm2: args.min_area,
    };
    if let Some(dir) = &args.views {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let passes = if args.forward_only { 1 } else { 2 };
    let frames = passes * ((route.len_mm() / args.frame_step).ceil() as usize + 1);
    let mut progress = Progress::new("flying", frames);
    let renderer = Arc::new(Renderer::for_many_frames(volume));
    let write_view = |n: usize, _: &PatchView, image: &Image| match &args.views {
        Some(dir) => write_png(&review_json::view_file(dir, n), image),
        None => Ok(()),
    };
    let review = review(
        &renderer,
        &lumen,
        &route,
        &request,
        || progress.step(),
        write_view,
    )?;
    progress.finish();
    let report = review_json::to_json(
        &review,
        args.min_area,
        !args.forward_only,
        args.views.as_deref(),
    );
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        say(&review, args);
    }
    Ok(())
}

/// Refuses options that cannot give a review.
fn check(args: &CoverageArgs) -> Result<()> {
    if !(args.frame_step.is_finite() && args.frame_step > 0.0) {
        bail!(
            "--frame-step must be a positive number of mm, not {}",
            args.frame_step
        );
    }
    if !(args.min_area.is_finite() && args.min_area >= 0.0) {
        bail!(
            "--min-area must be a number of mm² ≥ 0, not {}",
            args.min_area
        );
    }
    Ok(())
}

fn write_png(path: &Path, image: &Image) -> Result<()> {
    endocast_io::image_out::write_png_rgb8(
        path,
        image.width() as u32,
        image.height() as u32,
        image.rgb(),
    )
    .with_context(|| format!("cannot write {}", path.display()))
}

/// The review in words.
fn say(review: &Review, args: &CoverageArgs) {
    let before = 100.0 * review.before().seen_fraction();
    let how = if args.forward_only {
        "flying forward"
    } else {
        "flying both ways"
    };
    println!(
        "coverage: {before:.1} % of {} wall voxels (within {:.1} mm of the path) seen {how}",
        review.flight.wall_voxels(),
        review.reach_mm
    );
    println!(
        "{} unseen patches, {} of at least {} mm² listed, {} of at least {REVIEW_AREA_MM2} mm²",
        review.patches_total,
        review.views.len(),
        args.min_area,
        review_json::at_least(review, REVIEW_AREA_MM2)
    );
    for (n, view) in review.views.iter().enumerate() {
        let c = view.patch.centroid_mm;
        println!(
            "  {n:3}: {:8.1} mm² at {:.1},{:.1},{:.1}",
            view.patch.area_mm2, c.x, c.y, c.z
        );
    }
    println!(
        "coverage after reviewing them: {:.1} %",
        100.0 * review.after.seen_fraction()
    );
}
