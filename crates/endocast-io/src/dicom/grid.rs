//! The uniform grid a stack is stored on. Evenly spaced slices are the grid. Unevenly spaced
//! slices go onto a finer grid on which every real slice is a plane of its own, copied exactly
//! (at the nearest plane, the move stated); only the planes between real slices are
//! interpolated. A missing slice (a gap of a whole number of steps in an otherwise even stack)
//! is refused unless the caller asks to fill it, and then named in a warning.

use super::scan::ImageFile;
use super::stack::Stack;
use crate::error::{ReadError, Result};
use rayon::prelude::*;
use std::path::Path;

/// Largest relative deviation of a gap from the mean gap that still counts as even.
const UNEVEN_TOLERANCE: f64 = 0.01;
/// A slice within this share of a step of a plane lies on it; a gap within it of a whole
/// number of steps is that many steps.
const ON_PLANE: f64 = 0.05;
/// The grid never has more than this many times the real slices.
const MAX_RESAMPLE_FACTOR: usize = 4;
/// Steps tried for uneven slices: the smallest gap divided by 1, 2, ... up to this.
const MAX_SUBDIVISION: usize = 4;
/// How many slices a message names.
const EXAMPLES: usize = 5;

/// Where the real slices of a stack go on the volume's grid.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Grid {
    /// Planes of the volume.
    pub count: usize,
    /// Step between planes (mm).
    pub step_mm: f64,
    /// The plane of each real slice (increasing, the first 0 and the last `count - 1`), or
    /// `None` when the slices are the planes.
    pub planes: Option<Vec<usize>>,
}

/// The grid for `stack`: the slices themselves when evenly spaced; else a grid keeping every
/// real slice (warned). A missing slice is an error unless `fill_missing`.
pub(super) fn plan(
    root: &Path,
    stack: &Stack,
    files: &[ImageFile],
    fill_missing: bool,
    warnings: &mut Vec<String>,
) -> Result<Grid> {
    let offsets: Vec<f64> = stack.slices.iter().map(|s| s.offset_mm).collect();
    let gaps: Vec<f64> = offsets.windows(2).map(|w| w[1] - w[0]).collect();
    let mean = stack.spacing.z;
    if gaps
        .iter()
        .all(|g| (g - mean).abs() <= UNEVEN_TOLERANCE * mean)
    {
        return Ok(Grid {
            count: offsets.len(),
            step_mm: mean,
            planes: None,
        });
    }
    let names = Names { root, stack, files };
    if let Some(step) = missing_step(&gaps) {
        let grid = on_step(&offsets, step);
        let message = missing_slices(&names, &offsets, &grid);
        if !fill_missing {
            return Err(ReadError::inconsistent(
                root,
                format!(
                    "{message}; a file of the series may be absent or unreadable. To read it \
                     anyway, the gap filled by interpolation between its neighbours, pass \
                     --fill-missing-slices (OpenOptions::fill_missing_slices)"
                ),
            ));
        }
        warnings.push(format!(
            "{}: {message}; filled by linear interpolation between its neighbours, as asked \
             (--fill-missing-slices): those planes are synthesised, not measured",
            root.display()
        ));
        return Ok(grid);
    }
    let smallest = gaps.iter().copied().fold(f64::INFINITY, f64::min);
    let grid = finer_grid(&offsets, smallest);
    warnings.push(uneven_warning(&names, &offsets, &gaps, &grid));
    Ok(grid)
}

