//! The typed values of NRRD header fields (encoding, byte skip, space, data files, centring):
//! what the field parsers produce and the header holds, below both.

/// How the samples are stored in the data file(s).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Encoding {
    /// Bytes as they are in memory.
    Raw,
    /// gzip-compressed raw bytes.
    Gzip,
    /// Samples as decimal numbers separated by white space (or commas).
    Ascii,
    /// The raw bytes as pairs of hexadecimal digits, white space ignored.
    Hex,
}

impl Encoding {
    pub(super) fn name(self) -> &'static str {
        match self {
            Self::Raw => "raw",
            Self::Gzip => "gzip",
            Self::Ascii => "ascii",
            Self::Hex => "hex",
        }
    }
}

/// The `byte skip` field: a count, or −1 for "the data are the last bytes of the file".
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum ByteSkip {
    Bytes(u64),
    ToEnd,
}

/// The `space` field: the world frame that `space directions` and `space origin` are in.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Space {
    Lps,
    Ras,
    Las,
    /// `scanner-xyz`, `3D-right-handed`, `3D-left-handed` (or a bare `space dimension: 3`):
    /// a 3-D frame with no anatomical meaning; the name as the file spells it.
    NonAnatomical(String),
}

impl Space {
    pub(super) fn name(&self) -> &str {
        match self {
            Self::Lps => "left-posterior-superior",
            Self::Ras => "right-anterior-superior",
            Self::Las => "left-anterior-superior",
            Self::NonAnatomical(name) => name,
        }
    }
}

/// Where the samples are.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum DataFiles {
    /// In the header's own file, after the blank line.
    Attached,
    /// One file, named relative to the header's folder.
    Single(String),
    /// Several files, each holding a slab of `subdim` axes (default: all axes but the last).
    Many {
        names: Vec<String>,
        subdim: Option<usize>,
    },
}

/// Centring of samples on an axis, which decides where `axis mins` puts the first sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Center {
    Cell,
    Node,
}
