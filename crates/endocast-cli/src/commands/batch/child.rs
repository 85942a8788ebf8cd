//! A step of a study run as a child process of this program, its output collected, and killed
//! when it runs past the study's deadline (`--timeout`).

use anyhow::{bail, Context, Result};
use serde_json::Value;
use std::io::Read;
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How often a step with a deadline is looked at: the most a timed-out step runs over it.
const POLL: Duration = Duration::from_millis(20);

/// When a study must have ended, and the `--timeout` that set it (for the message).
#[derive(Debug, Clone, Copy)]
pub struct Deadline {
    /// The instant the study's time runs out.
    pub at: Instant,
    /// The study's time, as `--timeout` gave it.
    pub timeout: Duration,
}

/// Runs `program args…` as step `command`; its JSON output (or `null` when it prints none), or
/// its error message. Past `deadline` the child is killed (SIGKILL: a temporary file it was
/// writing is removed by the next write of the same output) and the step fails with
/// "timed out after N s".
pub fn run_step(
    program: &Path,
    command: &str,
    args: &[String],
    deadline: Option<Deadline>,
) -> Result<Value> {
    let mut child = Command::new(program)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("cannot run {}", program.display()))?;
    let stdout = drain(child.stdout.take());
    let stderr = drain(child.stderr.take());
    let status = wait(&mut child, deadline);
    let (stdout, stderr) = (joined(stdout), joined(stderr));
    let Some(status) = status? else {
        let seconds = deadline.map_or(0.0, |d| d.timeout.as_secs_f64());
        bail!("{command}: timed out after {seconds} s (--timeout)");
    };
    if !status.success() {
        let stderr = String::from_utf8_lossy(&stderr);
        let said = stderr
            .lines()
            .rev()
            .find_map(|line| line.strip_prefix("error: "))
            .map_or_else(|| last_lines(&stderr), str::to_owned);
        bail!("{command}: {said} ({status})");
    }
    let stdout = String::from_utf8_lossy(&stdout);
    Ok(serde_json::from_str(&stdout).unwrap_or(Value::Null))
}

/// Waits for `child` to end; `None` when it was killed at `deadline`.
fn wait(child: &mut Child, deadline: Option<Deadline>) -> Result<Option<ExitStatus>> {
    let Some(deadline) = deadline else {
        return Ok(Some(child.wait()?));
    };
    loop {
        if let Some(status) = child.try_wait()? {
            return Ok(Some(status));
        }
        if Instant::now() >= deadline.at {
            child.kill()?;
            child.wait()?;
            return Ok(None);
        }
        std::thread::sleep(POLL);
    }
}

/// Reads a child's pipe to its end on a thread of its own (a child that fills one pipe while
/// the other is read would block for ever).
fn drain(pipe: Option<impl Read + Send + 'static>) -> Option<JoinHandle<Vec<u8>>> {
    pipe.map(|mut pipe| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            // A read error ends the output there: what was read is kept.
            let _ = pipe.read_to_end(&mut bytes);
            bytes
        })
    })
}

/// What a [`drain`] thread read.
fn joined(reader: Option<JoinHandle<Vec<u8>>>) -> Vec<u8> {
    reader
        .and_then(|thread| thread.join().ok())
        .unwrap_or_default()
}

/// The last lines of a step's standard error (a panic's message and where), for a failure
/// that printed no `error:` line.
fn last_lines(stderr: &str) -> String {
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    let tail = &lines[lines.len().saturating_sub(3)..];
    if tail.is_empty() {
        "no message".to_owned()
    } else {
        tail.join(" / ")
    }
}