/// The step of a stack whose gaps are all one step but for a few (at most two, or a tenth of
/// them) of a whole number of steps, the grid keeping within [`MAX_RESAMPLE_FACTOR`] times the
/// slices: the mean of the one-step gaps. `None` otherwise.
fn missing_step(gaps: &[f64]) -> Option<f64> {
    let mut sorted = gaps.to_vec();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let steps: Vec<f64> = gaps.iter().map(|g| (g / median).round()).collect();
    let whole = gaps
        .iter()
        .zip(&steps)
        .all(|(g, &k)| k >= 1.0 && (g - k * median).abs() <= ON_PLANE * median);
    let skips = steps.iter().filter(|&&k| k > 1.0).count();
    let planes = steps.iter().sum::<f64>() + 1.0;
    let most = (MAX_RESAMPLE_FACTOR * (gaps.len() + 1)) as f64;
    if !whole || skips == 0 || skips > (gaps.len() / 10).max(2) || planes > most {
        return None;
    }
    let single: Vec<f64> = gaps
        .iter()
        .zip(&steps)
        .filter(|(_, &k)| k == 1.0)
        .map(|(g, _)| *g)
        .collect();
    Some(single.iter().sum::<f64>() / single.len() as f64)
}

/// The grid of planes about `step` apart spanning the stack, each slice on its nearest plane.
fn on_step(offsets: &[f64], step: f64) -> Grid {
    let span = offsets[offsets.len() - 1];
    let intervals = ((span / step).round() as usize).max(offsets.len() - 1);
    nearest_planes(offsets, intervals)
}

/// `intervals` equal steps over the stack, each slice on its nearest plane but never on the
/// plane of another (pushed to the next free one, leaving room for the slices after it).
fn nearest_planes(offsets: &[f64], intervals: usize) -> Grid {
    let last = offsets.len() - 1;
    let step = offsets[last] / intervals as f64;
    let mut planes: Vec<usize> = Vec::with_capacity(offsets.len());
    for (k, offset) in offsets.iter().enumerate() {
        let nearest = (offset / step).round() as usize;
        let lowest = planes.last().map_or(0, |p| p + 1);
        planes.push(nearest.max(lowest).min(intervals - (last - k)));
    }
    Grid {
        count: intervals + 1,
        step_mm: step,
        planes: Some(planes),
    }
}

/// For uneven slices: the coarsest grid (the smallest gap divided by 1, 2, ...) on which every
/// slice lies on a plane; failing that, the smallest gap, each slice on its nearest plane. At
/// most [`MAX_RESAMPLE_FACTOR`] times the slices.
fn finer_grid(offsets: &[f64], smallest: f64) -> Grid {
    let span = offsets[offsets.len() - 1];
    let most = MAX_RESAMPLE_FACTOR * offsets.len() - 1;
    for divisor in 1..=MAX_SUBDIVISION {
        let intervals = (span / (smallest / divisor as f64)).round() as usize;
        if intervals > most {
            break;
        }
        let step = span / intervals as f64;
        if offsets
            .iter()
            .all(|o| (o / step - (o / step).round()).abs() <= ON_PLANE)
        {
            return nearest_planes(offsets, intervals);
        }
    }
    // Planes no farther apart than the smallest gap, so that two slices never share one.
    let intervals = ((span / smallest - 1e-9).ceil() as usize).clamp(offsets.len() - 1, most);
    nearest_planes(offsets, intervals)
}

/// What messages need to name a slice.
struct Names<'a> {
    root: &'a Path,
    stack: &'a Stack,
    files: &'a [ImageFile],
}

impl Names<'_> {
    /// `slice 4 (1-004.dcm, 12.00 mm along the stack)`, counting from 1.
    fn slice(&self, k: usize, offsets: &[f64]) -> String {
        let slice = &self.stack.slices[k];
        let file = &self.files[slice.file];
        let name = file.path.strip_prefix(self.root).unwrap_or(&file.path);
        let frame = if file.frames.len() > 1 {
            format!(" frame {}", slice.frame + 1)
        } else {
            String::new()
        };
        format!(
            "slice {} ({}{frame}, {:.2} mm along the stack)",
            k + 1,
            name.display(),
            offsets[k]
        )
    }

    /// The patient position (mm) of the first pixel of a plane `along` mm along the stack.
    fn position(&self, along: f64) -> String {
        let p = self.stack.origin + along * self.stack.stack_direction;
        format!("({:.2}, {:.2}, {:.2})", p.x, p.y, p.z)
    }
}

