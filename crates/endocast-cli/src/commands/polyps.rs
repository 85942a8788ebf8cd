//! `endocast polyps`: polyp candidates on the wall of the study's lumen (the colon the
//! colonoscopy preset finds, or the lumen a path starts in) by shape index and curvedness
//! (see `endocast_core::polyps`): listed, as JSON with `--json`, a view of each with
//! `--thumbnails`, and stored as annotations of a case with `--case`.

use crate::input::InputArgs;
use crate::look::{set_threads, LookArgs, ScanLook};
use crate::lumen::LumenArgs;
use crate::optics::LensArgs;
use crate::parse::parse_size;
use crate::study_report;
use anyhow::{Context, Result};
use clap::Args;
use endocast_core::annotate::{Annotations, ScanIdentity};
use endocast_core::flight::{Flight, FlightOptions, Layout, Shot};
use endocast_core::navigate::Lumen;
use endocast_core::polyps::{
    annotations, find_candidates, searched_lumen, view_pose, Candidate, PolypOptions, VIEW_FOV_DEG,
};
use endocast_core::render::Renderer;
use endocast_core::study::Study;
use endocast_core::Volume;
use endocast_io::case::{Case, ScanSource};
use endocast_io::route_file::read_route;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Arguments of `endocast polyps`.
#[derive(Args, Debug)]
pub struct PolypsArgs {
    #[command(flatten)]
    input: InputArgs,
    /// A path file: the wall searched is that of the lumen it starts in (default: the
    /// structure the preset finds, the colon with --preset colonoscopy).
    #[arg(long = "path", value_name = "FILE")]
    route: Option<PathBuf>,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    lumen: LumenArgs,
    #[command(flatten)]
    lens: LensArgs,
    /// Gaussian smoothing before the curvatures, mm.
    #[arg(long, value_name = "MM", default_value_t = PolypOptions::default().sigma_mm)]
    sigma: f64,
    /// Smallest candidate listed, mm: both its size and its cap region's extent across the
    /// wall (narrower than the size, which is the whole protrusion's) must reach it.
    #[arg(long, value_name = "MM", default_value_t = PolypOptions::default().min_size_mm)]
    min_size: f64,
    /// Write a view of each candidate, from the lumen, as polyp_NNN.png (in the list's order,
    /// from 1), the candidates marked, in the preset's look.
    #[arg(long, value_name = "DIR")]
    thumbnails: Option<PathBuf>,
    /// Size of the thumbnails, pixels.
    #[arg(long, value_name = "WxH", default_value = "256x256", value_parser = parse_size)]
    size: [usize; 2],
    /// Add the candidates to this case file as labelled points (made when it does not exist;
    /// it must be of this scan).
    #[arg(long, value_name = "FILE")]
    case: Option<PathBuf>,
    /// Print `{"candidates": [{"centre": [x, y, z], "size_mm", "score"}]}` (LPS mm).
    #[arg(long)]
    json: bool,
}

/// Runs `endocast polyps`.
pub fn run(args: &PolypsArgs) -> Result<()> {
    set_threads(args.look.threads)?;
    let options = PolypOptions {
        sigma_mm: args.sigma,
        min_size_mm: args.min_size,
        ..PolypOptions::default()
    };
    options.check()?;
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let volume = loaded.volume;
    let scan_look = args.look.on_scan(&volume, &args.lumen, None, None)?;
    study_report::say(&scan_look.study);
    let lumen = searched(args, &volume, &scan_look.study)?;
    let candidates = find_candidates(&volume, &lumen, &options)?;
    if let Some(path) = &args.case {
        add_to_case(path, args, &volume, &candidates)?;
    }
    if let Some(dir) = &args.thumbnails {
        thumbnails(dir, args, volume.clone(), &lumen, &scan_look, &candidates)?;
    }
    if args.json {
        let records: Vec<_> = candidates
            .iter()
            .map(|c| json!({"centre": c.centre_mm.to_array(), "size_mm": c.size_mm, "score": c.score}))
            .collect();
        println!(
            "{}",
            serde_json::to_string_pretty(&json!({ "candidates": records }))?
        );
    } else {
        say(&candidates);
    }
    Ok(())
}

