//! `endocast convert`: read any scan, write it as NIfTI, NRRD, MetaImage or OME-Zarr.

use crate::input::InputArgs;
use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `endocast convert`.
#[derive(Args, Debug)]
pub struct ConvertArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Output file: .nii, .nii.gz, .nrrd or .mha (replaced if it exists); or a .zarr folder:
    /// OME-Zarr 0.5 (Zarr v3) with levels 0 (full resolution), 1, 2, 3 (each halved, while
    /// larger than a 64³ chunk), z/y/x in mm, 64³ zstd chunks, int16 HU for CT, the LPS frame
    /// in an "endocast" attribute. An existing .zarr folder is replaced only if it is a Zarr
    /// store or empty.
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
