//! A batch's progress as its studies end, and its summary: `summary.csv` and `summary.json`
//! (one record a study: scan, status, message, seconds, output folder and outputs).

use super::study::{Record, Status};
use anyhow::{Context, Result};
use std::path::Path;
use std::time::{Duration, Instant};

/// Counts the studies as they end and says how long the rest should take.
pub struct Progress {
    total: usize,
    workers: usize,
    ended: usize,
    /// Seconds of the studies that ran (not skipped).
    ran_seconds: Vec<f64>,
    start: Instant,
}

impl Progress {
    /// Progress over `total` studies run by `workers` at once.
    pub fn new(total: usize, workers: usize) -> Self {
        Self {
            total,
            workers,
            ended: 0,
            ran_seconds: Vec::new(),
            start: Instant::now(),
        }
    }

    /// Prints the line of a study that ended (on standard error).
    pub fn ended(&mut self, record: &Record) {
        self.ended += 1;
        if record.status != Status::Skipped {
            self.ran_seconds.push(record.seconds);
        }
        let status = match record.status {
            Status::Ok => "ok".to_owned(),
            Status::Skipped => "skipped (finished before)".to_owned(),
            Status::Failed => format!("FAILED: {}", record.message),
        };
        eprintln!(
            "[{}/{}] {} in {:.1} s: {status}{}",
            self.ended,
            self.total,
            record.scan,
            record.seconds,
            self.time_left()
        );
    }

    /// "; about N s left" from the mean time of the studies that ran, or nothing.
    fn time_left(&self) -> String {
        let left = self.total - self.ended;
        if left == 0 || self.ran_seconds.is_empty() {
            return String::new();
        }
        let mean = self.ran_seconds.iter().sum::<f64>() / self.ran_seconds.len() as f64;
        let seconds = mean * left as f64 / self.workers.min(left) as f64;
        format!(
            "; about {} left ({} s so far)",
            human(seconds),
            self.start.elapsed().as_secs()
        )
    }
}

/// Seconds as people read them.
fn human(seconds: f64) -> String {
    if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else {
        format!("{:.0} min", seconds / 60.0)
    }
}

/// Writes `out/summary.csv` and `out/summary.json` atomically.
pub fn write(out: &Path, records: &[Record]) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let json = serde_json::to_string_pretty(&serde_json::json!({ "studies": records }))?;
    let file = out.join("summary.json");
    endocast_io::atomic::write_file(&file, |w| w.write_all(json.as_bytes()))
        .with_context(|| format!("cannot write {}", file.display()))?;
    let csv = to_csv(records)?;
    let file = out.join("summary.csv");
    endocast_io::atomic::write_file(&file, |w| w.write_all(&csv))
        .with_context(|| format!("cannot write {}", file.display()))
}

/// The summary as CSV: scan, status, message, seconds, output, then the outputs as JSON.
fn to_csv(records: &[Record]) -> Result<Vec<u8>> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer.write_record(["scan", "status", "message", "seconds", "output", "outputs"])?;
    for r in records {
        let status = serde_json::to_value(r.status)?;
        writer.write_record([
            r.scan.as_str(),
            status.as_str().unwrap_or_default(),
            r.message.as_str(),
            &format!("{:.2}", r.seconds),
            r.output.as_str(),
            &serde_json::to_string(&r.outputs)?,
        ])?;
    }
    Ok(writer.into_inner()?)
}

/// Prints the summary: as JSON, or the counts and each failure and warning in words.
pub fn say(records: &[Record], took: Duration, json: bool) -> Result<()> {
    if json {
        let all = serde_json::json!({ "studies": records });
        println!("{}", serde_json::to_string_pretty(&all)?);
        return Ok(());
    }
    let count = |s| records.iter().filter(|r| r.status == s).count();
    println!(
        "{} studies in {:.1} s: {} ok, {} skipped, {} failed",
        records.len(),
        took.as_secs_f64(),
        count(Status::Ok),
        count(Status::Skipped),
        count(Status::Failed)
    );
    for r in records.iter().filter(|r| !r.message.is_empty()) {
        match r.status {
            Status::Failed => println!("  failed: {}: {}", r.scan, r.message),
            _ => println!("  {}: {}", r.scan, r.message),
        }
    }
    Ok(())
}
