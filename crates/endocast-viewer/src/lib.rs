//! The interactive virtual endoscopy workstation behind `endocast view`: fly through a scan in
//! real time with the slices through the camera, the controls, key frames, marks and cases.
//!
//! The parts and who owns what:
//! - [`scene`]: the scan, where it came from, its renderer and value histogram, and the lumen
//!   the camera flies in (the collider's distance field);
//! - [`controller`]: the flying camera (mouse-look, keys, roll, sliding along the wall);
//! - [`worker`]: the render thread, which owns the prepared renderer and draws the newest view
//!   through the library's progressive driver (a quick preview while moving, refinement to
//!   the full frame and an accumulated still when the view stands; new input supersedes the
//!   frame in flight);
//! - [`session`]: the state of one open scan — every user action is a method, so tests drive it
//!   without a window;
//! - [`case`]: case files, written atomically and autosaved;
//! - [`case_choice`]: which case a session reopens and saves to (never one it would replace);
//! - [`review`], [`dissection`], [`cleansing`]: the reading tools of CT colonography (the
//!   wall a flight missed, the wall laid flat, the tagged fluid removed);
//! - [`compare`]: a second scan of the patient (prone beside supine) beside the view, its
//!   camera following the first's through the scans' correspondence;
//! - [`planner`]: the centred path between two points (or to the farthest) as key frames;
//! - [`export`]: the flight filmed (GIF, MP4, PNGs) and its path files (ours, Slicer Markups);
//! - [`geometry`]: the grid, the endoscope's instrument, marker spheres and meshes drawn;
//! - [`jobs`]: work off the UI thread (slices, overview, planning, export, screenshots);
//! - [`app`]: the window (egui), which maps input to the session and draws what it has.
//!
//! ```no_run
//! # #[cfg(feature = "window")] {
//! use endocast_viewer::app::{run, ViewerOptions};
//! use endocast_viewer::scene::ScanSource;
//! use endocast_core::presets::Preset;
//!
//! run(ViewerOptions {
//!     source: ScanSource::Phantom { name: "colon".into(), size: 128 },
//!     preset: Preset::find("colonoscopy"),
//!     pose: None,
//!     case: None,
//!     screenshot: None,
//!     on_screenshot: None,
//!     look: None,
//!     layout: None,
//!     compare: None,
//! })
//! .unwrap();
//! # }
//! ```

#[cfg(feature = "window")]
pub mod app;
pub mod case;
pub mod case_choice;
pub mod cleansing;
#[cfg(feature = "window")]
mod cleansing_ui;
pub mod compare;
#[cfg(feature = "window")]
mod compare_ui;
pub mod controller;
pub mod dissection;
#[cfg(feature = "window")]
mod dissection_ui;
pub mod export;
#[cfg(feature = "window")]
mod flight_ui;
pub mod geometry;
#[cfg(feature = "window")]
mod geometry_ui;
pub mod jobs;
#[cfg(feature = "window")]
pub mod keys;
#[cfg(feature = "window")]
mod loading;
#[cfg(feature = "window")]
mod mark_tool;
#[cfg(feature = "window")]
mod marks;
#[cfg(feature = "window")]
mod overview;
#[cfg(feature = "window")]
mod panel;
pub mod planner;
pub mod review;
#[cfg(feature = "window")]
mod review_ui;
pub mod scene;
pub mod session;
#[cfg(feature = "window")]
mod slice_viewer;
#[cfg(feature = "window")]
mod slices;
#[cfg(feature = "window")]
mod state;
#[cfg(feature = "window")]
mod tf_colours;
#[cfg(feature = "window")]
mod tf_editor;
#[cfg(feature = "window")]
mod view;
pub mod worker;
