//! `endocast path`: the centred flight path through a lumen between two points (or to the
//! farthest point), written as our path JSON or as 3D Slicer Markups (`.mrk.json`).

use super::path_target;
use crate::input::InputArgs;
use crate::look::find_preset;
use crate::lumen::LumenArgs;
use crate::parse::parse_vec3;
use crate::structure;
use crate::study_report;
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use endocast_core::navigate::{LumenChoiceError, DEFAULT_SCOPE_DIAMETER_MM};
use endocast_core::path::SmoothOptions;
use endocast_core::study::{Study, StudyPath, StudyPathError, StudyRequest};
use endocast_core::Volume;
use endocast_io::path_file::{write_path_json, PathDocument};
use endocast_io::route_file::is_markups;
use glam::DVec3;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `endocast path`.
#[derive(Args, Debug)]
pub struct PathArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Start, world mm (LPS, as `endocast info` reports); must lie in the lumen.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    from: Option<[f64; 3]>,
    /// Start as a voxel index I,J,K (instead of --from).
    #[arg(long, value_name = "I,J,K", value_parser = parse_vec3)]
    from_voxel: Option<[f64; 3]>,
    /// End, world mm; without it (and --to-voxel) the path runs to the farthest lumen point.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    to: Option<[f64; 3]>,
    /// End as a voxel index I,J,K.
    #[arg(long, value_name = "I,J,K", value_parser = parse_vec3)]
    to_voxel: Option<[f64; 3]>,
    /// The lumen's preset: colonoscopy, bronchoscopy, angioscopy, sinus, ventricles.
    #[arg(long)]
    preset: Option<String>,
    /// Wall isovalue, physical units (HU for CT).
    #[arg(long, value_name = "VALUE", allow_negative_numbers = true)]
    iso: Option<f64>,
    #[command(flatten)]
    lumen: LumenArgs,
    /// Spacing of the smoothing spline's control points along the path, mm (tightened
    /// automatically where the smooth path would leave the lumen).
    #[arg(long, value_name = "MM", default_value_t = 5.0)]
    smoothing: f64,
    /// Spacing of the points written, mm.
    #[arg(long, value_name = "MM", default_value_t = 2.0)]
    step: f64,
    /// Output: path JSON (docs/path-format.md), or 3D Slicer Markups when it ends in .mrk.json.
    #[arg(short, long)]
    output: PathBuf,
    /// Print the result as JSON.
    #[arg(long)]
    json: bool,
    /// A target (a nodule), world mm: with the bronchoscopy preset, the path runs from the
    /// trachea through the labelled airway tree, in airways at least --scope-diameter wide, to
    /// the reachable centreline point nearest the target; --json then also lists the branches
    /// passed (trachea, main, lobar, segmental), the distance left to the target, the carina
    /// (where the trachea's lumen splits) and the labelled tree (each fork's split too). The path JSON keeps the target ("target"), so that `fly`, Python and the
    /// workstation's "Read path" draw it in the endoscope view.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true,
          conflicts_with_all = ["from", "from_voxel", "to", "to_voxel"])]
    target: Option<[f64; 3]>,
    /// The bronchoscope's outer diameter for --target, mm (default 4.9: a standard adult
    /// diagnostic bronchoscope; thin scopes are about 4, ultrathin about 3).
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_SCOPE_DIAMETER_MM, requires = "target")]
    scope_diameter: f64,
    /// Also write the structure the preset found (tinted on the slices through the start) as
    /// a PNG; needs --preset and no --from.
    #[arg(long, value_name = "FILE.png")]
    show_structure: Option<PathBuf>,
}

