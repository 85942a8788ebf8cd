//! `endocast dissect`: the lumen cut open along its path and laid flat (virtual dissection, the
//! "filet" view), written as a PNG with its map back to 3D beside it (`NAME.map.npy`).

use crate::commands::path::plan;
use crate::input::InputArgs;
use crate::look::{set_threads, LookArgs, ScanLook};
use crate::lumen::LumenArgs;
use crate::study_report;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::dissect::{
    dissect, DissectOptions, Dissection, Wall, DEFAULT_REACH_MM, DEFAULT_ROWS, DEFAULT_STEP_MM,
};
use endocast_core::flight::Route;
use endocast_core::path::{Path as CamPath, SmoothOptions};
use endocast_io::route_file::read_route;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Arguments of `endocast dissect`.
#[derive(Args, Debug)]
pub struct DissectArgs {
    #[command(flatten)]
    input: InputArgs,
    /// The path to cut along (path JSON or Slicer Markups, as `endocast path` writes); without
    /// it, the automatic path through the structure the preset finds (as `endocast path` plans
    /// it).
    #[arg(long = "path", value_name = "FILE")]
    route: Option<PathBuf>,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    lumen: LumenArgs,
    /// The flat image (PNG): length along the path across (one column per --along-step), the
    /// circumference down (one row per 360°/--rows, 0° at the path's up vector, 90° at its
    /// right), with a mm axis and the scale in words. Its map, NAME.map.npy, is written beside
    /// it: float32, height × width × 3, the wall point (LPS mm) of each pixel, NaN where none.
    #[arg(short, long, value_name = "PNG")]
    output: PathBuf,
    /// Arc length along the path per column, mm.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_STEP_MM)]
    along_step: f64,
    /// Rows around the path (the angular count).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_ROWS)]
    rows: usize,
    /// How far from the path a ray looks for the wall, mm.
    #[arg(long, value_name = "MM", default_value_t = DEFAULT_REACH_MM)]
    reach: f64,
    /// Print the image's size, scale (mm per pixel), files and the dissection's time
    /// (`dissect_ms`: the rays and the image, without loading the scan or planning the path)
    /// as JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `endocast dissect`.
pub fn run(args: &DissectArgs) -> Result<()> {
    set_threads(args.look.threads)?;
    let map_file = map_file(&args.output)?;
    let given = args
        .route
        .as_deref()
        .map(|p| read_route(p).context("cannot read the path"))
        .transpose()?;
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let volume = loaded.volume;
    let ScanLook {
        settings, study, ..
    } = args.look.on_scan(&volume, &args.lumen, None, None)?;
    study_report::say(&study);
    let path = match given {
        Some(Route::Path(path)) => path,
        Some(Route::Keys(_)) => bail!("--path holds key frames: dissection needs a path's points"),
        None => {
            plan(&volume, &study, None, None, &SmoothOptions::default())?
                .planned
                .path
        }
    };
    let options = DissectOptions {
        step_mm: args.along_step,
        rows: args.rows,
        reach_mm: args.reach,
    };
    let clock = Instant::now();
    let flat = dissect(&volume, &path, &Wall::of(&settings), &options)?;
    let took = clock.elapsed();
    write(&flat, &args.output, &map_file)?;
    let mut report = to_json(&flat, &path, &args.output, &map_file);
    report["dissect_ms"] = json!(took.as_secs_f64() * 1e3);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        say(&flat, &path, &args.output, &map_file);
        println!("laid flat in {}", short_time(took));
    }
    Ok(())
}

/// The map's file beside the image: `flat.png` → `flat.map.npy`.
fn map_file(output: &Path) -> Result<PathBuf> {
    let is_png = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png {
        bail!("-o must name a .png file, not {}", output.display());
    }
    Ok(output.with_extension("map.npy"))
}

/// Writes the image and its map.
fn write(flat: &Dissection, image_file: &Path, map_file: &Path) -> Result<()> {
    let (w, h) = (flat.image.width() as u32, flat.image.height() as u32);
    endocast_io::image_out::write_png_rgb8(image_file, w, h, flat.image.rgb())
        .with_context(|| format!("cannot write {}", image_file.display()))?;
    endocast_io::image_out::write_npy_f32_channels(map_file, w, h, 3, flat.map.as_slice())
        .with_context(|| format!("cannot write {}", map_file.display()))
}

/// The dissection's size, scale and files as JSON.
fn to_json(flat: &Dissection, path: &CamPath, image_file: &Path, map_file: &Path) -> Value {
    let plot = flat.plot;
    json!({
        "image": image_file.display().to_string(),
        "map": map_file.display().to_string(),
        "width": flat.image.width(),
        "height": flat.image.height(),
        "plot": {"x": plot.x, "y": plot.y, "columns": plot.columns, "rows": plot.rows},
        "path_length_mm": path.len_mm(),
        "along_mm_per_px": flat.scale.along_mm_per_px,
        "around_deg_per_px": flat.scale.around_deg_per_px,
        "around_mm_per_px": flat.scale.around_mm_per_px,
        "wall_fraction": flat.hit_fraction,
    })
}

/// The dissection in words.
fn say(flat: &Dissection, path: &CamPath, image_file: &Path, map_file: &Path) {
    let s = flat.scale;
    println!(
        "{} mm of path laid flat: {} × {} wall pixels, {} mm/px along, {}°/px around ({:.2} mm \
         at the median wall distance), wall in {:.1} % of them",
        path.len_mm().round(),
        flat.plot.columns,
        flat.plot.rows,
        s.along_mm_per_px,
        s.around_deg_per_px,
        s.around_mm_per_px,
        100.0 * flat.hit_fraction
    );
    println!("wrote {} and {}", image_file.display(), map_file.display());
}

/// A duration in ms or s, as people read it.
fn short_time(took: Duration) -> String {
    let ms = took.as_secs_f64() * 1e3;
    if ms < 1e3 {
        format!("{ms:.0} ms")
    } else {
        format!("{:.2} s", ms / 1e3)
    }
}
