//! `endocast match`: supine/prone correspondence. Each scan's study plans its colon path as
//! `endocast path` does; the paths are matched (normalised arc length refined by warping their
//! directions, the patient's turn about the long axis fitted), and a finding in the first scan
//! gives its counterpart in the second with a view of it, and optionally the two views side by
//! side.

use crate::look::find_preset;
use crate::parse::{parse_size, parse_vec3};
use crate::study_report;
use anyhow::{Context, Result};
use clap::Args;
use endocast_core::correspond::{side_by_side, Correspondence, Counterpart};
use endocast_core::render::Renderer;
use endocast_core::study::{Study, StudyRequest};
use endocast_core::Volume;
use endocast_io::OpenOptions;
use glam::DVec3;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Arguments of `endocast match`.
#[derive(Args, Debug)]
pub struct MatchArgs {
    /// The first scan (e.g. supine), in any format `endocast info` reads.
    first: PathBuf,
    /// The second scan of the same patient (e.g. prone).
    second: PathBuf,
    /// The finding in the first scan, world mm (LPS).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_negative_numbers = true)]
    at: [f64; 3],
    /// The procedure whose structure and path are matched in both scans.
    #[arg(long, default_value = "colonoscopy")]
    preset: String,
    /// Also write the first scan's view of the finding beside the second's view of its
    /// counterpart (PNG; each view on the path, looking at the point, the point crossed).
    #[arg(short, long, value_name = "FILE.png")]
    output: Option<PathBuf>,
    /// Size of each of the two views, pixels.
    #[arg(long, value_name = "WxH", default_value = "384x384", value_parser = parse_size)]
    size: [usize; 2],
    /// Vertical field of view of the views, degrees (default: the preset's).
    #[arg(long, value_name = "DEG")]
    fov: Option<f64>,
    /// Print the counterpart and the match as JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `endocast match`.
pub fn run(args: &MatchArgs) -> Result<()> {
    let preset = find_preset(&args.preset)?;
    let request = StudyRequest::preset(preset);
    let open = |path: &Path| -> Result<(Volume, Study)> {
        let loaded = endocast_io::open(path, &OpenOptions::default())
            .with_context(|| format!("cannot read the scan {}", path.display()))?;
        for warning in &loaded.warnings {
            eprintln!("warning: {warning}");
        }
        let study = Study::resolve(&loaded.volume, &request);
        study_report::say(&study);
        Ok((loaded.volume, study))
    };
    let (volume_a, study_a) = open(&args.first)?;
    let (volume_b, study_b) = open(&args.second)?;
    let matched = Correspondence::of_studies((&volume_a, &study_a), (&volume_b, &study_b))?;
    let found = matched.counterpart(DVec3::from(args.at))?;
    if let Some(output) = &args.output {
        let fov = args.fov.unwrap_or(preset.fov_deg);
        let renderers = [
            Arc::new(Renderer::new(volume_a)),
            Arc::new(Renderer::new(volume_b)),
        ];
        let scans = [
            (&renderers[0], study_a.settings()),
            (&renderers[1], study_b.settings()),
        ];
        let image =
            side_by_side(scans, &found, fov, args.size).context("cannot render the views")?;
        endocast_io::image_out::write_png_rgb8(
            output,
            image.width() as u32,
            image.height() as u32,
            image.rgb(),
        )
        .with_context(|| format!("cannot write {}", output.display()))?;
    }
    if args.json {
        let report = to_json(&matched, &found);
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        say(&matched, &found);
    }
    Ok(())
}

/// The counterpart and the match as JSON (world mm, LPS).
fn to_json(matched: &Correspondence, found: &Counterpart) -> Value {
    let v = |p: DVec3| [p.x, p.y, p.z];
    let (length_first, length_second) = matched.lengths_mm();
    json!({
        "point": v(found.point_mm),
        "arc_mm": found.arc_mm,
        "eye": v(found.view.eye_mm),
        "look_at": v(found.view.look_at_mm),
        "up": v(found.view.up),
        "first": {
            "arc_mm": found.arc_first_mm,
            "distance_mm": found.distance_mm,
            "eye": v(found.view_first.eye_mm),
            "look_at": v(found.view_first.look_at_mm),
            "up": v(found.view_first.up),
            "path_mm": length_first,
        },
        "path_mm": length_second,
        "turn_deg": matched.turn_deg(),
        "reversed": matched.reversed(),
        "match_cost": matched.cost(),
    })
}

/// The counterpart in words.
fn say(matched: &Correspondence, found: &Counterpart) {
    let p = found.point_mm;
    let (length_first, length_second) = matched.lengths_mm();
    println!(
        "finding {:.1} mm from the first path at {:.1} of {length_first:.1} mm",
        found.distance_mm, found.arc_first_mm
    );
    println!(
        "counterpart at {:.1},{:.1},{:.1} mm, {:.1} of {length_second:.1} mm along the second \
         path{}",
        p.x,
        p.y,
        p.z,
        found.arc_mm,
        if matched.reversed() {
            " (planned from the other end)"
        } else {
            ""
        }
    );
    println!(
        "patient turned {:.0}° about the long axis; direction mismatch {:.3}",
        matched.turn_deg(),
        matched.cost()
    );
}
