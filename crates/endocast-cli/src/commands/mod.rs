//! One module per subcommand.

pub mod annotate;
pub mod batch;
pub mod bench;
pub mod convert;
pub mod coverage;
pub mod dissect;
pub mod film;
pub mod fly;
mod fly_coverage;
mod fly_dataset;
mod fly_frames;
pub mod info;
pub mod match_scans;
pub mod mesh;
pub mod path;
mod path_target;
pub mod phantom;
pub mod polyps;
pub mod presets;
pub mod render;
pub mod view;
