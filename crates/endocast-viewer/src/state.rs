//! What the window keeps beside the session, shared by the window's parts.

use crate::case::Autosave;
use crate::cleansing::CleanseSwitch;
use crate::compare_ui::CompareView;
use crate::dissection_ui::DissectionView;
use crate::flight_ui::FlightTools;
use crate::geometry_ui::MeshLoader;
use crate::jobs::Job;
use crate::mark_tool::MarkTool;
use crate::overview::OverviewView;
use crate::review::ReviewTools;
use crate::session::Session;
use crate::slice_viewer::SliceViewer;
use crate::slices::SlicesView;
use endocast_core::render::progressive::Stage;
use std::time::Instant;

/// The open session and what the window keeps beside it.
pub(crate) struct Ready {
    pub session: Session,
    pub slices: SlicesView,
    /// The slice shown large beside the endoscope, if one is.
    pub large_slice: Option<SliceViewer>,
    pub overview: OverviewView,
    /// Path planning and export.
    pub tools: FlightTools,
    /// Reading meshes.
    pub meshes: MeshLoader,
    /// Background tasks whose result is a line for the status bar (a screenshot).
    pub tasks: Vec<Job<String>>,
    pub autosave: Autosave,
    pub view_texture: Option<egui::TextureHandle>,
    pub shown: Option<(u64, Stage, u64)>,
    /// What clicks and drags in the view do: look, label, draw or measure.
    pub marks: MarkTool,
    /// The last time the camera was moved by input.
    pub last_input: Option<Instant>,
    /// The review of the wall a flight missed.
    pub review: ReviewTools,
    /// The virtual dissection and its flat view.
    pub dissection: DissectionView,
    /// The scan cleansed of tagged fluid, or as acquired.
    pub cleanse: CleanseSwitch,
    /// A second scan (prone beside supine) whose view follows this one.
    pub compare: CompareView,
}

impl Ready {
    /// Forgets what was derived from the scan shown before it changed (cleansed or restored):
    /// the slices, the overview, the review and the dissection are made again on the new one.
    pub fn scene_changed(&mut self) {
        self.slices = SlicesView::default();
        self.overview = OverviewView::default();
        if let Some(viewer) = &mut self.large_slice {
            viewer.forget_image();
        }
        self.shown = None;
        self.review = ReviewTools::default();
        self.dissection.tools.clear();
    }
}

/// What the control panel asks of the application.
pub(crate) enum Action {
    /// Open the path typed in the panel (a scan, or a case file `.json`).
    Open,
    /// Read another series of the open DICOM folder (its SeriesInstanceUID).
    OpenSeries(String),
    /// Read the scan again with its index axes pointing as this code says (a file that
    /// declares no orientation, turned the other way up).
    Reorient(String),
    /// Open the path typed in the panel as a second scan beside this one (prone beside
    /// supine), its camera following this one.
    Compare,
    /// Save the case now.
    SaveCase,
    /// Show a line in the status bar.
    Message(String),
}
