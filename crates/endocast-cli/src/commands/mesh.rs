//! `endocast mesh`: the lumen's wall as a triangle mesh (STL, OBJ or PLY) in world mm, for 3D
//! printing, 3D Slicer or MeshLab, or to load back with `--mesh`.

use crate::input::InputArgs;
use crate::look::find_preset;
use crate::parse::parse_vec3;
use crate::study_report;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::isosurface::{isosurface, lumen_surface};
use endocast_core::navigate::{seed_voxel, Lumen, LumenSide};
use endocast_core::pose::Pose;
use endocast_core::study::{Study, StudyRequest};
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
    /// Isovalue of the wall, physical units (HU for CT); default: the preset's in the scan's
    /// units, else the scan's own wall (as `render`).
    #[arg(long, value_name = "VALUE", allow_negative_numbers = true)]
    iso: Option<f64>,
    /// Take the isovalue (and which side is the lumen) from a procedure preset.
    #[arg(long)]
    preset: Option<String>,
    /// A point in the lumen (world mm): only the surface of the connected lumen around it,
    /// grown at the preset's lumen threshold as `path` grows it (a closed lumen gives a
    /// watertight mesh). Without it, the isosurface of the whole volume.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    from: Option<[f64; 3]>,
    /// The lumen is brighter than the wall (contrast); default: the preset's, else darker.
    #[arg(long)]
    bright_lumen: bool,
}

/// Runs `endocast mesh`.
pub fn run(args: &MeshArgs) -> Result<()> {
    if args.iso.is_some_and(|iso| !iso.is_finite()) {
        bail!("--iso must be a finite number");
    }
    let preset = args.preset.as_deref().map(find_preset).transpose()?;
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let volume = &loaded.volume;
    // The scan understood as `render` and `path` understand it: the preset in the scan's own
    // units, the wall and the lumen's side. A mesh needs no start, so no structure is searched
    // (the pose only says so).
    let (lo, hi) = volume.geometry().world_bounds();
    let centre = (lo + hi) / 2.0;
    let request = StudyRequest {
        preset,
        iso: args.iso,
        bright_lumen: args.bright_lumen,
        pose: Some(Pose {
            eye_mm: centre,
            look_at_mm: centre + DVec3::Z,
            up: DVec3::Y,
        }),
        ..StudyRequest::default()
    };
    let study = Study::resolve(volume, &request);
    study_report::say(&study);
    let iso = study.settings().iso_hu;
    let side = study.lumen().map_or(LumenSide::Below, |(_, side)| side);
    let start = Instant::now();
    let mesh = match args.from {
        Some(point) => {
            let seed = seed_voxel(volume, DVec3::from(point))
                .map_err(|_| anyhow::anyhow!("--from {point:?} lies outside the volume"))?;
            // Grown at the lumen's threshold, as `path` and collision grow it.
            let threshold = study.lumen().map_or(iso, |(threshold, _)| threshold);
            let lumen =
                Lumen::from_seed(volume, seed, threshold, side).context("no lumen at --from")?;
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
