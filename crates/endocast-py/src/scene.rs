//! Geometry drawn with the scan by `render` and `fly`: `meshes` (STL, OBJ or PLY files, world
//! mm) and `overlays` (DICOM segmentations and dose grids, `FILE` or `FILE:LEVEL,LEVEL,…`), as
//! the command's `--mesh` and `--overlay` draw them.

use crate::errors::{error, to_py};
use crate::kwargs::Kwargs;
use endocast_core::scene::{Material, Scene};
use endocast_io::overlay_scene::add_overlay;
use endocast_io::Limits;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::Arc;

/// The geometry files a call names, read by [`SceneFiles::read`].
pub struct SceneFiles {
    meshes: Vec<PathBuf>,
    overlays: Vec<PathBuf>,
}

impl SceneFiles {
    /// Takes `meshes` and `overlays` (each a list of file names).
    pub fn take(kw: &Kwargs<'_>) -> PyResult<Self> {
        Ok(Self {
            meshes: kw.take("meshes")?.unwrap_or_default(),
            overlays: kw.take("overlays")?.unwrap_or_default(),
        })
    }

    /// The scene of the files (slow for large meshes: call it without the GIL), `None` when
    /// there are none; with a line for each overlay not drawn whole (a dose level outside the
    /// grid's range), for a Python warning.
    pub fn read(&self) -> PyResult<(Option<Arc<Scene>>, Vec<String>)> {
        let mut scene = Scene::new();
        for path in &self.meshes {
            let mesh = endocast_io::mesh::read_mesh(path)
                .map_err(|e| error(format!("cannot read the mesh: {e}")))?;
            scene.add_mesh(&mesh, Material::MESH);
        }
        let mut partial = Vec::new();
        for spec in &self.overlays {
            let spec = spec.to_string_lossy();
            let drawn = add_overlay(&mut scene, &spec, &Limits::default()).map_err(to_py)?;
            if !drawn.complete {
                partial.push(drawn.summary);
            }
        }
        Ok(((!scene.is_empty()).then(|| Arc::new(scene)), partial))
    }
}

/// Issues a Python `UserWarning` for each line.
pub fn warn(py: Python<'_>, lines: &[String]) -> PyResult<()> {
    let warnings = py.import("warnings")?;
    for line in lines {
        warnings.call_method1("warn", (line.as_str(),))?;
    }
    Ok(())
}
