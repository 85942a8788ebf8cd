//! The geometry options `render`, `fly` and `bench` share: meshes, a grid, markers and the
//! endoscope's instruments drawn in the volume (the library's [`Scene`]).

use crate::parse::parse_vec3;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::scene::{
    Endoscope, GridPlane, Marker, Material, Scene, DEFAULT_INSTRUMENT_LENGTH_MM,
};
use endocast_io::overlay_scene::add_overlay;
use glam::DVec3;
use std::path::PathBuf;
use std::sync::Arc;

/// The radius of a marker when `--marker` gives none, mm.
const DEFAULT_MARKER_RADIUS_MM: f64 = 2.0;

/// Geometry in the volume.
#[derive(Args, Debug, Clone, Default)]
pub struct SceneArgs {
    /// A triangle mesh (STL, OBJ or PLY, world mm LPS) drawn in the volume, optionally with a
    /// colour (a name, R,G,B in 0–1 or #rrggbb) and an opacity 0–1 (default light blue, 1).
    /// Repeatable. Translucent meshes are composited with the volume in depth order.
    #[arg(long, value_name = "FILE[:COLOUR[:OPACITY]]")]
    pub mesh: Vec<String>,
    /// A planar grid of lines for orientation: a point of it, its normal and the line spacing
    /// (world mm), e.g. 0,0,120:0,0,1:10. Opaque white lines a twentieth of the spacing wide.
    #[arg(long, value_name = "ORIGIN:NORMAL:SPACING", allow_hyphen_values = true)]
    pub grid: Option<String>,
    /// Width of the grid's lines, mm.
    #[arg(long, value_name = "MM", requires = "grid")]
    pub grid_width: Option<f64>,
    /// Moves the grid along its normal, mm.
    #[arg(
        long,
        value_name = "MM",
        requires = "grid",
        allow_negative_numbers = true
    )]
    pub grid_shift: Option<f64>,
    /// A marker sphere at a point (world mm), optionally of a radius (default 2 mm).
    /// Repeatable.
    #[arg(long, value_name = "X,Y,Z[:RADIUS]", allow_hyphen_values = true)]
    pub marker: Vec<String>,
    /// Shows an instrument of this diameter (mm) in front of the camera, as through an
    /// endoscope's working channel; DIAMETER:LENGTH also sets how far it reaches (default 20 mm).
    #[arg(long, value_name = "DIAMETER[:LENGTH]")]
    pub endoscope: Option<String>,
    /// A second instrument beside the first (with --endoscope).
    #[arg(long, requires = "endoscope")]
    pub second_instrument: bool,
    /// A DICOM segmentation (SEG: each segment a surface in its recommended colour) or dose
    /// grid (RTDOSE: isodose surfaces at LEVELS in its units, default 50, 80 and 95 % of its
    /// maximum) drawn with the scan. Repeatable.
    #[arg(long, value_name = "FILE[:LEVELS]")]
    pub overlay: Vec<String>,
}

impl SceneArgs {
    /// The scene the options describe (meshes read and their hierarchies built), or `None`
    /// when they describe none.
    pub fn scene(&self) -> Result<Option<Arc<Scene>>> {
        let mut scene = Scene::new();
        for spec in &self.mesh {
            let (path, material) = mesh_spec(spec)?;
            let mesh = endocast_io::mesh::read_mesh(&path).context("cannot read the mesh")?;
            scene.add_mesh(&mesh, material);
        }
        for spec in &self.overlay {
            let limits = endocast_io::Limits::default();
            eprintln!("{}", add_overlay(&mut scene, spec, &limits)?.summary);
        }
        if let Some(spec) = &self.grid {
            scene.add_grid(self.grid(spec)?, Material::GRID);
        }
        for spec in &self.marker {
            let (centre, radius) = match spec.split_once(':') {
                Some((c, r)) => (c, number(r, "marker radius")?),
                None => (spec.as_str(), DEFAULT_MARKER_RADIUS_MM),
            };
            let centre = DVec3::from(parse_vec3(centre).map_err(anyhow::Error::msg)?);
            scene.add_marker(Marker::new(centre, radius)?, Material::MARKER);
        }
        if let Some(spec) = &self.endoscope {
            let (diameter, length) = match spec.split_once(':') {
                Some((d, l)) => (number(d, "diameter")?, number(l, "length")?),
                None => (number(spec, "diameter")?, DEFAULT_INSTRUMENT_LENGTH_MM),
            };
            let endoscope = Endoscope::new(diameter, length)?;
            scene.set_endoscope(Some(
                endoscope.with_second_instrument(self.second_instrument),
            ));
        }
        Ok((!scene.is_empty()).then(|| Arc::new(scene)))
    }