/// The lumen whose wall is searched: the one `--path` starts in, else the study's structure.
fn searched(args: &PolypsArgs, volume: &Volume, study: &Study) -> Result<Lumen> {
    let start = match &args.route {
        Some(path) => Some(
            read_route(path)
                .context("cannot read the path")?
                .points_mm(1.0)?[0],
        ),
        None => None,
    };
    Ok(searched_lumen(study, volume, start)?)
}

/// Adds the candidates to the case at `path` as annotations (a new case of the scan when
/// there is none).
fn add_to_case(
    path: &Path,
    args: &PolypsArgs,
    volume: &Volume,
    candidates: &[Candidate],
) -> Result<()> {
    let identity = ScanIdentity::of(volume);
    let source = ScanSource::File {
        path: args.input.path.clone(),
        series: args.input.series.clone(),
        orientation: args.input.orientation.clone(),
    };
    Case::update(
        path,
        || Ok(Case::new(source, Some(&identity))),
        |case| -> Result<()> {
            case.check_scan(&identity, path)?;
            let mut marks = case.annotations(path)?;
            for mark in annotations(candidates) {
                marks.add(mark)?;
            }
            case.set_annotations(&marks);
            Ok(())
        },
    )?;
    eprintln!(
        "{} candidate(s) added to {}",
        candidates.len(),
        path.display()
    );
    Ok(())
}

/// Writes a view of each candidate into `dir`, all candidates marked.
fn thumbnails(
    dir: &Path,
    args: &PolypsArgs,
    volume: Volume,
    lumen: &Lumen,
    scan_look: &ScanLook,
    candidates: &[Candidate],
) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let geometry = *volume.geometry();
    let (lo, hi) = geometry.world_bounds();
    let optics = args.lens.optics(
        scan_look.study.preset(),
        scan_look.look.as_ref(),
        Some(VIEW_FOV_DEG),
        0.0,
        (hi - lo).length(),
    )?;
    let options = FlightOptions {
        size: args.size,
        optics,
        stereo: None,
        layout: Layout::Endoscope,
        window: scan_look.study.window(),
    };
    let mut flight = Flight::new(Arc::new(Renderer::new(volume)), options);
    flight.set_look(scan_look.look.clone());
    flight.set_annotations(Some(Annotations::from_items(annotations(candidates))?));
    for (n, candidate) in candidates.iter().enumerate() {
        let pose = view_pose(candidate, lumen, &geometry);
        let shot = Shot {
            pose,
            arc_mm: 0.0,
            tangent: (pose.look_at_mm - pose.eye_mm).normalize_or(candidate.normal),
            fov_deg: Some(VIEW_FOV_DEG),
            look: None,
        };
        let (image, _) = flight.frame(n, &shot, &scan_look.settings)?;
        let file = dir.join(format!("polyp_{:03}.png", n + 1));
        endocast_io::image_out::write_png_rgb8(
            &file,
            image.width() as u32,
            image.height() as u32,
            image.rgb(),
        )
        .with_context(|| format!("cannot write {}", file.display()))?;
    }
    Ok(())
}

/// The candidates in words, one a line.
fn say(candidates: &[Candidate]) {
    println!("{} polyp candidate(s), best first:", candidates.len());
    for (n, c) in candidates.iter().enumerate() {
        let p = c.centre_mm;
        println!(
            "  {:3}: {:5.1} mm, score {:.2}, at {:.1},{:.1},{:.1} ({} wall voxels)",
            n + 1,
            c.size_mm,
            c.score,
            p.x,
            p.y,
            p.z,
            c.voxels
        );
    }
}
