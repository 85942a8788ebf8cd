//! `fly --frames`: a part of a flight, its frames numbered as in the whole flight and written
//! as PNGs into a folder, so that parts flown on several machines join (`endocast film`) into
//! the film the whole flight makes, frame for frame the same pixels.

use anyhow::{bail, Result};
use endocast_io::video::SinkKind;
use std::ops::Range;
use std::path::Path;

/// The frames asked for: `START:END` (from frame START to before END, counting from 0; END
/// past the flight's last frame stops there) or `K/N` (part K of N equal parts, from 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameRange {
    /// Frames `start..end`.
    Span(usize, usize),
    /// Part `k` of `n`.
    Part(usize, usize),
}

/// Parses `--frames`: `START:END` or `K/N`.
pub fn parse_frames(text: &str) -> Result<FrameRange, String> {
    let numbers = |a: &str, b: &str| -> Result<(usize, usize), String> {
        let number = |s: &str| {
            s.trim()
                .parse::<usize>()
                .map_err(|_| format!("{s:?} is not a frame number; give START:END or K/N"))
        };
        Ok((number(a)?, number(b)?))
    };
    if let Some((a, b)) = text.split_once(':') {
        let (start, end) = numbers(a, b)?;
        if start >= end {
            return Err(format!("{text}: END must be past START"));
        }
        Ok(FrameRange::Span(start, end))
    } else if let Some((a, b)) = text.split_once('/') {
        let (k, n) = numbers(a, b)?;
        if !(1..=n).contains(&k) {
            return Err(format!("{text}: part K of N needs 1 ≤ K ≤ N"));
        }
        Ok(FrameRange::Part(k, n))
    } else {
        Err(format!("{text:?}: give START:END or K/N"))
    }
}

impl FrameRange {
    /// The frames of a flight of `count` frames this range takes; an error when it takes none.
    pub fn of(self, count: usize) -> Result<Range<usize>> {
        let range = match self {
            Self::Span(start, end) => start..end.min(count),
            Self::Part(k, n) => count * (k - 1) / n..count * k / n,
        };
        if range.is_empty() {
            bail!("--frames {self}: no frame of the flight's {count} (frames 0 to {count} - 1)");
        }
        Ok(range)
    }
}

impl std::fmt::Display for FrameRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Span(start, end) => write!(f, "{start}:{end}"),
            Self::Part(k, n) => write!(f, "{k}/{n}"),
        }
    }
}

/// Refuses what a part of a flight cannot make: a single film (the parts are joined into one),
/// the coverage or a training-data set (both are the whole flight's).
pub fn check(output: &Path, coverage: bool, dataset: bool) -> Result<()> {
    if SinkKind::for_path(output)? != SinkKind::PngFolder {
        bail!(
            "--frames writes a folder of PNGs, not {}: join the parts with `endocast film`",
            output.display()
        );
    }
    if coverage || dataset {
        bail!("--frames flies a part of the flight: --coverage and --dataset need all of it");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_and_parts_cover_the_flight_once() {
        assert_eq!(parse_frames("3:7"), Ok(FrameRange::Span(3, 7)));
        assert_eq!(FrameRange::Span(3, 7).of(5).unwrap(), 3..5);
        assert!(FrameRange::Span(5, 7).of(5).is_err());
        let parts: Vec<_> = (1..=3)
            .map(|k| FrameRange::Part(k, 3).of(10).unwrap())
            .collect();
        assert_eq!(parts, [0..3, 3..6, 6..10]);
        assert!(FrameRange::Part(1, 3).of(2).is_err());
        for bad in ["7:3", "3:3", "0/2", "3/2", "a:4", "-1:4", "12", ""] {
            assert!(parse_frames(bad).is_err(), "{bad}");
        }
    }
}
