//! `endocast phantom`: analytic test volumes saved to a file.

use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::phantom::{Phantom, PhantomOptions};
use std::path::PathBuf;

/// Arguments of `endocast phantom`.
#[derive(Args, Debug)]
pub struct PhantomArgs {
    /// sphere-shell, straight-tube, curved-tube, colon, vessel, joint, sinus or layered.
    name: String,
    /// Output file: .nii, .nii.gz, .nrrd or .mha.
    #[arg(short, long)]
    output: PathBuf,
    /// Largest dimension in voxels (the colon at 512 is the paper's 512×512×478).
    #[arg(long, default_value_t = 128)]
    size: usize,
    /// Gaussian noise, standard deviation in HU.
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// Seed of the noise (and of the polyps' draw with --polyps).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// colon only: N polyps of 4–10 mm (sessile, pedunculated and flat in turn) drawn with
    /// --seed at random places on and between the folds, instead of the five fixed ones;
    /// 0 gives a colon of folds only.
    #[arg(long, value_name = "N")]
    polyps: Option<usize>,
    /// The colon: pools of tagged fluid (600 HU oral contrast) under the air in its sumps, with
    /// the blurred rims of a CT, for `--cleanse on`.
    #[arg(long)]
    tagged_fluid: bool,
}

/// The largest phantom we agree to build (2048³ would be 16 GiB).
const MAX_SIZE: usize = 1024;

/// Runs `endocast phantom`.
pub fn run(args: &PhantomArgs) -> Result<()> {
    let Some(phantom) = Phantom::from_name(&args.name) else {
        let names: Vec<&str> = Phantom::ALL.iter().map(|p| p.name()).collect();
        bail!(
            "unknown phantom {:?}; choose one of {}",
            args.name,
            names.join(", ")
        );
    };
    if args.tagged_fluid && phantom != Phantom::Colon {
        bail!(
            "--tagged-fluid is for the colon phantom, not {}",
            phantom.name()
        );
    }
    if !(8..=MAX_SIZE).contains(&args.size) {
        bail!("--size must be between 8 and {MAX_SIZE}, not {}", args.size);
    }
    if !args.noise.is_finite() || args.noise < 0.0 {
        bail!(
            "--noise must be a finite, non-negative HU value, not {}",
            args.noise
        );
    }
    let options = PhantomOptions {
        size: args.size,
        noise_hu: args.noise,
        seed: args.seed,
        polyps: args.polyps,
        tagged_fluid: args.tagged_fluid,
    };
    if args.polyps.is_some() && phantom != Phantom::Colon {
        bail!("--polyps applies to the colon phantom only");
    }
    let volume = phantom.build(&options);
    endocast_io::write(&args.output, &volume).context("cannot write the phantom")?;
    let [nx, ny, nz] = volume.dims();
    println!(
        "{}: {} phantom, {nx} × {ny} × {nz} voxels",
        args.output.display(),
        phantom.name()
    );
    Ok(())
}
