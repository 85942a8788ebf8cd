//! Electronic cleansing: tagged fluid removed from a CT colonography scan, so that the wall under
//! a pool renders as wall at its own depth instead of the pool's surface.
//!
//! In CT colonography the patient drinks oral contrast that tags residual fluid: it lies in the
//! colon's sumps as bright pools (≈ 300–1000 HU) under the air, its surface a flat level
//! perpendicular to gravity. Rendered as is, the air/fluid level is a wall, and where the pool
//! meets the real wall the partial volumes between tag and tissue read as a thin bright ring.
//! Cleansing works in three steps, after the published methods but not their code:
//! - **Tag**: voxels above [`TAG_THRESHOLD_HU`] in 6-connected components ([`pools`]), as in the
//!   thresholding-and-connectivity step of Zalis, Perumpillichira & Hahn, "Digital subtraction
//!   bowel cleansing for CT colonography using morphological and linear filtration methods",
//!   IEEE Trans. Med. Imaging 23(11), 2004.
//! - **Pools**: a component is fluid only if it lies under air with a flat level across it and
//!   nothing of it above that level; bone, contrast-filled vessels and bowel loops full of tagged
//!   fluid have no such level and stay as they are. (Zalis et al. rely on the air/fluid boundary
//!   being horizontal too.)
//! - **Rims** ([`rim`]): every voxel within [`RIM_MM`] of a pool is taken as a mixture of air,
//!   tagged fluid and tissue. The fluid's share is known from where the voxel lies against the
//!   level (the level's blur, [`LEVEL_RAMP_VOX`]), the tissue's share then from its value, and
//!   the voxel is rewritten as the same share of tissue in air. So the tag → tissue ramp at the
//!   wall becomes an air → tissue ramp crossed at the same place (its midpoint stays on the
//!   wall), the air/fluid level becomes air, and the wall's air → tissue ramp above the level is
//!   left untouched. This is the partial-volume view of Näppi & Yoshida, "Fully automated
//!   three-dimensional detection of polyps in fecal-tagging CT colonography" (Acad. Radiol.
//!   14(3), 2007) and of the air/tissue/fluid mixture model of Cai, Zalis, Näppi, Harris &
//!   Yoshida, "Structure-analysis method for electronic cleansing in cathartic and noncathartic
//!   CT colonography" (Med. Phys. 35(7), 2008), here with a fixed soft-tissue value and a
//!   linear level profile instead of their local structure analysis.
//!
//! The patient is taken to lie supine or prone (gravity either way along the index axis closest
//! to the patient's anterior–posterior axis; each pool is tried both ways); a decubitus scan's
//! levels are not found and the scan is left as it is.
//!
//! ```
//! use endocast_core::cleanse::cleanse;
//! use endocast_core::phantom::{Phantom, PhantomOptions};
//!
//! let options = PhantomOptions { size: 192, tagged_fluid: true, ..Default::default() };
//! let cleansed = cleanse(&Phantom::Colon.build(&options)).unwrap();
//! assert!(!cleansed.pools.is_empty());
//! let [nx, ny, nz] = cleansed.volume.dims();
//! let brightest = (0..nz).flat_map(|k| (0..ny).flat_map(move |j| (0..nx).map(move |i| (i, j, k))))
//!     .map(|(i, j, k)| cleansed.volume.physical(i, j, k).unwrap())
//!     .fold(f64::MIN, f64::max);
//! // Nothing left at the tag's level (200 HU; soft tissue is about 40).
//! assert!(brightest < 200.0, "tagged fluid left: {brightest} HU");
//! ```

mod gravity;
mod pools;
mod rim;

#[cfg(test)]
mod tests;

pub use gravity::Gravity;
pub use pools::TaggedPool;

use crate::tissue::{ScanValues, ValueKind};
use crate::{Modality, Volume};
use std::fmt;

/// Tagged fluid is brighter than this, HU (soft tissue and unenhanced wall are below ~100).
pub const TAG_THRESHOLD_HU: f64 = 200.0;
/// How far around a pool its partial volumes reach, mm (a CT's blur is one to two voxels).
pub const RIM_MM: f64 = 2.0;
/// Width of the air/fluid level's blur across the level, voxels along gravity.
pub const LEVEL_RAMP_VOX: f64 = 2.0;
/// The air the fluid is replaced with, HU.
pub const AIR_HU: f64 = -1000.0;
/// The soft tissue (colon wall) the fluid is taken to meet, HU.
pub const SOFT_TISSUE_HU: f64 = 40.0;

