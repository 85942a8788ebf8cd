//! How far a read has come, for a progress bar: the reader counts what it has done (the
//! DICOM reader: headers, then the files decoded), and another thread (the viewer's window)
//! looks at the counts while it runs.

use std::sync::atomic::{AtomicU8, AtomicUsize, Ordering};
use std::sync::Arc;

/// The steps of a read that report how far they are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReadStep {
    /// DICOM: reading the header of every file in the folder.
    Headers,
    /// DICOM: decoding the pixels of the chosen series, file by file.
    Pixels,
}

impl ReadStep {
    /// What the step does, for a status line ("headers", "pixels").
    pub fn name(self) -> &'static str {
        match self {
            Self::Headers => "headers",
            Self::Pixels => "pixels",
        }
    }
}

/// One look at a read's progress: `done` of `total` items of `step`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadProgress {
    /// The step under way.
    pub step: ReadStep,
    /// Items done (never more than `total`).
    pub done: usize,
    /// Items in this step.
    pub total: usize,
}

impl ReadProgress {
    /// The step's fraction done, 0–1.
    pub fn fraction(&self) -> f32 {
        if self.total == 0 {
            1.0
        } else {
            self.done as f32 / self.total as f32
        }
    }
}

/// Counts a read's progress; clones share the counts, so the caller keeps one and hands one
/// to the read (in [`crate::OpenOptions::progress`]). Formats read in one stream (NIfTI, NRRD,
/// MetaImage) say nothing: [`Progress::get`] stays `None`.
#[derive(Debug, Clone, Default)]
pub struct Progress(Arc<Counters>);

#[derive(Debug, Default)]
struct Counters {
    /// 0: nothing reported yet; else the [`ReadStep`]'s index + 1.
    step: AtomicU8,
    done: AtomicUsize,
    total: AtomicUsize,
}

const STEPS: [ReadStep; 2] = [ReadStep::Headers, ReadStep::Pixels];

impl Progress {
    /// How far the read is; `None` before it reported anything.
    pub fn get(&self) -> Option<ReadProgress> {
        let step = usize::from(self.0.step.load(Ordering::Acquire));
        let step = *STEPS.get(step.checked_sub(1)?)?;
        let total = self.0.total.load(Ordering::Acquire);
        let done = self.0.done.load(Ordering::Acquire).min(total);
        Some(ReadProgress { step, done, total })
    }

    /// Starts `step` of `total` items.
    pub(crate) fn begin(&self, step: ReadStep, total: usize) {
        let index = STEPS.iter().position(|s| *s == step).unwrap_or(0);
        self.0.done.store(0, Ordering::Release);
        self.0.total.store(total, Ordering::Release);
        self.0.step.store(index as u8 + 1, Ordering::Release);
    }

    /// One more item of the step done.
    pub(crate) fn advance(&self) {
        self.0.done.fetch_add(1, Ordering::AcqRel);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_counts_follow_the_steps_and_clones_share_them() {
        let progress = Progress::default();
        assert_eq!(progress.get(), None);
        let reader = progress.clone();
        reader.begin(ReadStep::Headers, 4);
        reader.advance();
        let seen = progress.get().unwrap();
        assert_eq!(
            (seen.step, seen.done, seen.total),
            (ReadStep::Headers, 1, 4)
        );
        assert!((seen.fraction() - 0.25).abs() < 1e-6);
        reader.begin(ReadStep::Pixels, 2);
        for _ in 0..3 {
            reader.advance();
        }
        let seen = progress.get().unwrap();
        assert_eq!((seen.step, seen.done, seen.total), (ReadStep::Pixels, 2, 2));
    }
}
