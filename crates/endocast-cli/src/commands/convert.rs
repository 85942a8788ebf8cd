//! `endocast convert`: read any scan, write it as NIfTI, NRRD or MetaImage.

use crate::input::InputArgs;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `endocast convert`.
#[derive(Args, Debug)]
pub struct ConvertArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Output file: .nii, .nii.gz, .nrrd or .mha.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs `endocast convert`.
pub fn run(args: &ConvertArgs) -> Result<()> {
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    endocast_io::write(&args.output, &loaded.volume).context("cannot write the converted scan")?;
    let [nx, ny, nz] = loaded.volume.dims();
    println!("{}: {nx} × {ny} × {nz} voxels", args.output.display());
    Ok(())
}