/// Runs `endocast path`.
pub fn run(args: &PathArgs) -> Result<()> {
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let volume = &loaded.volume;
    let request = StudyRequest {
        preset: args.preset.as_deref().map(find_preset).transpose()?,
        iso: args.iso,
        lumen_threshold: args.lumen.lumen_threshold,
        bright_lumen: args.lumen.bright_lumen,
        ..StudyRequest::default()
    };
    let from = point(volume, args.from, args.from_voxel, "--from")?;
    let to = point(volume, args.to, args.to_voxel, "--to")?;
    let clock = Instant::now();
    let study = Study::resolve(volume, &request);
    study_report::say(&study);
    if let Some(path) = &args.show_structure {
        structure::write(path, volume, &study)?;
    }
    let options = SmoothOptions {
        control_spacing_mm: args.smoothing,
        step_mm: 0.5,
        ..SmoothOptions::default()
    };
    let (study_path, target) = match args.target {
        Some(t) => {
            let routed = path_target::plan(volume, &study, t, args.scope_diameter, &options)?;
            let target = (path_target::to_json(&routed), path_target::say(&routed));
            (routed.path, Some(target))
        }
        None => (plan(volume, &study, from, to, &options)?, None),
    };
    let StudyPath {
        lumen_voxels,
        field,
        planned,
    } = study_path;
    let seconds = clock.elapsed().as_secs_f64();
    let points = planned
        .path
        .points_every(args.step)
        .with_context(|| format!("--step {}", args.step))?;
    write(&args.output, &points, args.target.map(DVec3::from))?;
    let mut summary = json!({
        "output": args.output,
        "points": points.len(),
        "length_mm": planned.path.len_mm(),
        "min_radius_mm": planned.min_radius_mm,
        "mean_radius_mm": planned.mean_radius_mm,
        "lumen_voxels": lumen_voxels,
        "max_radius_mm": field.max_mm(),
        "seconds": seconds,
        "study": study_report::to_json(&study),
    });
    if let (Some((route, _)), Some(fields)) = (&target, summary.as_object_mut()) {
        fields.extend(
            route
                .as_object()
                .into_iter()
                .flatten()
                .map(|(k, v)| (k.clone(), v.clone())),
        );
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        println!(
            "{}: {} points, {:.1} mm long, radius min {:.1} mm, mean {:.1} mm ({:.1} s)",
            args.output.display(),
            points.len(),
            planned.path.len_mm(),
            planned.min_radius_mm,
            planned.mean_radius_mm,
            seconds
        );
        if let Some((_, line)) = &target {
            println!("{line}");
        }
    }
    Ok(())
}

/// The study's path ([`Study::plan`]), its errors in terms of the options.
pub(crate) fn plan(
    volume: &Volume,
    study: &Study,
    from: Option<DVec3>,
    to: Option<DVec3>,
    options: &SmoothOptions,
) -> Result<StudyPath> {
    study
        .plan(volume, from, to, options)
        .map_err(|error| match error {
            StudyPathError::NoStart(why) => anyhow!(
                "{why}: --from X,Y,Z (mm) or --from-voxel I,J,K, or a --preset whose structure \
                 is found"
            ),
            StudyPathError::Lumen(LumenChoiceError::Underdetermined) => {
                anyhow!("give --preset, --iso or --lumen-threshold")
            }
            error => error.into(),
        })
}

/// A world point from `--NAME X,Y,Z` or `--NAME-voxel I,J,K`, or `None` when neither is given.
fn point(
    volume: &Volume,
    world: Option<[f64; 3]>,
    voxel: Option<[f64; 3]>,
    name: &str,
) -> Result<Option<DVec3>> {
    Ok(match (world, voxel) {
        (Some(_), Some(_)) => bail!("give {name} or {name}-voxel, not both"),
        (Some(p), None) => Some(DVec3::from(p)),
        (None, Some(v)) => Some(volume.geometry().world_of(DVec3::from(v))),
        (None, None) => None,
    })
}

/// Writes the points as Slicer Markups (`.mrk.json`) or as our path JSON.
/// Writes the path's points, and the target it leads to (path JSON only: Markups has no
/// place for it).
fn write(output: &Path, points: &[DVec3], target_mm: Option<DVec3>) -> Result<()> {
    let name = output
        .file_name()
        .and_then(|n| n.to_str())
        .map_or("path", |n| n.split('.').next().unwrap_or(n));
    if is_markups(output) {
        if target_mm.is_some() {
            eprintln!(
                "note: a Markups curve has no place for the target: write a .json path for the \
                 endoscope views to draw it"
            );
        }
        endocast_io::markups::write_markups_curve(output, name, points)
    } else {
        let document = PathDocument {
            name: name.to_owned(),
            points_mm: points.to_vec(),
            key_frames: Vec::new(),
            target_mm,
        };
        write_path_json(output, &document)
    }
    .context("cannot write the path")
}
