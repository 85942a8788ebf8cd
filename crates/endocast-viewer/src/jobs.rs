//! Work off the UI thread: a [`Job`] runs on its own thread and the UI picks its result up by
//! polling, so the UI never waits; [`Derived`] keeps the newest result of a computation keyed
//! by its input (the slices for a camera, the overview for a lumen), one job at a time, the
//! newest key winning.

use std::sync::mpsc::{channel, Receiver, TryRecvError};
use std::sync::Arc;

/// Called from a job's thread when it has finished (e.g. to ask the UI to repaint).
pub type Notify = Arc<dyn Fn() + Send + Sync>;

/// What a poll of a job found.
#[derive(Debug)]
pub enum Polled<T> {
    /// Still running.
    Running,
    /// Finished with this result.
    Done(T),
    /// The job's thread died without a result (a bug, already reported by the panic).
    Lost,
}

/// A computation on its own thread.
#[derive(Debug)]
pub struct Job<T> {
    result: Receiver<T>,
}

impl<T: Send + 'static> Job<T> {
    /// Starts `work` on a thread named `name`; `notify` is called when it has finished.
    pub fn spawn(name: &str, notify: Notify, work: impl FnOnce() -> T + Send + 'static) -> Self {
        let (send, result) = channel();
        let spawned = std::thread::Builder::new()
            .name(format!("endocast-{name}"))
            .spawn(move || {
                let _ = send.send(work());
                notify();
            });
        // A thread that cannot start reads as a lost job: its sender is already dropped.
        drop(spawned);
        Self { result }
    }

    /// The result, once it is there (taken: a later poll says [`Polled::Lost`]).
    pub fn poll(&self) -> Polled<T> {
        match self.result.try_recv() {
            Ok(value) => Polled::Done(value),
            Err(TryRecvError::Empty) => Polled::Running,
            Err(TryRecvError::Disconnected) => Polled::Lost,
        }
    }

    /// Waits for the result (tests and benchmarks only: the UI polls).
    pub fn wait(self) -> Option<T> {
        self.result.recv().ok()
    }
}

/// The newest result of a computation of a key, recomputed off the UI thread when the key
/// changes. While a job runs, the last result stays shown; a key asked for meanwhile is
/// computed when it finishes (only the newest).
pub struct Derived<K, T> {
    shown: Option<(K, T)>,
    running: Option<(K, Job<T>)>,
}

impl<K, T> Default for Derived<K, T> {
    fn default() -> Self {
        Self {
            shown: None,
            running: None,
        }
    }
}

impl<K: PartialEq + Clone, T: Send + 'static> Derived<K, T> {
    /// Takes a finished job's result and, when nothing runs and the shown result is not of
    /// `key`, starts `start(key)`. Returns true when a new result has arrived.
    pub fn refresh(&mut self, key: &K, start: impl FnOnce(&K) -> Job<T>) -> bool {
        let mut arrived = false;
        if let Some((k, job)) = &self.running {
            match job.poll() {
                Polled::Running => return false,
                Polled::Done(value) => {
                    self.shown = Some((k.clone(), value));
                    arrived = true;
                }
                Polled::Lost => {}
            }
            self.running = None;
        }
        let current = self.shown.as_ref().is_some_and(|(k, _)| k == key);
        if !current {
            self.running = Some((key.clone(), start(key)));
        }
        arrived
    }

    /// The newest result and the key it is of.
    pub fn shown(&self) -> Option<&(K, T)> {
        self.shown.as_ref()
    }

    /// Whether a job is running.
    pub fn busy(&self) -> bool {
        self.running.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn quiet() -> Notify {
        Arc::new(|| {})
    }

    #[test]
    fn the_newest_key_wins_and_the_old_result_stays_meanwhile() {
        let mut squares: Derived<u64, u64> = Derived::default();
        let slow = |k: &u64| {
            let k = *k;
            Job::spawn("test", quiet(), move || {
                std::thread::sleep(Duration::from_millis(20));
                k * k
            })
        };
        assert!(!squares.refresh(&3, slow));
        assert!(squares.busy() && squares.shown().is_none());
        // Asked for 4 while 3 runs: 3 arrives first, then 4 is computed.
        let deadline = Instant::now() + Duration::from_secs(10);
        while squares.shown().is_none_or(|(k, _)| *k != 4) {
            assert!(Instant::now() < deadline, "never got 16");
            squares.refresh(&4, slow);
            std::thread::sleep(Duration::from_millis(2));
        }
        assert_eq!(squares.shown(), Some(&(4, 16)));
        assert!(!squares.busy());
    }
}
