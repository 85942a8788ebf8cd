//! The heart of endocast, free of file formats and GUI: the [`Volume`] every reader produces,
//! its [`Geometry`] in the patient frame, and analytic [`phantom`]s whose right answers are known.
//! The procedures' defaults (mode, transfer function, isovalues, lumen, slice window, lens) live
//! in one table, [`presets`], which every front end reads.
//!
//! ```
//! use endocast_core::phantom::{Phantom, PhantomOptions};
//!
//! let volume = Phantom::SphereShell.build(&PhantomOptions { size: 32, ..Default::default() });
//! assert_eq!(volume.dims(), [32, 32, 32]);
//! let (lo, hi) = volume.physical_range();
//! assert!(lo < -500.0 && hi > 0.0);
//! ```

pub mod animation;
pub mod annotate;
pub mod camera;
pub mod cleanse;
pub mod correspond;
pub mod coverage;
pub mod dataset;
pub mod dissect;
pub mod flight;
pub mod geometry;
pub mod isosurface;
pub mod look;
pub mod navigate;
pub mod path;
pub mod phantom;
pub mod polyps;
pub mod pose;
pub mod presets;
pub mod render;
pub mod scene;
pub mod study;
#[cfg(test)]
mod test_rng;
pub mod tissue;
pub mod views;
pub mod volume;

pub use geometry::{Geometry, GeometryError};
pub use volume::{Modality, ValueMap, Volume, VolumeError};
