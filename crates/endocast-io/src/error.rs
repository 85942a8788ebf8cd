//! The one error type of every reader and writer: few broad kinds, each naming the file. The
//! message shows control characters from file names and file content escaped
//! ([`crate::escape()`]).

use crate::escape::escape;
use std::fmt::Display;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a scan could not be read or written. Every variant names the file it is about.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ReadError {
    /// The operating system refused (missing file, permission, disk full, ...).
    #[error("{}: {}", shown(.path), escaped(.cause))]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The underlying error (shown in this error's message, so not chained as a source).
        cause: std::io::Error,
    },
    /// The file is not what its format requires: what was expected and what was found.
    #[error("{}: {}", shown(.path), escaped(.message))]
    Format {
        /// The file.
        path: PathBuf,
        /// Expected versus found, in words.
        message: String,
    },
    /// A valid file using a feature we do not read (e.g. a DICOM transfer syntax or data type).
    #[error("{}: unsupported {}", shown(.path), escaped(.what))]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// The feature, named so a user can look it up.
        what: String,
    },
    /// The header asks for more than the configured resource limit.
    #[error("{}: {} needs {requested} but the limit is {limit}", shown(.path), escaped(.what))]
    Limit {
        /// The file.
        path: PathBuf,
        /// What was being sized (e.g. "voxels").
        what: String,
        /// How much the header asks for.
        requested: u64,
        /// The configured limit.
        limit: u64,
    },
    /// Parts of the input contradict each other (e.g. slices of different sizes in a series).
    #[error("{}: inconsistent input: {}", shown(.path), escaped(.message))]
    Inconsistent {
        /// The file or directory.
        path: PathBuf,
        /// What disagrees with what.
        message: String,
    },
}

impl ReadError {
    /// An I/O error about `path`.
    pub fn io(path: &Path, cause: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            cause,
        }
    }

    /// A format error about `path`.
    pub fn format(path: &Path, message: impl Into<String>) -> Self {
        Self::Format {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    /// An unsupported-feature error about `path`.
    pub fn unsupported(path: &Path, what: impl Into<String>) -> Self {
        Self::Unsupported {
            path: path.to_path_buf(),
            what: what.into(),
        }
    }

    /// An inconsistency error about `path`.
    pub fn inconsistent(path: &Path, message: impl Into<String>) -> Self {
        Self::Inconsistent {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    /// The file or directory the error is about.
    pub fn path(&self) -> &Path {
        match self {
            Self::Io { path, .. }
            | Self::Format { path, .. }
            | Self::Unsupported { path, .. }
            | Self::Limit { path, .. }
            | Self::Inconsistent { path, .. } => path,
        }
    }
}

fn shown(path: &Path) -> String {
    escape(&path.display().to_string())
}

fn escaped(text: &impl Display) -> String {
    escape(&text.to_string())
}

/// Result of reading or writing a scan.
pub type Result<T, E = ReadError> = std::result::Result<T, E>;