/// `2 slices missing: between slice 3 (...) and slice 4 (...) a gap of 6.00 mm, 2 steps of
/// 3.00 mm (the missing plane at (0.00, 0.00, 6.00) mm)`.
fn missing_slices(names: &Names, offsets: &[f64], grid: &Grid) -> String {
    let planes = grid.planes.as_deref().unwrap_or_default();
    let mut missing = 0;
    let mut gaps: Vec<String> = Vec::new();
    for (k, pair) in planes.windows(2).enumerate() {
        let skipped = pair[1] - pair[0] - 1;
        if skipped == 0 {
            continue;
        }
        missing += skipped;
        let mut at: Vec<String> = (pair[0] + 1..pair[1])
            .take(EXAMPLES)
            .map(|p| names.position(p as f64 * grid.step_mm))
            .collect();
        if skipped > EXAMPLES {
            at.push("...".to_owned());
        }
        gaps.push(format!(
            "between {} and {} a gap of {:.2} mm, {} steps of {:.2} mm (missing at {} mm)",
            names.slice(k, offsets),
            names.slice(k + 1, offsets),
            offsets[k + 1] - offsets[k],
            skipped + 1,
            grid.step_mm,
            at.join(", ")
        ));
    }
    format!("{missing} slice(s) missing: {}", gaps.join("; "))
}

fn uneven_warning(names: &Names, offsets: &[f64], gaps: &[f64], grid: &Grid) -> String {
    let planes = grid.planes.as_deref().unwrap_or_default();
    let moves: Vec<f64> = planes
        .iter()
        .zip(offsets)
        .map(|(&p, o)| p as f64 * grid.step_mm - o)
        .collect();
    let largest = moves.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let moved: Vec<usize> = (0..moves.len())
        .filter(|&k| moves[k].abs() > ON_PLANE * grid.step_mm)
        .collect();
    let mut text = format!(
        "{}: uneven gaps between slices ({} mm); stored on {} planes {:.3} mm apart: each of \
         the {} real slices is kept exactly on its nearest plane (moved at most {largest:.3} mm) \
         and only the planes between them are interpolated linearly",
        names.root.display(),
        distinct_gaps(gaps),
        grid.count,
        grid.step_mm,
        offsets.len()
    );
    if !moved.is_empty() {
        let examples: Vec<String> = moved
            .iter()
            .take(EXAMPLES)
            .map(|&k| format!("{} by {:+.3} mm", names.slice(k, offsets), moves[k]))
            .collect();
        text.push_str(&format!(
            "; {} slice(s) moved by more than {:.0} % of a step (slices {}): {}{}",
            moved.len(),
            ON_PLANE * 100.0,
            ranges(&moved),
            examples.join(", "),
            if moved.len() > EXAMPLES { ", ..." } else { "" }
        ));
    }
    text
}