/// Whether a study's scan is cleansed: `--cleanse on|off` on every command, the viewer's
/// checkbox and Python's `cleanse=`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Cleanse {
    /// The scan as acquired (the default: cleansing changes what the reader sees, so it is asked
    /// for, and a scan without tagged fluid gains nothing from it).
    #[default]
    Off,
    /// Tagged fluid removed ([`cleanse`]).
    On,
}

impl Cleanse {
    /// `on` or `off` (ASCII case ignored); `None` for anything else.
    pub fn from_name(name: &str) -> Option<Self> {
        match name.trim().to_ascii_lowercase().as_str() {
            "on" => Some(Self::On),
            "off" => Some(Self::Off),
            _ => None,
        }
    }

    /// `volume` as this switch asks, with the line to tell the user: the scan itself when
    /// [`Cleanse::Off`], its cleansed copy ([`cleanse`]) when [`Cleanse::On`]. Every front end
    /// loads its study's scan through this.
    pub fn apply(self, volume: Volume) -> Result<(Volume, Option<String>), CleanseError> {
        match self {
            Self::Off => Ok((volume, None)),
            Self::On => {
                let cleansed = cleanse(&volume)?;
                let summary = cleansed.summary();
                Ok((cleansed.volume, Some(summary)))
            }
        }
    }
}

/// A scan with its tagged fluid removed.
#[derive(Debug, Clone)]
pub struct Cleansed {
    /// The cleansed copy (same geometry, value map and modality as the original).
    pub volume: Volume,
    /// The pools found and removed, largest first.
    pub pools: Vec<TaggedPool>,
    /// Voxels whose value changed.
    pub changed_voxels: usize,
}

impl Cleansed {
    /// One line for the user: how many pools, their levels and the voxels changed.
    pub fn summary(&self) -> String {
        if self.pools.is_empty() {
            return "cleansing: no tagged fluid under air found; the scan is unchanged".to_owned();
        }
        let fluid: usize = self.pools.iter().map(|p| p.voxels).sum();
        format!(
            "cleansing: {} pool(s) of tagged fluid ({fluid} voxels, median tag {:.0} HU) removed; \
             {} voxels changed",
            self.pools.len(),
            self.pools[0].tag_hu,
            self.changed_voxels
        )
    }
}

/// Why a scan cannot be cleansed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CleanseError {
    /// The scan's values are not Hounsfield units: an MR or other modality, or values that do
    /// not look like HU.
    NotHounsfield,
}

impl fmt::Display for CleanseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotHounsfield => write!(
                f,
                "electronic cleansing needs a CT in Hounsfield units; this scan's values are not"
            ),
        }
    }
}

impl std::error::Error for CleanseError {}

/// `volume` with its tagged fluid and the fluid's partial volumes replaced by air (see the
/// module documentation). The original is not changed.
pub fn cleanse(volume: &Volume) -> Result<Cleansed, CleanseError> {
    let offset = hounsfield_offset(volume.modality(), &ScanValues::measure(volume))?;
    let scan = pools::HuScan::new(volume, offset);
    let gravity = Gravity::supine_or_prone(volume.geometry());
    let found = pools::find(&scan, &gravity);
    let mut voxels = volume.voxels().to_vec();
    let changed_voxels = rim::rewrite(&scan, &found, &mut voxels);
    let cleansed = Volume::new(
        *volume.geometry(),
        voxels,
        volume.value_map(),
        volume.modality().clone(),
    )
    .unwrap_or_else(|e| unreachable!("a copy of the voxels keeps their count: {e}"));
    Ok(Cleansed {
        volume: cleansed,
        pools: found.into_iter().map(|p| p.pool).collect(),
        changed_voxels,
    })
}

/// Whether a scan of `modality` whose values measure as `values` can be cleansed: a CT (or a
/// scan that does not say what it is) in Hounsfield units; the offset of its values from HU.
/// [`cleanse`] refuses every other scan, and the viewer offers its switch only where this holds.
pub fn hounsfield_offset(modality: &Modality, values: &ScanValues) -> Result<f64, CleanseError> {
    match (modality, values.kind) {
        (Modality::Mr | Modality::Other(_), _) => Err(CleanseError::NotHounsfield),
        (_, ValueKind::Hounsfield { offset }) => Ok(offset),
        _ => Err(CleanseError::NotHounsfield),
    }
}
