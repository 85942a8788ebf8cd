//! Analytic phantoms: CT-like volumes whose right answers are known, for every test that needs a
//! scan (the ray caster's depth to a sphere, the centreline of a tube, two isosurfaces in a
//! joint) without a data file.
//!
//! ```
//! use endocast_core::phantom::{self, Phantom, PhantomOptions};
//!
//! let options = PhantomOptions { size: 32, ..Default::default() };
//! let volume = Phantom::StraightTube.build(&options);
//! let (same, tube) = phantom::straight_tube(&options);
//! assert_eq!(volume.voxels(), same.voxels());
//! // The lumen is air on the axis, tissue well outside the radius.
//! let axis = tube.centreline.point_at(10.0);
//! assert_eq!(volume.sample_physical(axis), Some(-1000.0));
//! let wall = axis + glam::DVec3::X * (tube.radius_vox + 2.0);
//! assert_eq!(volume.sample_physical(wall), Some(40.0));
//! ```
//!
//! Conventions shared by all phantoms:
//! - Values are Hounsfield units (see [`profile`] for each material), stored with
//!   `ValueMap::new(1.0, -1024.0)` and `Modality::Ct`.
//! - Spacing 1 mm isotropic, identity direction (LPS), origin chosen so that the centre of the
//!   grid is at world (0, 0, 0); world = voxel index − (dims − 1) / 2.
//! - Every analytic truth is given in continuous voxel index space (`*_vox`).
//! - Every boundary is a linear ramp two voxels wide centred on the analytic surface, so the
//!   value halfway between two materials (e.g. −480 HU between air and tissue) is crossed on the
//!   surface to within a few hundredths of a voxel under trilinear interpolation.
//! - Noise, when asked for, is Gaussian and a pure function of (seed, voxel index).

mod bins;
mod centreline;
mod colon;
mod colon_polyps;
mod colon_prone;
mod curved_tube;
mod joint;
mod layered;
mod noise;
mod polyp;
pub mod profile;
mod raster;
mod shape;
mod sinus;
mod sphere_shell;
mod straight_tube;
mod tagged_pool;
mod vessel;

pub use centreline::Centreline;
pub use colon::{colon, Colon, Fold};
pub use colon_polyps::{colon_polyps, PolypColon, POLYP_DIAMETER_MM};
pub use colon_prone::{colon_prone, ColonPair};
pub use curved_tube::{curved_tube, CurvedTube};
pub use joint::{joint, Joint};
pub use layered::{layered, Layered, SECRETION_HU};
pub use polyp::{Polyp, PolypShape};
pub use shape::Ball;
pub use sinus::{sinus, Cavity, Septum, Sinus};
pub use sphere_shell::{sphere_shell, SphereShell};
pub use straight_tube::{straight_tube, Tube};
pub use tagged_pool::{Pool, TAGGED_FLUID_HU};
pub use vessel::{vessel, Stent, Vessel};

#[cfg(test)]
pub(crate) use raster::rasterize;

use crate::Volume;

/// The phantoms, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Phantom {
    /// A spherical shell of tissue with air inside and outside ([`sphere_shell`]).
    SphereShell,
    /// An air-filled cylinder along `k` through tissue ([`straight_tube`]).
    StraightTube,
    /// An air-filled tube bent through 270° along a circular arc ([`curved_tube`]).
    CurvedTube,
    /// A colon-like air tube along a winding 3-D curve, with folds and polyps ([`colon`]).
    Colon,
    /// A contrast-filled vessel with a stent and calcifications ([`vessel`]).
    Vessel,
    /// Three bones with a thin contrast layer between each two ([`joint`]).
    Joint,
    /// Air cavities divided by thin bony septa ([`sinus`]).
    Sinus,
    /// Air over a secretion layer of known, varying thickness over tissue ([`layered`]).
    Layered,
    /// The colon of the same options scanned prone: deformed and turned over
    /// ([`colon_prone`]).
    ColonProne,
}

impl Phantom {
    /// Every phantom, in a fixed order.
    pub const ALL: [Phantom; 9] = [
        Self::SphereShell,
        Self::StraightTube,
        Self::CurvedTube,
        Self::Colon,
        Self::Vessel,
        Self::Joint,
        Self::Sinus,
        Self::Layered,
        Self::ColonProne,
    ];

