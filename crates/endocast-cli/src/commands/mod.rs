//! One module per subcommand.

pub mod annotate;
pub mod bench;
pub mod convert;
pub mod coverage;
pub mod dissect;
pub mod fly;
mod fly_coverage;
pub mod info;
pub mod mesh;
pub mod path;
pub mod phantom;
pub mod presets;
pub mod render;
pub mod view;
