//! Navigation through a lumen: the lumen itself ([`Lumen`]), the distance of every lumen voxel
//! to the wall ([`DistanceField`]), a camera that slides along the wall instead of entering it
//! ([`Collider`]), the minimal centred path between two points ([`centreline`]) and a default
//! viewpoint for a scan ([`default_viewpoint`]).
//!
//! ```
//! use endocast_core::navigate::{DistanceField, Lumen, LumenSide};
//! use endocast_core::phantom::{self, PhantomOptions};
//!
//! let (volume, tube) = phantom::straight_tube(&PhantomOptions { size: 32, ..Default::default() });
//! let lumen = Lumen::from_seed(&volume, [16, 16, 16], -480.0, LumenSide::Below)?;
//! let field = DistanceField::new(&lumen, volume.geometry());
//! // The widest point lies a tube radius (give or take a voxel) from the wall.
//! assert!((field.max_mm() - tube.radius_vox).abs() < 1.0);
//! # Ok::<(), endocast_core::navigate::NavError>(())
//! ```
//!
//! Units: points are world millimetres (LPS) unless a name says `voxel`; voxel indices are
//! `[usize; 3]` of the volume, `i` first.

mod airway;
mod aorta;
mod axial;
mod bit_grid;
mod central;
mod centreline;
mod collision;
mod colon;
mod distance;
mod error;
mod faces;
mod joint;
mod lumen;
mod nasal;
mod plan;
mod preset;
mod section;
mod side;
mod snap;
#[cfg(test)]
mod test_util;
mod trachea;
mod upright;
mod viewpoint;

pub use airway::{AirwayBranch, AirwayRoute, AirwayTree, RouteError, DEFAULT_SCOPE_DIAMETER_MM};
pub use aorta::{find_aorta, Aorta};
pub use central::{CENTRAL_DEPTH_MM, CENTRAL_ML};
pub use centreline::{
    centreline, snap_radius_mm, CentrelinePath, PathEnd, SNAP_RADIUS_MM, SNAP_RADIUS_VOXELS,
};
pub use collision::Collider;
pub use colon::find_colon;
pub use distance::DistanceField;
pub use error::NavError;
pub use faces::FACE_MARGIN_MM;
pub use joint::{find_joint, Joint, BONE_CORE_DEPTH_MM, JOINT_REACH_MM, MAX_JOINT_GAP_MM};
pub use lumen::{Lumen, LumenSide};
pub use nasal::{
    find_nasal_cavity, NasalCavity, FRONT_SHARE, MIN_ROUTE_MM, PASSAGE_HALF_WIDTH_MM,
    SCOPE_RADIUS_MM,
};
pub use plan::{plan_in, plan_path, seed_voxel, smooth_centreline, smooth_raw, PlannedPath};
pub use preset::{preset_lumen, Central, LumenChoice, LumenChoiceError};
pub use snap::nearest_lumen_point;
pub use trachea::find_trachea;
pub use upright::{guess_head_orientation, UprightGuess};
pub(crate) use viewpoint::looking_along;
pub use viewpoint::{
    default_view, default_viewpoint, viewpoint_in, DefaultView, FramingReason, NOT_CONFIDENT,
};
