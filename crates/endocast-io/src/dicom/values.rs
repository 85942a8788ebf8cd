//! One value map for the whole series: exact when every slice shares its rescale, otherwise
//! the physical range requantised onto 16 bits; padding voxels replaced by the lowest value.

use super::pixels::{FrameStats, SampleMap};
use crate::error::{ReadError, Result};
use crate::samples::Rescale;
use endocast_core::ValueMap;
use rayon::prelude::*;
use std::path::Path;

/// Turns the decoded voxels (`raw = stored + type_min`, slice `k` with `rescales[k]`) into
/// voxels under one [`ValueMap`], in place, and returns that map.
pub(super) fn unify(
    root: &Path,
    voxels: &mut [u16],
    slice_len: usize,
    rescales: &[Rescale],
    stats: &[FrameStats],
    map: &SampleMap,
    warnings: &mut Vec<String>,
) -> Result<ValueMap> {
    let first = rescales[0];
    let padding_count: usize = stats.iter().map(|s| s.padding).sum();
    if rescales.iter().all(|r| *r == first) {
        let value_map = ValueMap::new(first.slope, first.intercept + map.type_min() * first.slope)
            .map_err(|e| ReadError::format(root, e.to_string()))?;
        if let (Some(padding), true) = (map.padding(), padding_count > 0) {
            let (min, max) = stored_extremes(stats);
            // The lowest physical value: the smallest stored value unless the slope is negative.
            let lowest = if first.slope > 0.0 { min } else { max };
            replace_padding(voxels, padding, lowest);
            warn_padding(root, padding_count, value_map.physical(lowest), warnings);
        }
        return Ok(value_map);
    }
    requantize(
        root,
        voxels,
        slice_len,
        rescales,
        stats,
        map,
        padding_count,
        warnings,
    )
}

/// Slices with different rescales: map every voxel to its physical value and spread the
/// series' physical range over 16 bits (exact when every rescale is integral).
#[allow(clippy::too_many_arguments)]
fn requantize(
    root: &Path,
    voxels: &mut [u16],
    slice_len: usize,
    rescales: &[Rescale],
    stats: &[FrameStats],
    map: &SampleMap,
    padding_count: usize,
    warnings: &mut Vec<String>,
) -> Result<ValueMap> {
    let type_min = map.type_min();
    let physical =
        |stored: u16, r: &Rescale| (f64::from(stored) + type_min) * r.slope + r.intercept;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (r, s) in rescales.iter().zip(stats).filter(|(_, s)| s.has_values()) {
        let (a, b) = (physical(s.min, r), physical(s.max, r));
        lo = lo.min(a.min(b));
        hi = hi.max(a.max(b));
    }
    if lo > hi {
        // Every voxel is padding: nothing to measure, keep them all at zero.
        (lo, hi) = (0.0, 0.0);
    }
    let integral = rescales
        .iter()
        .all(|r| r.slope.fract() == 0.0 && r.intercept.fract() == 0.0);
    let value_map =
        ValueMap::fitting(lo, hi, integral).map_err(|e| ReadError::format(root, e.to_string()))?;
    let padding = map.padding();
    voxels
        .par_chunks_mut(slice_len)
        .zip(rescales)
        .for_each(|(slice, r)| {
            for v in slice.iter_mut() {
                let value = if Some(*v) == padding {
                    lo
                } else {
                    physical(*v, r)
                };
                *v = value_map.quantize(value);
            }
        });
    let (slopes, intercepts) = ranges(rescales);
    warnings.push(format!(
        "{}: RescaleSlope/RescaleIntercept differ between slices (slopes {slopes}, intercepts \
         {intercepts}); values were requantised onto one 16-bit scale (step {:.4})",
        root.display(),
        value_map.scale()
    ));
    if padding_count > 0 {
        warn_padding(root, padding_count, lo, warnings);
    }
    Ok(value_map)
}

/// Smallest and largest non-padding stored values over all slices.
fn stored_extremes(stats: &[FrameStats]) -> (u16, u16) {
    let min = stats.iter().map(|s| s.min).min().unwrap_or(0);
    let max = stats.iter().map(|s| s.max).max().unwrap_or(0);
    if min > max {
        (0, 0)
    } else {
        (min, max)
    }
}

fn replace_padding(voxels: &mut [u16], padding: u16, lowest: u16) {
    voxels.par_iter_mut().for_each(|v| {
        if *v == padding {
            *v = lowest;
        }
    });
}

fn warn_padding(root: &Path, count: usize, lowest: f64, warnings: &mut Vec<String>) {
    warnings.push(format!(
        "{}: {count} padding voxels (PixelPaddingValue, outside the scanned area) were set to \
         the lowest value of the series, {lowest}",
        root.display()
    ));
}

/// "a…b" ranges of the slopes and intercepts, for the warning.
fn ranges(rescales: &[Rescale]) -> (String, String) {
    let span = |values: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        format!("{lo}…{hi}")
    };
    (
        span(&mut rescales.iter().map(|r| r.slope)),
        span(&mut rescales.iter().map(|r| r.intercept)),
    )
}
