//! The camera pose options that `render`, `view` and `annotate` share.

use crate::parse::parse_vec3;
use anyhow::{bail, Result};
use clap::Args;
use endocast_core::camera::default_up;
use endocast_core::pose::Pose;
use glam::DVec3;

/// `--eye`, `--look-at` and `--up`: where the camera is and where it looks, world mm (LPS).
#[derive(Args, Debug, Clone, Copy)]
pub struct PoseArgs {
    /// Eye position, world mm (LPS, as `endocast info` reports), with --look-at. Without both,
    /// `render` and `view` start inside the structure the preset means, looking along it
    /// (without a preset, framing the whole object); `annotate` needs both to pick pixels.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub eye: Option<[f64; 3]>,
    /// Point looked at, world mm (with --eye).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub look_at: Option<[f64; 3]>,
    /// Up direction (default: superior, +z; posterior when looking up or down).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<[f64; 3]>,
}

impl PoseArgs {
    /// The camera the user placed, `None` when they placed none; up defaults to superior
    /// ([`default_up`]).
    pub fn pose(&self) -> Result<Option<Pose>> {
        match (self.eye, self.look_at) {
            (Some(eye), Some(look_at)) => {
                let (eye_mm, look_at_mm) = (DVec3::from(eye), DVec3::from(look_at));
                Ok(Some(Pose {
                    eye_mm,
                    look_at_mm,
                    up: self
                        .up
                        .map_or_else(|| default_up(look_at_mm - eye_mm), DVec3::from),
                }))
            }
            (None, None) => Ok(None),
            _ => bail!("--eye and --look-at go together"),
        }
    }

    /// `pose` with the `--up` given, if any, in place of its own up.
    pub fn with_up(&self, pose: Pose) -> Pose {
        Pose {
            up: self.up.map_or(pose.up, DVec3::from),
            ..pose
        }
    }
}
