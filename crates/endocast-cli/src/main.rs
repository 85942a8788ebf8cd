//! The `endocast` command-line tool: every command is a thin front end over the libraries.

mod case_args;
mod cleanse_args;
mod commands;
mod input;
mod look;
mod lumen;
mod optics;
mod parse;
mod peel;
mod pose_args;
mod progress;
mod scene_args;
mod structure;
mod study_report;

use clap::{CommandFactory, Parser, Subcommand};
use std::process::ExitCode;

/// Virtual endoscopy of CT and MRI scans.
#[derive(Parser)]
#[command(name = "endocast", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Describe a scan: dimensions, spacing, orientation, value range, series, warnings.
    Info(commands::info::InfoArgs),
    /// Make an analytic phantom volume and save it (.nii, .nii.gz, .nrrd or .mha).
    Phantom(commands::phantom::PhantomArgs),
    /// Convert a scan to another format (.nii, .nii.gz, .nrrd, .mha or an OME-Zarr .zarr folder).
    Convert(commands::convert::ConvertArgs),
    /// Render one endoscopic (or outside) view of a scan to PNG.
    Render(Box<commands::render::RenderArgs>),
    /// The centred flight path through a lumen, to path JSON or Slicer Markups (.mrk.json).
    Path(Box<commands::path::PathArgs>),
    /// Fly along a path (or key frames) to a GIF, an MP4 or PNG frames, optionally as a
    /// dashboard with slices and an overview, optionally measuring the wall seen.
    Fly(Box<commands::fly::FlyArgs>),
    /// The wall a flight missed, as patches with their area, centroid and a camera that sees
    /// each (JSON with --json), their views (--views) and the coverage before and after them.
    Coverage(Box<commands::coverage::CoverageArgs>),
    /// Polyp candidates on the wall of the colon (or the lumen a path starts in) by shape
    /// index and curvedness: listed (JSON with --json), viewed (--thumbnails), added to a case.
    Polyps(Box<commands::polyps::PolypsArgs>),
    /// Virtual dissection: the lumen cut open along its path and laid flat (length × angle)
    /// to a PNG with a mm scale, and NAME.map.npy, each pixel's 3D wall point (LPS mm).
    Dissect(Box<commands::dissect::DissectArgs>),
    /// List the procedure presets: mode, transfer function, isovalues, lumen, slice window, lens.
    Presets(commands::presets::PresetsArgs),
    /// The lumen's wall (an isosurface) as a triangle mesh: STL, OBJ or PLY in world mm.
    Mesh(Box<commands::mesh::MeshArgs>),
    /// Frames per second along a fly path (default: the paper's protocol on the colon phantom).
    Bench(Box<commands::bench::BenchArgs>),
    /// Add, list and remove the annotations of a case file: labelled points, strokes on the
    /// tissue and measurements, at world points or picked through a pixel of a view.
    Annotate(Box<commands::annotate::AnnotateArgs>),
    /// The interactive workstation: fly through a scan with the slices, the controls, key
    /// frames, marks and cases (a window; `--screenshot` grabs it and quits).
    View(Box<commands::view::ViewArgs>),
    /// Supine/prone correspondence: a finding in the first scan gives its counterpart and a
    /// view of it in the second (JSON with --json), and the two views side by side (-o).
    Match(Box<commands::match_scans::MatchArgs>),
    /// Every study of a manifest (CSV or JSON lines) through the pipeline: path, flight with
    /// coverage and film, a key view, and for colonoscopy the dissection and polyp candidates;
    /// resumable, each study isolated, summarised in summary.csv and summary.json.
    Batch(Box<commands::batch::BatchArgs>),
    /// Join the frames of a flight flown in parts (`fly --frames`, PNG folders) into one film.
    Film(commands::film::FilmArgs),
}

fn main() -> ExitCode {
    remove_temporary_files_on_signals();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info(args) => commands::info::run(&args),
        Command::Phantom(args) => commands::phantom::run(&args),
        Command::Convert(args) => commands::convert::run(&args),
        Command::Render(args) => commands::render::run(&args),
        Command::Bench(args) => commands::bench::run(&args),
        Command::Presets(args) => commands::presets::run(&args),
        Command::Path(args) => commands::path::run(&args),
        Command::Fly(args) => commands::fly::run(&args),
        Command::View(args) => commands::view::run(&args),
        Command::Coverage(args) => commands::coverage::run(&args),
        Command::Polyps(args) => commands::polyps::run(&args),
        Command::Dissect(args) => commands::dissect::run(&args),
        Command::Mesh(args) => commands::mesh::run(&args),
        Command::Annotate(args) => commands::annotate::run(&args),
        Command::Match(args) => commands::match_scans::run(&args),
        Command::Batch(args) => commands::batch::run(&args, &Cli::command()),
        Command::Film(args) => commands::film::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            // Messages may quote file names and headers: no control character gets through.
            eprintln!("error: {}", endocast_io::escape(&format!("{error:#}")));
            ExitCode::FAILURE
        }
    }
}

/// On SIGINT or SIGTERM, removes the temporary files of the outputs being written (a film in
/// progress, a PNG being written) and exits with status 128 + the signal's number, as a
/// shell reports a command killed by it.
fn remove_temporary_files_on_signals() {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
        return; // the default handlers stay: interrupted, temporary files may remain
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            endocast_io::atomic::remove_temporary_files();
            eprintln!("\ninterrupted: temporary files removed");
            std::process::exit(128 + signal);
        }
    });
}
