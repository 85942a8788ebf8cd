//! What a scan's values mean: Hounsfield units (DICOM CT, or a file that stores HU + 1024 such
//! as the Stanford CThead), or arbitrary intensities (MRI, industrial CT) read from the
//! histogram: the boundary between background and object (Otsu), and for a brain the CSF and
//! tissue levels and which of them is dark (T1, FLAIR) or bright (T2).
//!
//! The presets ([`crate::presets`]) are written in tissue terms on a reference scale (HU for
//! CT; CSF and white-matter levels of a T1 for the ventricles); [`resolve`] turns one into the
//! values of a given scan, and [`default_settings`] gives the view without a preset.
//!
//! ```
//! use endocast_core::phantom::{Phantom, PhantomOptions};
//! use endocast_core::tissue::{ScanValues, ValueKind};
//!
//! let volume = Phantom::SphereShell.build(&PhantomOptions { size: 32, ..Default::default() });
//! let scan = ScanValues::measure(&volume);
//! assert_eq!(scan.kind, ValueKind::Hounsfield { offset: 0.0 });
//! ```

mod brain;
mod extent;
mod histogram;
mod resolve;

pub use brain::{central_box, central_structure, measure_csf, CsfContrast};
pub use extent::{object_extent, object_points, object_world_extent};
pub use resolve::{default_look, default_settings, resolve, Resolved};

use crate::{Modality, Volume};
use histogram::Histogram;
use std::fmt;

/// `scan = scale · reference + offset`: a value on a preset's reference scale in a scan's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearMap {
    /// Scan units per reference unit; negative where the order of tissues is reversed (CSF
    /// bright on T2 against dark on the T1 reference).
    pub scale: f64,
    /// The scan's value of reference 0.
    pub offset: f64,
}

impl LinearMap {
    /// The map that changes nothing.
    pub const IDENTITY: Self = Self {
        scale: 1.0,
        offset: 0.0,
    };

    /// The map taking reference values `from` to scan values `to` (two distinct points).
    pub fn through(from: (f64, f64), to: (f64, f64)) -> Self {
        let scale = (to.1 - to.0) / (from.1 - from.0);
        Self {
            scale,
            offset: to.0 - scale * from.0,
        }
    }

    /// The scan value of reference value `v`.
    pub fn apply(&self, v: f64) -> f64 {
        self.scale * v + self.offset
    }
}

/// The kind of values a scan holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ValueKind {
    /// Hounsfield units plus `offset`: 0 for CT with a known rescale, 1024 for files that store
    /// HU + 1024 (recognised from the air and soft-tissue peaks).
    Hounsfield {
        /// The stored value of 0 HU.
        offset: f64,
    },
    /// Arbitrary intensities: only the histogram says what is what.
    Intensity,
}

/// What the histogram of a scan says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanValues {
    /// HU or intensities.
    pub kind: ValueKind,
    /// Otsu's threshold over the whole volume: the boundary between background (air) and the
    /// object (body), physical units.
    pub object_threshold: f64,
    /// Median value below the threshold (background, air).
    pub background: f64,
    /// Median value above the threshold (the object: soft tissue and more).
    pub object: f64,
    /// Smallest and largest value.
    pub range: (f64, f64),
}

/// Air and soft tissue, HU: the two reference points of a scan read as intensities.
const AIR_HU: f64 = -1000.0;
const TISSUE_HU: f64 = 40.0;
/// The default view's wall, HU: halfway between air and soft tissue (Otsu gives −473…−510 HU on
/// the shared CT scans).
const DEFAULT_WALL_HU: f64 = -500.0;
/// The offset of files that store HU + 1024 (CThead, VTK's headsq).
const SHIFTED_HU_OFFSET: f64 = 1024.0;

impl ScanValues {
    /// Reads the histogram of `volume`: Otsu's background/object threshold, the two classes'
    /// medians, and whether the values are Hounsfield units: CT by its header, or a histogram
    /// with air near −1000 and soft tissue near 0 (HU), or air near 0 and soft tissue near 1024
    /// with bone above 1500 (HU + 1024, never for a volume that says it is MR).
    pub fn measure(volume: &Volume) -> Self {
        let h = Histogram::of(volume);
        let map = volume.value_map();
        let (lo, hi) = h.range().unwrap_or((0, 0));
        let t = h.otsu().unwrap_or(lo);
        let below = h.median(lo, t).unwrap_or(lo);
        let above = h.median(t.saturating_add(1).min(hi), hi).unwrap_or(hi);
        let [a, b] = [below, above].map(|s| map.physical(s));
        let range = {
            let (x, y) = (map.physical(lo), map.physical(hi));
            (x.min(y), x.max(y))
        };
        let mut scan = Self {
            kind: ValueKind::Intensity,
            object_threshold: map.physical(t) + 0.5 * map.scale(),
            background: a.min(b),
            object: a.max(b),
            range,
        };
        scan.kind = scan.recognise(volume.modality());
        scan
    }

    fn recognise(&self, modality: &Modality) -> ValueKind {
        let (min, max) = self.range;
        let hu = *modality == Modality::Ct
            || (min <= -900.0
                && self.background <= -700.0
                && (-300.0..=400.0).contains(&self.object));
        let shifted = *modality != Modality::Mr
            && min >= -100.0
            && max >= 1500.0
            && self.background < 300.0
            && (SHIFTED_HU_OFFSET - 100.0..=SHIFTED_HU_OFFSET + 200.0).contains(&self.object);
        match (hu, shifted) {
            (true, _) => ValueKind::Hounsfield { offset: 0.0 },
            (false, true) => ValueKind::Hounsfield {
                offset: SHIFTED_HU_OFFSET,
            },
            (false, false) => ValueKind::Intensity,
        }
    }

    /// The map from HU to this scan's values: a shift for HU scans; for intensities, the one
    /// that puts the default wall (−500 HU) on Otsu's threshold and stretches air-to-tissue over
    /// the background-to-object distance.
    pub fn from_hounsfield(&self) -> LinearMap {
        match self.kind {
            ValueKind::Hounsfield { offset } => LinearMap { scale: 1.0, offset },
            ValueKind::Intensity => {
                let spread = self.object - self.background;
                let scale = if spread > 0.0 {
                    spread / (TISSUE_HU - AIR_HU)
                } else {
                    1.0
                };
                LinearMap {
                    scale,
                    offset: self.object_threshold - scale * DEFAULT_WALL_HU,
                }
            }
        }
    }
}

impl fmt::Display for ScanValues {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.kind {
            ValueKind::Hounsfield { offset: 0.0 } => write!(f, "CT in HU"),
            ValueKind::Hounsfield { offset } => write!(f, "CT stored as HU + {offset}"),
            ValueKind::Intensity => write!(
                f,
                "intensities (background ≈ {}, object ≈ {}, boundary {})",
                short(self.background),
                short(self.object),
                short(self.object_threshold)
            ),
        }
    }
}

/// A value with as few decimals as it needs (at most one).
pub fn short(v: f64) -> String {
    if (v - v.round()).abs() < 0.05 {
        format!("{}", v.round())
    } else {
        format!("{v:.1}")
    }
}

#[cfg(test)]
mod tests;
