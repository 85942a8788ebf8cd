//! The colon phantom and a fly-through camera path along its centreline, for benchmarking our
//! renderer and the VTK peer (`../shared/peers/vtk_render.py`) on the same frames.
//!
//! ```text
//! cargo run --release -p endocast-io --example colon_path -- [--size 512] [--frames 60]
//!     [--ahead 10] [--noise 0] [--out-dir bench/out] [--path-only]
//! ```
//!
//! Writes into `--out-dir`:
//! - `colon{size}.nii.gz`: the phantom (int16 HU), unless `--path-only`;
//! - `colon{size}_path_lps.json`: `[{"eye": [x,y,z], "look_at": [..], "up": [..]}, ...]` in our
//!   world frame (LPS millimetres, world = origin + direction·(spacing∘index)), for `endocast`;
//! - `colon{size}_path_vtk.txt`: the same cameras, one a line `px py pz fx fy fz ux uy uz`, in
//!   the frame VTK's NIfTI reader builds, for `vtk_render.py --path`.
//!
//! VTK's frame: `vtkNIFTIImageReader` ignores the NIfTI affine and puts voxel (i, j, k) at
//! (i·sx, j·sy, k·sz) mm. So a world point p maps to `spacing ∘ voxel_from_world(p)`, and a
//! direction (the up vector) maps through the linear part of the same transform. For the colon
//! phantom (1 mm voxels, identity direction, grid centre at world 0) that is
//! `p_vtk = p_lps + (dims − 1) / 2`: a pure translation, no axis flips.
//!
//! The path is [`endocast_core::pose::fly_through`] along the centreline, the same one
//! `endocast bench` flies: `--frames` eyes evenly spaced in arc length, each looking `--ahead` mm
//! further along, with a rotation-minimising up vector.

use endocast_core::phantom::{self, PhantomOptions};
use endocast_core::pose::{fly_through, Pose};
use endocast_core::Geometry;
use glam::DVec3;
use serde_json::json;
use std::path::PathBuf;

/// Command-line settings.
struct Settings {
    size: usize,
    frames: usize,
    ahead_mm: f64,
    noise_hu: f64,
    out_dir: PathBuf,
    path_only: bool,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let settings = parse_args()?;
    std::fs::create_dir_all(&settings.out_dir)?;
    let options = PhantomOptions {
        size: settings.size,
        noise_hu: settings.noise_hu,
        ..Default::default()
    };
    let (volume, colon) = phantom::colon(&options);
    let geometry = volume.geometry();
    let line = &colon.centreline;
    let cameras = fly_through(
        geometry,
        |s| line.point_at(s),
        line.length_vox(),
        settings.frames,
        settings.ahead_mm,
    )
    .ok_or("the centreline is too short for these --frames and --ahead")?;
    let stem = format!("colon{}", settings.size);
    let json_path = settings.out_dir.join(format!("{stem}_path_lps.json"));
    let vtk_path = settings.out_dir.join(format!("{stem}_path_vtk.txt"));
    write_text(&json_path, &lps_json(&cameras)?)?;
    write_text(&vtk_path, &vtk_lines(&cameras, geometry))?;
    println!(
        "{} cameras over {:.0} mm of centreline: {} and {}",
        cameras.len(),
        colon.centreline.length_vox(),
        json_path.display(),
        vtk_path.display()
    );
    if !settings.path_only {
        let nii = settings.out_dir.join(format!("{stem}.nii.gz"));
        endocast_io::write(&nii, &volume)?;
        println!("{:?} voxels: {}", volume.dims(), nii.display());
    }
    Ok(())
}

/// Parses `--key value` pairs and `--path-only`.
fn parse_args() -> Result<Settings, Box<dyn std::error::Error>> {
    let mut s = Settings {
        size: 512,
        frames: 60,
        ahead_mm: 10.0,
        noise_hu: 0.0,
        out_dir: PathBuf::from("bench/out"),
        path_only: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        if flag == "--path-only" {
            s.path_only = true;
            continue;
        }
        let value = args.next().ok_or_else(|| format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--size" => s.size = value.parse()?,
            "--frames" => s.frames = value.parse()?,
            "--ahead" => s.ahead_mm = value.parse()?,
            "--noise" => s.noise_hu = value.parse()?,
            "--out-dir" => s.out_dir = PathBuf::from(value),
            _ => return Err(format!("unknown option {flag}").into()),
        }
    }
    if s.frames < 2 || !s.ahead_mm.is_finite() || s.ahead_mm <= 0.0 {
        return Err("--frames must be at least 2 and --ahead positive".into());
    }
    Ok(s)
}

/// The cameras as a JSON list of `{eye, look_at, up}` in world LPS mm.
fn lps_json(cameras: &[Pose]) -> serde_json::Result<String> {
    let list: Vec<_> = cameras
        .iter()
        .map(|c| {
            json!({
                "eye": c.eye_mm.to_array(),
                "look_at": c.look_at_mm.to_array(),
                "up": c.up.to_array(),
            })
        })
        .collect();
    serde_json::to_string_pretty(&list)
}

/// The cameras in VTK's frame, one `px py pz fx fy fz ux uy uz` line each, after a `#` header
/// (which `vtk_render.py` skips).
fn vtk_lines(cameras: &[Pose], geometry: &Geometry) -> String {
    let to_vtk = |p: DVec3| geometry.voxel_from_world().transform_point3(p) * geometry.spacing_mm();
    let mut text = String::from(
        "# px py pz fx fy fz ux uy uz in VTK's NIfTI frame: voxel (i,j,k) at (i*sx, j*sy, k*sz) mm\n",
    );
    for c in cameras {
        let (eye, focal) = (to_vtk(c.eye_mm), to_vtk(c.look_at_mm));
        let up = (to_vtk(c.eye_mm + c.up) - eye).normalize();
        let numbers: Vec<String> = [eye, focal, up]
            .iter()
            .flat_map(|v| v.to_array())
            .map(|x| format!("{x:.6}"))
            .collect();
        text.push_str(&numbers.join(" "));
        text.push('\n');
    }
    text
}

/// Writes `text` to `path` atomically.
fn write_text(path: &std::path::Path, text: &str) -> endocast_io::Result<()> {
    endocast_io::atomic::write_file(path, |w| w.write_all(text.as_bytes()))
}
