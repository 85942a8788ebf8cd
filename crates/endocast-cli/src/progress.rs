//! A one-line progress bar on stderr with the rate and an estimate of the time left.

use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

/// Width of the bar, characters.
const BAR: usize = 30;
/// The line is redrawn at most this often.
const REDRAW: Duration = Duration::from_millis(200);

/// Progress through `total` steps of some work.
#[derive(Debug)]
pub struct Progress {
    label: String,
    total: usize,
    done: usize,
    start: Instant,
    drawn: Option<Instant>,
}

impl Progress {
    /// Starts counting `total` steps of the work called `label`.
    pub fn new(label: &str, total: usize) -> Self {
        Self {
            label: label.to_owned(),
            total: total.max(1),
            done: 0,
            start: Instant::now(),
            drawn: None,
        }
    }

    /// One more step done; redraws the line now and then on a terminal, and prints a line at
    /// every tenth of the work otherwise (logs stay short).
    pub fn step(&mut self) {
        self.done += 1;
        let last = self.done == self.total;
        if std::io::stderr().is_terminal() {
            if last || self.drawn.is_none_or(|t| t.elapsed() >= REDRAW) {
                self.draw(true);
            }
        } else if last || (10 * self.done / self.total) > (10 * (self.done - 1) / self.total) {
            self.draw(false);
        }
    }

    /// Ends the line on a terminal.
    pub fn finish(&self) {
        if std::io::stderr().is_terminal() {
            eprintln!();
        }
    }

    /// Steps per second so far.
    pub fn rate(&self) -> f64 {
        self.done as f64 / self.start.elapsed().as_secs_f64().max(1e-9)
    }

    /// Draws the line: over the last one on a terminal, else as a line of its own.
    fn draw(&mut self, terminal: bool) {
        self.drawn = Some(Instant::now());
        let filled = BAR * self.done.min(self.total) / self.total;
        let rate = self.rate();
        let left = (self.total.saturating_sub(self.done)) as f64 / rate.max(1e-9);
        let line = format!(
            "{} [{}{}] {}/{}  {:.1}/s  {} left",
            self.label,
            "#".repeat(filled),
            "-".repeat(BAR - filled),
            self.done,
            self.total,
            rate,
            clock(left)
        );
        if !terminal {
            eprintln!("{line}");
            return;
        }
        eprint!("\r{line} ");
        // A progress line that cannot be drawn is no reason to stop the work.
        let _ = std::io::stderr().flush();
    }
}

/// `m:ss` (or `h:mm:ss`) for a number of seconds.
fn clock(seconds: f64) -> String {
    let s = seconds.clamp(0.0, 360_000.0).round() as u64;
    if s >= 3600 {
        format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
    } else {
        format!("{}:{:02}", s / 60, s % 60)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clock_reads_like_a_clock() {
        assert_eq!(clock(0.4), "0:00");
        assert_eq!(clock(75.0), "1:15");
        assert_eq!(clock(3725.0), "1:02:05");
        assert_eq!(clock(f64::NAN), "0:00");
    }
}
