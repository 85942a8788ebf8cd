//! End-to-end tests of the `endocast` binary, one module per topic, one test binary.

#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod annotate;
mod bad_input;
mod batch;
mod bronchoscopy;
mod cleanse;
mod common;
mod default_views;
mod dissect;
mod info_shared_data;
mod integrity;
mod look;
mod navigation;
mod phantom_convert;
mod presets;
mod readme;
mod real_scans;
mod render;
mod scene;
mod study_table;
mod view;
mod zarr_round_trip;
