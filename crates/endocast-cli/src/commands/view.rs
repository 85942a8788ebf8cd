//! `endocast view`: the interactive workstation (see the `endocast-viewer` crate).

use crate::look::find_preset;
use crate::pose_args::PoseArgs;
use crate::study_report;
use anyhow::{bail, Result};
use clap::Args;
use endocast_core::look::LookKind;
use endocast_core::views::slices::Plane;
use endocast_viewer::app::{run as run_viewer, ScreenshotHook, ViewerOptions};
use endocast_viewer::scene::ScanSource;
use endocast_viewer::session::Session;
use std::path::PathBuf;
use std::sync::Arc;

/// Arguments of `endocast view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// The scan: a DICOM directory or file, .nii/.nii.gz, .hdr with its .img (NIfTI or Analyze
    /// 7.5), .nrrd/.nhdr, .mha/.mhd.
    scan: Option<PathBuf>,
    /// DICOM: load this SeriesInstanceUID instead of the largest series.
    #[arg(long, value_name = "UID")]
    series: Option<String>,
    /// Fly through a generated phantom instead of a scan (colon, straight-tube, ...).
    #[arg(long, value_name = "NAME", conflicts_with = "scan")]
    phantom: Option<String>,
    /// The phantom's largest dimension, voxels.
    #[arg(long, default_value_t = 256)]
    size: usize,
    /// Clinical defaults: colonoscopy, bronchoscopy, angioscopy, sinus, ventricles,
    /// arthroscopy (default: none, the whole object framed, as `render` does; for a phantom,
    /// which is tissue to its border, colonoscopy).
    #[arg(long)]
    preset: Option<String>,
    /// Reopen a case file (its scan, view, key frames and marks); it is autosaved there.
    #[arg(long, value_name = "FILE.json")]
    case: Option<PathBuf>,
    #[command(flatten)]
    pose: PoseArgs,
    /// The endoscope's look to start with: plain, clinical or realistic (default: the
    /// preset's; the panel changes it).
    #[arg(long, value_name = "LOOK")]
    look: Option<String>,
    /// Show a slice large beside the endoscope from the start: axial, coronal or sagittal
    /// (the slice column's "large:" buttons change it).
    #[arg(long, value_name = "PLANE")]
    layout: Option<String>,
    /// A second scan of the same patient (e.g. prone beside supine; a file, or `phantom:NAME`
    /// for a phantom of --size) shown beside the endoscope: the scans' colon paths are matched
    /// as `endocast match` matches them, and its camera follows this one's (its eye at the
    /// counterpart, turned as the wall is). The panel's "Compare" button opens one too.
    #[arg(long, value_name = "SCAN")]
    compare: Option<PathBuf>,
    /// Write a screenshot of the window (PNG) once the view has refined, then quit.
    #[arg(long, value_name = "FILE.png")]
    screenshot: Option<PathBuf>,
    /// With --screenshot: print what the session resolved (values, structure, start) and its
    /// camera as JSON, as `render --json` does.
    #[arg(long, requires = "screenshot")]
    json: bool,
}

/// Runs `endocast view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    let name = match (&args.preset, &args.phantom) {
        (Some(name), _) => Some(name.as_str()),
        (None, Some(_)) => Some("colonoscopy"),
        (None, None) => None,
    };
    let preset = name.map(find_preset).transpose()?;
    let source = match (&args.scan, &args.phantom, &args.case) {
        (Some(path), _, _) => ScanSource::File {
            path: path.clone(),
            series: args.series.clone(),
            orientation: None,
        },
        (None, Some(name), _) => ScanSource::Phantom {
            name: name.clone(),
            size: args.size,
        },
        // The case names its scan.
        (None, None, Some(_)) => ScanSource::Phantom {
            name: String::new(),
            size: 0,
        },
        (None, None, None) => bail!("give a scan, --phantom NAME or --case FILE"),
    };
    let look = match &args.look {
        Some(name) => Some(
            LookKind::from_name(name)
                .ok_or_else(|| anyhow::anyhow!("--look {name:?}: plain, clinical or realistic"))?,
        ),
        None => None,
    };
    let layout = match &args.layout {
        Some(name) => Some(
            Plane::ALL
                .into_iter()
                .find(|p| p.name() == name)
                .ok_or_else(|| anyhow::anyhow!("--layout {name:?}: axial, coronal or sagittal"))?,
        ),
        None => None,
    };
    let on_screenshot = args
        .json
        .then(|| ScreenshotHook(Arc::new(|session: &Session| print_session(session))));
    run_viewer(ViewerOptions {
        source,
        preset,
        pose: args.pose.pose()?,
        case: args.case.clone(),
        screenshot: args.screenshot.clone(),
        on_screenshot,
        look,
        layout,
        compare: args
            .compare
            .as_deref()
            .map(|scan| second_scan(scan, args.size)),
    })
    .map_err(anyhow::Error::msg)
}

/// The second scan of `--compare`: a file, or `phantom:NAME` (a phantom of `size`).
fn second_scan(scan: &std::path::Path, size: usize) -> ScanSource {
    match scan.to_str().and_then(|s| s.strip_prefix("phantom:")) {
        Some(name) => ScanSource::Phantom {
            name: name.to_owned(),
            size,
        },
        None => ScanSource::File {
            path: scan.to_path_buf(),
            series: None,
            orientation: None,
        },
    }
}

/// Prints what `session` resolved and its camera, as JSON on stdout.
fn print_session(session: &Session) {
    let camera = session.fly_camera().pose();
    let report = serde_json::json!({
        "camera": study_report::pose_json(&camera),
        "study": study_report::to_json(session.study()),
    });
    match serde_json::to_string_pretty(&report) {
        Ok(text) => println!("{text}"),
        Err(e) => eprintln!("error: {e}"),
    }
}
