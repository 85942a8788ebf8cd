//! CSF against brain tissue, from a box at the centre of the head: the ventricles lie there,
//! and there CSF is the smaller of the two classes Otsu's threshold splits the box into, dark on
//! T1 and FLAIR, bright on T2.

use super::extent::object_extent;
use super::histogram::Histogram;
use super::ScanValues;
use crate::navigate::Central;
use crate::presets::{Preset, Structure};
use crate::Volume;

/// Half the central box's size, as a fraction of the object's extent along each axis (between
/// its 5th and 95th percentiles).
const BOX_HALF: f64 = 0.15;
/// The CSF class must be at most this fraction of the central box; otherwise the box holds no
/// clear minority and the contrast is not trusted.
const MAX_CSF_FRACTION: f64 = 0.45;

/// The CSF and tissue levels of a brain scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CsfContrast {
    /// Median of the CSF class, physical units.
    pub csf: f64,
    /// Median of the tissue class, physical units.
    pub tissue: f64,
    /// Otsu's threshold between them in the central box, physical units.
    pub threshold: f64,
    /// CSF is darker than tissue (T1, FLAIR); false: brighter (T2).
    pub dark: bool,
    /// Fraction of the central box that is CSF.
    pub csf_fraction: f64,
}

impl CsfContrast {
    /// `"T1-like, dark"` or `"T2-like, bright"`.
    pub fn weighting(&self) -> &'static str {
        if self.dark {
            "T1-like, dark"
        } else {
            "T2-like, bright"
        }
    }
}

/// The CSF/tissue contrast in the central box of the object of `volume` (see the module
/// documentation); `None` when the box has a single value or no class is a clear minority.
pub fn measure_csf(volume: &Volume, scan: &ScanValues) -> Option<CsfContrast> {
    let (lo, hi) = central_box(volume, scan)?;
    let h = Histogram::of_box(volume, lo, hi);
    let (min, max) = h.range()?;
    let t = h.otsu()?;
    let below = h.count(min, t) as f64 / h.total() as f64;
    let map = volume.value_map();
    let (low_class, high_class) = (h.median(min, t)?, h.median(t + 1, max)?);
    let (lo_value, hi_value) = (map.physical(low_class), map.physical(high_class));
    // Which class is physically darker (a negative value map swaps them).
    let (dark_value, bright_value, dark_fraction) = if lo_value <= hi_value {
        (lo_value, hi_value, below)
    } else {
        (hi_value, lo_value, 1.0 - below)
    };
    let dark = dark_fraction <= 0.5;
    let csf_fraction = dark_fraction.min(1.0 - dark_fraction);
    if csf_fraction > MAX_CSF_FRACTION {
        return None;
    }
    let (csf, tissue) = if dark {
        (dark_value, bright_value)
    } else {
        (bright_value, dark_value)
    };
    Some(CsfContrast {
        csf,
        tissue,
        threshold: map.physical(t) + 0.5 * map.scale(),
        dark,
        csf_fraction,
    })
}

/// The central structure `preset` (in the scan's units) means on `volume`: the box at the
/// object's centre, the CSF level and the background's (midway between the scan's lowest
/// value and its darker class); `None` for presets that mean the largest lumen, and for a
/// scan without a clear CSF/tissue contrast at its centre.
pub fn central_structure(preset: &Preset, volume: &Volume, scan: &ScanValues) -> Option<Central> {
    if preset.lumen?.structure != Structure::Central {
        return None;
    }
    let csf = measure_csf(volume, scan)?;
    Some(Central {
        region: central_box(volume, scan)?,
        floor: csf.csf,
        background: 0.5 * (scan.range.0 + csf.csf.min(csf.tissue)),
    })
}

/// The inclusive voxel box around the middle of the object (voxels above the background
/// threshold), [`BOX_HALF`] of its extent each way; `None` for a volume without object.
pub fn central_box(volume: &Volume, scan: &ScanValues) -> Option<([usize; 3], [usize; 3])> {
    let dims = volume.dims();
    let (p5, p95) = object_extent(volume, scan, 0.05)?;
    let mut lo = [0; 3];
    let mut hi = [0; 3];
    for a in 0..3 {
        let centre = 0.5 * (p5[a] + p95[a]) as f64;
        let half = (BOX_HALF * (p95[a] - p5[a]) as f64).max(2.0);
        lo[a] = (centre - half).max(0.0).round() as usize;
        hi[a] = ((centre + half).round() as usize).min(dims[a] - 1);
    }
    Some((lo, hi))
}
