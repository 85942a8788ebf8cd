//! `endocast view`: the interactive workstation (see the `endocast-viewer` crate).

use crate::look::find_preset;
use crate::pose_args::PoseArgs;
use anyhow::{bail, Result};
use clap::Args;
use endocast_core::pose::Pose;
use endocast_viewer::app::{run as run_viewer, ViewerOptions};
use endocast_viewer::scene::ScanSource;
use glam::DVec3;
use std::path::PathBuf;

/// Arguments of `endocast view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// The scan: a DICOM directory or file, .nii/.nii.gz, .nrrd/.nhdr, .mha/.mhd.
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
    /// Clinical defaults: colonoscopy, bronchoscopy, angioscopy, sinus, ventricles.
    #[arg(long, default_value = "colonoscopy")]
    preset: String,
    /// Reopen a case file (its scan, view, key frames and marks); it is autosaved there.
    #[arg(long, value_name = "FILE.json")]
    case: Option<PathBuf>,
    #[command(flatten)]
    pose: PoseArgs,
    /// Write a screenshot of the window (PNG) once the view has refined, then quit.
    #[arg(long, value_name = "FILE.png")]
    screenshot: Option<PathBuf>,
}

/// Runs `endocast view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    let preset = find_preset(&args.preset)?;
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
    let pose = match (args.pose.eye, args.pose.look_at) {
        (Some(eye), Some(at)) => Some(Pose {
            eye_mm: DVec3::from_array(eye),
            look_at_mm: DVec3::from_array(at),
            up: DVec3::from_array(args.pose.up.unwrap_or([0.0, 0.0, 1.0])),
        }),
        (None, None) => None,
        _ => bail!("--eye and --look-at go together"),
    };
    run_viewer(ViewerOptions {
        source,
        preset,
        pose,
        case: args.case.clone(),
        screenshot: args.screenshot.clone(),
    })
    .map_err(anyhow::Error::msg)
}
