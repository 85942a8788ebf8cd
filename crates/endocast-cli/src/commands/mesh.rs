//! `endocast mesh`: the lumen's wall as a triangle mesh (STL, OBJ or PLY) in world mm, for 3D
//! printing, 3D Slicer or MeshLab, or to load back with `--mesh`.

use crate::input::InputArgs;
use crate::look::find_preset;
use crate::parse::parse_vec3;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::isosurface::{isosurface, lumen_surface};
use endocast_core::navigate::{Lumen, LumenSide};
use glam::DVec3;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `endocast mesh`.
#[derive(Args, Debug)]
pub struct MeshArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Output mesh: .stl (binary), .obj or .ply (binary), written atomically.
    #[arg(short, long)]
    output: PathBuf,
    /// Isovalue of the wall, physical units (HU for CT).
    #[arg(long, value_name = "VALUE", allow_negative_numbers = true)]
    iso: Option<f64>,
    /// Take the isovalue (and which side is the lumen) from a procedure preset.
    #[arg(long)]
    preset: Option<String>,
    /// A point in the lumen (world mm): only the surface of the connected lumen around it (a
    /// closed lumen gives a watertight mesh). Without it, the isosurface of the whole volume.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    from: Option<[f64; 3]>,
    /// The lumen is brighter than the wall (contrast); default: the preset's, else darker.
    #[arg(long)]
    bright_lumen: bool,
}

/// Runs `endocast mesh`.
pub fn run(args: &MeshArgs) -> Result<()> {
    let preset = args.preset.as_deref().map(find_preset).transpose()?;
    let Some(iso) = args.iso.or(preset.map(|p| p.iso)) else {
        bail!("give --iso or --preset");
    };
    if !iso.is_finite() {
        bail!("--iso {iso} is not a finite number");
    }
    let side = match (args.bright_lumen, preset.and_then(|p| p.lumen)) {
        (true, _) => LumenSide::Above,
        (false, Some(lumen)) => lumen.side,
        (false, None) => LumenSide::Below,
    };
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let volume = &loaded.volume;
    let start = Instant::now();
    let mesh = match args.from {
        Some(point) => {
            let g = volume.geometry();
            let v = g
                .voxel_from_world()
                .transform_point3(DVec3::from(point))
                .round();
            let dims = volume.dims();
            if v.cmplt(DVec3::ZERO).any() || (0..3).any(|a| v[a] >= dims[a] as f64) {
                bail!("--from {point:?} lies outside the volume");
            }
            let seed = [v.x as usize, v.y as usize, v.z as usize];
            let lumen = Lumen::from_seed(volume, seed, iso, side).context("no lumen at --from")?;
            lumen_surface(volume, &lumen)
        }
        None => isosurface(volume, iso, side),
    }
    .context("no surface at this isovalue")?;
    let extract_ms = start.elapsed().as_secs_f64() * 1e3;
    endocast_io::mesh::write_mesh(&args.output, &mesh).context("cannot write the mesh")?;
    let open = mesh.open_edges();
    println!(
        "{}: {} triangles, {} vertices, {} in {extract_ms:.0} ms",
        args.output.display(),
        mesh.triangles().len(),
        mesh.vertices().len(),
        if open == 0 {
            "watertight".to_string()
        } else {
            format!("{open} open edges (the lumen reaches the volume's border)")
        }
    );
    Ok(())
}