    /// The kebab-case name (`sphere-shell`, `straight-tube`, `curved-tube`, `colon`, `vessel`, `joint`, `sinus`, `layered`, `colon-prone`).
    pub fn name(self) -> &'static str {
        match self {
            Self::SphereShell => "sphere-shell",
            Self::StraightTube => "straight-tube",
            Self::CurvedTube => "curved-tube",
            Self::Colon => "colon",
            Self::Vessel => "vessel",
            Self::Joint => "joint",
            Self::Sinus => "sinus",
            Self::Layered => "layered",
            Self::ColonProne => "colon-prone",
        }
    }

    /// The phantom called `name` (as given by [`Phantom::name`], ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name.trim()))
    }

    /// One line saying what the phantom is and what it tests.
    pub fn description(self) -> &'static str {
        match self {
            Self::SphereShell => "tissue shell with air inside and outside: depth to a sphere",
            Self::StraightTube => "air cylinder along k through tissue: the simplest lumen",
            Self::CurvedTube => {
                "air tube bent through 270 degrees along an arc: paths around a bend"
            }
            Self::Colon => {
                "winding air tube with haustral folds and polyps (or N drawn ones): fly-through"
            }
            Self::Vessel => "contrast-filled vessel with a metal stent and calcifications",
            Self::Joint => {
                "three bones around two thin contrast layers: two isosurfaces, depth peeling"
            }
            Self::Sinus => "air cavities divided by thin bony septa: thin structures",
            Self::Layered => {
                "air over a secretion layer of known, growing thickness over tissue: secretion"
            }
            Self::ColonProne => {
                "the colon of the same seed prone: sagged, stretched and turned over: supine/prone"
            }
        }
    }

    /// Generates the phantom's volume (see the module doc for its conventions).
    pub fn build(self, options: &PhantomOptions) -> Volume {
        match self {
            Self::SphereShell => sphere_shell(options).0,
            Self::StraightTube => straight_tube(options).0,
            Self::CurvedTube => curved_tube(options).0,
            Self::Colon => match options.polyps {
                Some(count) => colon_polyps(options, count).0,
                None => colon(options).0,
            },
            Self::Vessel => vessel(options).0,
            Self::Joint => joint(options).0,
            Self::Sinus => sinus(options).0,
            Self::Layered => layered(options).0,
            Self::ColonProne => colon_prone(options).0,
        }
    }
}

/// How to generate a phantom.
///
/// Not `#[non_exhaustive]`, so that `PhantomOptions { size: 32, ..Default::default() }` works
/// outside this crate; new fields will always come with a default.
#[derive(Debug, Clone, PartialEq)]
pub struct PhantomOptions {
    /// The largest dimension, in voxels (1 mm each): the other dimensions and every feature scale
    /// with it. The colon keeps the 512 × 512 × 478 aspect of its "paper size" 512. Clamped to
    /// `8..=4096`. Default 128.
    pub size: usize,
    /// Standard deviation of added Gaussian noise, in HU; 0 (the default), negative or non-finite
    /// values add none.
    pub noise_hu: f64,
    /// Seed of the noise; the same seed gives the same voxels on any machine and thread count.
    /// Default 1.
    pub seed: u64,
    /// The colon only: this many polyps of drawn sizes, shapes and places (drawn with `seed`,
    /// see [`colon_polyps`]) instead of its five fixed ones; `Some(0)` gives folds only.
    /// Default `None`.
    pub polyps: Option<usize>,
    /// The colon: pools of tagged fluid (oral contrast) under the air in its sumps, for
    /// electronic cleansing. Other phantoms ignore it. Default false.
    pub tagged_fluid: bool,
}

impl Default for PhantomOptions {
    fn default() -> Self {
        Self {
            size: 128,
            noise_hu: 0.0,
            seed: 1,
            polyps: None,
            tagged_fluid: false,
        }
    }
}

impl PhantomOptions {
    /// Smallest size honoured: below it the features vanish in the boundary ramps.
    const MIN_SIZE: usize = 8;
    /// Largest size honoured: keeps voxel counts far from overflow (4096³ is already 128 GiB).
    const MAX_SIZE: usize = 4096;

    /// The size actually used, as a float for the geometry that scales with it.
    fn size_vox(&self) -> f64 {
        self.size.clamp(Self::MIN_SIZE, Self::MAX_SIZE) as f64
    }

    /// The cube `size³` most phantoms use.
    fn cube(&self) -> [usize; 3] {
        [self.size_vox() as usize; 3]
    }

    /// The noise σ actually used (HU).
    fn noise_sigma_hu(&self) -> f64 {
        if self.noise_hu.is_finite() && self.noise_hu > 0.0 {
            self.noise_hu
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests;
