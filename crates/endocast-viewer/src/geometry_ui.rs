//! The panel's geometry section: the toggles (grid, the endoscope's instrument, marker
//! spheres at the marks, meshes) and reading a mesh off the UI thread.

use crate::geometry::with_mesh;
use crate::jobs::{Job, Polled};
use crate::session::Session;
use endocast_core::scene::Scene;
use std::path::PathBuf;
use std::sync::Arc;

/// A mesh being read, and the file field.
#[derive(Default)]
pub(crate) struct MeshLoader {
    path: String,
    job: Option<Job<Result<(Scene, PathBuf), String>>>,
}

impl MeshLoader {
    /// The toggles and the mesh field; returns a status line for errors.
    pub(crate) fn geometry_ui(
        &mut self,
        ui: &mut egui::Ui,
        session: &mut Session,
    ) -> Option<String> {
        let t = &mut session.controls.geometry;
        ui.horizontal(|ui| {
            ui.checkbox(&mut t.grid, "grid");
            ui.checkbox(&mut t.endoscope, "instrument");
            ui.checkbox(&mut t.markers, "mark spheres");
        });
        let files = session.geometry_mut().mesh_files().len();
        ui.add_enabled(
            files > 0,
            egui::Checkbox::new(
                &mut session.controls.geometry.meshes,
                format!("meshes ({files})"),
            ),
        );
        if self.job.is_some() {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label("reading the mesh…");
            });
            return None;
        }
        let mut message = None;
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(&mut self.path)
                    .hint_text("mesh .stl .obj .ply, or DICOM SEG/RTDOSE")
                    .desired_width(170.0),
            );
            if ui.button("Add mesh").clicked() {
                let path = PathBuf::from(self.path.trim());
                let meshes = session.geometry_mut().meshes().clone();
                let ctx = ui.ctx().clone();
                let notify = Arc::new(move || ctx.request_repaint());
                self.job = Some(Job::spawn("mesh", notify, move || {
                    with_mesh(meshes, &path).map(|scene| (scene, path))
                }));
                message = Some(format!("reading {}", self.path.trim()));
            }
        });
        message
    }

    /// Takes a mesh read (and shows the meshes); returns a status line when one was read or
    /// failed.
    pub(crate) fn poll(&mut self, session: &mut Session) -> Option<String> {
        let polled = self.job.as_ref()?.poll();
        let result = match polled {
            Polled::Running => return None,
            Polled::Done(result) => result,
            Polled::Lost => Err("reading the mesh stopped".into()),
        };
        self.job = None;
        Some(match result {
            Ok((meshes, path)) => {
                let line = format!("read {}", path.display());
                session.geometry_mut().set_meshes(meshes, path);
                session.controls.geometry.meshes = true;
                line
            }
            Err(e) => e,
        })
    }
}
