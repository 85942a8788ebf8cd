//! The camera pose options that `render`, `view` and `annotate` share.

use crate::parse::parse_vec3;
use clap::Args;

/// `--eye`, `--look-at` and `--up`: where the camera is and where it looks, world mm (LPS).
#[derive(Args, Debug, Clone, Copy)]
pub struct PoseArgs {
    /// Eye position, world mm (LPS, as `endocast info` reports), with --look-at. Without both,
    /// `render` and `view` start inside the structure the preset means, looking along it
    /// (`render` without a preset frames the whole volume); `annotate` needs both to pick pixels.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<[f64; 3]>,
    /// Point looked at, world mm (with --eye).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub look_at: Option<[f64; 3]>,
    /// Up direction (default: superior, +z; posterior when looking up or down).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<[f64; 3]>,
}
