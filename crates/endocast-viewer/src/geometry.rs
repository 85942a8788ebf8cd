//! Geometry drawn with the scan (the library's [`Scene`]): an orientation grid, the endoscope's
//! instruments in front of the camera, marker spheres at the marks and at the planned path's
//! ends, and triangle meshes read from files. The toggles are controls; the scene is rebuilt
//! only when they (or the points they mark) change, and meshes are read off the UI thread.

use endocast_core::scene::{Endoscope, GridPlane, Marker, Material, Scene};
use endocast_io::mesh::MeshFormat;
use endocast_io::overlay_scene::add_overlay;
use endocast_io::Limits;
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Spacing of the orientation grid's lines, mm.
pub const GRID_SPACING_MM: f64 = 10.0;
/// Diameter of the endoscope's instrument, mm (a common working channel's).
pub const INSTRUMENT_DIAMETER_MM: f64 = 2.8;
/// Radius of the marker spheres, mm.
pub const MARKER_RADIUS_MM: f64 = 1.5;

/// Which geometry is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Toggles {
    /// An axial grid of lines through the scan's centre.
    pub grid: bool,
    /// The endoscope's instrument in front of the camera.
    pub endoscope: bool,
    /// Spheres at the marks.
    pub markers: bool,
    /// The meshes read.
    pub meshes: bool,
}

/// A shared scene compared by identity (the render worker re-applies it when it changes).
#[derive(Debug, Clone, Default)]
pub struct SceneRef(pub Option<Arc<Scene>>);

impl PartialEq for SceneRef {
    fn eq(&self, other: &Self) -> bool {
        match (&self.0, &other.0) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (a, b) => a.is_none() && b.is_none(),
        }
    }
}

/// What a scene is built from.
#[derive(Debug, Clone, PartialEq)]
struct Built {
    toggles: Toggles,
    markers_mm: Vec<DVec3>,
    meshes: usize,
}

/// The meshes read (their hierarchies built) and the scene last built.
#[derive(Debug, Default)]
pub struct Geometry {
    meshes: Scene,
    files: Vec<PathBuf>,
    built: Option<(Built, SceneRef)>,
}

impl Geometry {
    /// The meshes read so far, as a scene to add one to (see [`with_mesh`]).
    pub fn meshes(&self) -> &Scene {
        &self.meshes
    }

    /// Takes `meshes` (the old ones and the one read from `file`, from [`with_mesh`]); the
    /// file is kept absolute, so that a case saved elsewhere still finds it.
    pub fn set_meshes(&mut self, meshes: Scene, file: PathBuf) {
        self.meshes = meshes;
        self.files.push(std::path::absolute(&file).unwrap_or(file));
    }

    /// The files of the meshes read.
    pub fn mesh_files(&self) -> &[PathBuf] {
        &self.files
    }

    /// The scene for `toggles` with markers at `markers_mm`, around `centre_mm` (the grid's
    /// point); the same one as last time when nothing changed.
    pub fn scene(
        &mut self,
        toggles: Toggles,
        markers_mm: Vec<DVec3>,
        centre_mm: DVec3,
    ) -> SceneRef {
        let wanted = Built {
            toggles,
            markers_mm,
            meshes: self.files.len(),
        };
        if let Some((built, scene)) = &self.built {
            if *built == wanted {
                return scene.clone();
            }
        }
        let scene = self.build(&wanted, centre_mm);
        let scene = SceneRef((!scene.is_empty()).then(|| Arc::new(scene)));
        self.built = Some((wanted, scene.clone()));
        scene
    }

    fn build(&self, wanted: &Built, centre_mm: DVec3) -> Scene {
        let t = wanted.toggles;
        // Cloning shares the meshes and their hierarchies.
        let mut scene = if t.meshes {
            self.meshes.clone()
        } else {
            Scene::new()
        };
        if t.grid {
            if let Ok(grid) = GridPlane::new(centre_mm, DVec3::Z, GRID_SPACING_MM) {
                scene.add_grid(grid, Material::GRID);
            }
        }
        if t.markers {
            for &p in &wanted.markers_mm {
                if let Ok(marker) = Marker::new(p, MARKER_RADIUS_MM) {
                    scene.add_marker(marker, Material::MARKER);
                }
            }
        }
        if t.endoscope {
            let length = endocast_core::scene::DEFAULT_INSTRUMENT_LENGTH_MM;
            scene.set_endoscope(Endoscope::new(INSTRUMENT_DIAMETER_MM, length).ok());
        }
        scene
    }
}

/// `meshes` with the geometry in `path` added, its hierarchy built: a mesh (STL, OBJ or PLY,
/// world mm), or else a DICOM overlay (`FILE[:LEVELS]`: a segmentation's segments or a dose grid's isodose
/// surfaces, as `--overlay` draws them). Slow for large meshes, so run it off the UI thread.
/// The error names the file.
pub fn with_mesh(mut meshes: Scene, path: &Path) -> Result<Scene, String> {
    if MeshFormat::of(path).is_err() {
        let spec = path.to_string_lossy();
        add_overlay(&mut meshes, &spec, &Limits::default()).map_err(|e| e.to_string())?;
        return Ok(meshes);
    }
    let mesh =
        endocast_io::mesh::read_mesh(path).map_err(|e| format!("cannot read the mesh: {e}"))?;
    meshes.add_mesh(&mesh, Material::MESH);
    Ok(meshes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use endocast_testdata::overlays::{write_segmentation, Grid, SegFrame};

    #[test]
    fn a_dicom_segmentation_is_added_as_its_surfaces() {
        let dir = tempfile::tempdir().unwrap();
        let seg = dir.path().join("seg.dcm");
        let grid = Grid {
            origin: [0.0, 0.0, 0.0],
            spacing: [1.0, 1.0],
            size: [4, 4],
        };
        let frames: Vec<SegFrame> = (0..3)
            .map(|z| SegFrame {
                segment: 1,
                z: f64::from(z),
                pixels: vec![(1, 1), (1, 2), (2, 1), (2, 2)],
            })
            .collect();
        write_segmentation(&seg, &grid, &[(1, "node", [34865, 53485, 50171])], &frames);
        assert!(!with_mesh(Scene::new(), &seg).unwrap().is_empty());
        let missing = dir.path().join("gone.dcm");
        let error = with_mesh(Scene::new(), &missing).unwrap_err();
        assert!(error.contains("gone.dcm"), "{error}");
    }
}