/// Slice numbers (from 1) of increasing indices `ks`, runs joined: `2-5, 9`.
fn ranges(ks: &[usize]) -> String {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for &k in ks {
        match runs.last_mut() {
            Some((_, end)) if *end + 1 == k => *end = k,
            _ => runs.push((k, k)),
        }
    }
    runs.iter()
        .map(|&(a, b)| match b - a {
            0 => format!("{}", a + 1),
            _ => format!("{}-{}", a + 1, b + 1),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The distinct gaps, to 0.01 mm, in order of first appearance: "1.14, 4.22, 7.38".
fn distinct_gaps(gaps: &[f64]) -> String {
    let mut seen: Vec<f64> = Vec::new();
    for gap in gaps {
        let rounded = (gap * 100.0).round() / 100.0;
        if !seen.contains(&rounded) {
            seen.push(rounded);
        }
    }
    seen.iter()
        .map(|g| format!("{g:.2}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Fills `output` (`count` planes of `slice_len` voxels) from `source` (the real slices in
/// stack order) as `planes` places them: a real slice's plane is an exact copy of it, a plane
/// between two real slices a linear blend of them by its distance in planes.
pub(super) fn resample(source: &[u16], slice_len: usize, planes: &[usize], output: &mut [u16]) {
    let last = planes.len() - 1;
    output
        .par_chunks_mut(slice_len)
        .enumerate()
        .for_each(|(plane, out)| {
            // The real slice at or before this plane, but never the last (it needs a successor).
            let below = planes.partition_point(|&p| p <= plane).clamp(1, last) - 1;
            let (p0, p1) = (planes[below], planes[below + 1]);
            let weight = (plane as f64 - p0 as f64) / (p1 - p0) as f64;
            let a = &source[below * slice_len..(below + 1) * slice_len];
            let b = &source[(below + 1) * slice_len..(below + 2) * slice_len];
            blend(a, b, weight.clamp(0.0, 1.0), out);
        });
}

fn blend(a: &[u16], b: &[u16], weight: f64, out: &mut [u16]) {
    if weight == 0.0 {
        out.copy_from_slice(a);
    } else if weight == 1.0 {
        out.copy_from_slice(b);
    } else {
        // Fixed point (16 fractional bits) keeps the loop on integers.
        let w = (weight * 65536.0).round() as u32;
        for ((o, &x), &y) in out.iter_mut().zip(a).zip(b) {
            let mixed = u32::from(x) * (65536 - w) + u32::from(y) * w;
            *o = ((mixed + 32768) >> 16) as u16;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn planes(grid: &Grid) -> Vec<usize> {
        grid.planes.clone().unwrap()
    }

    #[test]
    fn real_slices_are_copied_and_only_the_planes_between_blended() {
        // Three one-voxel slices on planes 0, 1 and 4 holding 0, 100 and 400.
        let mut output = [0u16; 5];
        resample(&[0, 100, 400], 1, &[0, 1, 4], &mut output);
        assert_eq!(output, [0, 100, 200, 300, 400]);
    }

    #[test]
    fn gaps_of_whole_half_steps_put_every_slice_on_a_plane() {
        // Gaps 1, 1.5, 1.5: a grid of 0.5 mm holds every slice exactly.
        let grid = finer_grid(&[0.0, 1.0, 2.5, 4.0], 1.0);
        assert_eq!((grid.count, grid.step_mm), (9, 0.5));
        assert_eq!(planes(&grid), [0, 2, 5, 8]);
    }

    #[test]
    fn other_gaps_put_each_slice_on_its_nearest_plane_of_its_own() {
        let grid = finer_grid(&[0.0, 1.0, 2.4, 3.4], 1.0);
        assert_eq!(grid.count, 5);
        assert_eq!(planes(&grid), [0, 1, 3, 4]);
        // A tiny gap would ask for too many planes: capped, slices still on planes of their own.
        let grid = finer_grid(&[0.0, 0.01, 4.0, 10.0], 0.01);
        assert_eq!(grid.count, 16);
        assert_eq!(planes(&grid), [0, 1, 6, 15]);
    }

    #[test]
    fn one_double_gap_is_a_missing_slice_but_two_spacings_are_not() {
        assert_eq!(missing_step(&[2.0, 2.0, 4.0, 2.0, 2.0]), Some(2.0));
        assert_eq!(
            on_step(&[0.0, 2.0, 4.0, 8.0], 2.0).planes,
            Some(vec![0, 1, 2, 4])
        );
        assert_eq!(missing_step(&[2.0, 2.0, 3.0, 2.0]), None);
        assert_eq!(
            missing_step(&[5.0, 5.0, 5.0, 2.5, 2.5, 2.5, 2.5, 2.5]),
            None
        );
        // A gap of a billion steps is no missing slice (nor a grid of a billion planes).
        assert_eq!(missing_step(&[1.0, 1.0, 1e9, 1.0, 1.0]), None);
    }

    #[test]
    fn slice_numbers_are_listed_as_runs() {
        assert_eq!(ranges(&[1, 2, 3, 4, 8, 10, 11]), "2-5, 9, 11-12");
    }

    #[test]
    fn distinct_gaps_are_listed_once() {
        assert_eq!(
            distinct_gaps(&[1.141, 4.22, 1.139, 7.38]),
            "1.14, 4.22, 7.38"
        );
    }
}
