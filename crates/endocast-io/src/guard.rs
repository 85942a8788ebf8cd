//! Calls into dependencies' decoders that may panic on corrupt data (dicom-rs 0.10's RLE
//! decoder has been seen to index past its buffer): the panic is caught and becomes an error
//! about the file, and a panic hook, installed the first time, stays silent for it, so that the
//! user sees our error and nothing else.
//!
//! The hook is silent for panics on a thread inside [`quietly`], and on rayon's worker threads
//! while any such call is under way (decoders parallelise frames with rayon, and a worker's
//! panic is carried back to the caller); every other panic goes to the hook that was there
//! before.

use rayon::current_thread_index;
use std::cell::Cell;
use std::panic::{self, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Once;

thread_local! {
    /// How many [`quietly`] calls this thread is inside.
    static DEPTH: Cell<usize> = const { Cell::new(0) };
}

/// How many [`quietly`] calls are under way on any thread.
static ACTIVE: AtomicUsize = AtomicUsize::new(0);

/// Runs `decode`; a panic inside it becomes `Err` (silently).
pub(crate) fn quietly<T>(decode: impl FnOnce() -> T) -> Result<T, Panicked> {
    install_hook();
    DEPTH.with(|d| d.set(d.get() + 1));
    ACTIVE.fetch_add(1, Ordering::SeqCst);
    let result = panic::catch_unwind(AssertUnwindSafe(decode));
    ACTIVE.fetch_sub(1, Ordering::SeqCst);
    DEPTH.with(|d| d.set(d.get() - 1));
    result.map_err(|_| Panicked)
}

/// A dependency's decoder panicked (on corrupt data).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Panicked;

impl std::fmt::Display for Panicked {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the decoder failed on corrupt data")
    }
}

fn install_hook() {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        let previous = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            let inside = DEPTH.with(Cell::get) > 0;
            let helping = ACTIVE.load(Ordering::SeqCst) > 0 && current_thread_index().is_some();
            if !(inside || helping) {
                previous(info);
            }
        }));
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_an_error() {
        assert_eq!(quietly(|| 7), Ok(7));
        let v: Vec<u8> = Vec::new();
        let index = v.len() + 3;
        assert_eq!(quietly(|| v[index]), Err(Panicked));
        // Panics on rayon's workers inside the call are caught by the caller too.
        let sum = quietly(|| {
            rayon::join(|| 1, || -> i32 { panic!("worker") });
        });
        assert_eq!(sum, Err(Panicked));
    }
}