    fn grid(&self, spec: &str) -> Result<GridPlane> {
        let parts: Vec<&str> = spec.split(':').collect();
        let [origin, normal, spacing] = parts[..] else {
            bail!("--grid {spec:?}: expected ORIGIN:NORMAL:SPACING, e.g. 0,0,120:0,0,1:10");
        };
        let vec = |s: &str| parse_vec3(s).map(DVec3::from).map_err(anyhow::Error::msg);
        let spacing = number(spacing, "grid spacing")?;
        let mut grid = GridPlane::new(vec(origin)?, vec(normal)?, spacing)?;
        if let Some(width) = self.grid_width {
            grid = grid.with_spacing(spacing, width)?;
        }
        Ok(grid.moved(self.grid_shift.unwrap_or(0.0)))
    }
}

/// A finite number.
fn number(text: &str, what: &str) -> Result<f64> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => bail!("{what} {text:?} is not a finite number"),
    }
}

/// `FILE[:COLOUR[:OPACITY]]`.
fn mesh_spec(spec: &str) -> Result<(PathBuf, Material)> {
    let mut parts = spec.splitn(3, ':');
    let path = PathBuf::from(parts.next().unwrap_or_default());
    let color = match parts.next() {
        Some(c) => parse_color(c)?,
        None => Material::MESH.color,
    };
    let opacity = match parts.next() {
        Some(o) => number(o, "mesh opacity")? as f32,
        None => 1.0,
    };
    let material = Material::new(color, opacity).with_context(|| format!("--mesh {spec}"))?;
    Ok((path, material))
}

/// A colour: a name, `R,G,B` in 0–1, or `#rrggbb`.
fn parse_color(text: &str) -> Result<[f32; 3]> {
    let named = match text.to_ascii_lowercase().as_str() {
        "white" => Some([1.0, 1.0, 1.0]),
        "red" => Some([0.9, 0.15, 0.1]),
        "green" => Some([0.2, 0.8, 0.3]),
        "blue" => Some([0.2, 0.4, 1.0]),
        "yellow" => Some([1.0, 0.85, 0.1]),
        "orange" => Some([1.0, 0.55, 0.1]),
        "cyan" => Some([0.1, 0.85, 0.9]),
        "magenta" => Some([0.9, 0.2, 0.8]),
        "grey" | "gray" => Some([0.6, 0.6, 0.6]),
        _ => None,
    };
    if let Some(c) = named {
        return Ok(c);
    }
    if let Some(hex) = text.strip_prefix('#') {
        let byte = |i: usize| u8::from_str_radix(hex.get(i..i + 2).unwrap_or("x"), 16);
        if let (6, Ok(r), Ok(g), Ok(b)) = (hex.len(), byte(0), byte(2), byte(4)) {
            return Ok([r, g, b].map(|v| f32::from(v) / 255.0));
        }
    }
    let v = parse_vec3(text).map_err(|_| {
        anyhow::anyhow!("colour {text:?}: use a name (red, white, …), R,G,B in 0–1 or #rrggbb")
    })?;
    Ok(v.map(|c| c as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_and_bad_ones_are_refused() {
        let (path, m) = mesh_spec("wall.stl:#ff8000:0.5").unwrap();
        assert_eq!(path, PathBuf::from("wall.stl"));
        assert_eq!(m.color, [1.0, 128.0 / 255.0, 0.0]);
        assert_eq!(m.opacity, 0.5);
        assert_eq!(mesh_spec("a.obj:red").unwrap().1.opacity, 1.0);
        assert!(mesh_spec("a.obj:0.2,0.3,0.4:2").is_err());
        assert!(mesh_spec("a.obj:purple").is_err());
        let args = SceneArgs {
            grid: Some("0,0,10:0,0,1:5".into()),
            grid_shift: Some(2.0),
            marker: vec!["1,2,3:4".into(), "0,0,0".into()],
            endoscope: Some("3:15".into()),
            ..SceneArgs::default()
        };
        let scene = args.scene().unwrap().unwrap();
        assert_eq!(scene.endoscope().unwrap().length_mm, 15.0);
        assert_eq!(args.grid("0,0,10:0,0,1:5").unwrap().origin_mm().z, 12.0);
        assert!(args.grid("0,0,10:0,0,0:5").is_err());
        assert!(args.grid("0,0,10:0,0,1").is_err());
        let bad = SceneArgs {
            marker: vec!["1,2,3:-1".into()],
            ..SceneArgs::default()
        };
        assert!(bad.scene().is_err());
        assert!(SceneArgs::default().scene().unwrap().is_none());
    }
}
