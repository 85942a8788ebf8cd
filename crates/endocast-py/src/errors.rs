//! Library errors as Python exceptions: one exception type, the library's message.

use pyo3::exceptions::PyValueError;
use pyo3::PyErr;
use std::error::Error;

pyo3::create_exception!(
    endocast,
    EndocastError,
    PyValueError,
    "An error from endocast (an unreadable scan, an invalid option, no lumen, ...); the \
     message is the library's, naming the file and the problem."
);

/// The exception for a library error: its message followed by those of its causes.
pub fn to_py<E: Error>(error: E) -> PyErr {
    let mut text = error.to_string();
    let mut cause = error.source();
    while let Some(c) = cause {
        let more = c.to_string();
        if !text.contains(&more) {
            text.push_str(": ");
            text.push_str(&more);
        }
        cause = c.source();
    }
    EndocastError::new_err(text)
}

/// The exception for a problem described in words.
pub fn error(text: impl Into<String>) -> PyErr {
    EndocastError::new_err(text.into())
}
