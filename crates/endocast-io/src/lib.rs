//! Readers and writers of endocast: every scan format becomes the one
//! [`Volume`](endocast_core::Volume), with its geometry in the LPS patient frame and its values
//! in physical units, or a [`ReadError`] that names the file and the problem.
//!
//! [`open`] picks the reader from the path (a directory or DICOM magic → DICOM series;
//! `.nii`/`.nii.gz` → NIfTI; `.nrrd`/`.nhdr` → NRRD; `.mha`/`.mhd` → MetaImage; a Zarr
//! folder → OME-Zarr; or raw when
//! [`OpenOptions::raw`] says how):
//!
//! ```no_run
//! use endocast_io::{open, OpenOptions};
//!
//! let loaded = open("../shared/data/brain-mri-t1/chris_t1.nii.gz".as_ref(), &OpenOptions::default())?;
//! println!("{:?} {}", loaded.volume.dims(), loaded.volume.geometry().orientation_code());
//! for warning in &loaded.warnings {
//!     eprintln!("warning: {warning}");
//! }
//! # Ok::<(), endocast_io::ReadError>(())
//! ```

pub mod atomic;
pub mod case;
mod compressed;
pub mod dataset;
mod detached;
pub mod dicom;
mod encode;
pub mod error;
mod escape;
mod guard;
pub mod image_out;
pub mod limits;
pub mod lit_sphere;
mod loaded;
pub mod markups;
pub mod mesh;
pub mod metaimage;
pub mod nifti;
pub mod nrrd;
mod open;
pub mod overlay_scene;
pub mod path_file;
mod progress;
pub mod raw;
pub mod review_json;
pub mod route_file;
pub mod samples;
mod text;
pub mod texture;
pub mod transfer_json;
pub mod video;
pub mod zarr;

pub use error::{ReadError, Result};
pub use escape::escape;
pub use image_out::{
    write_image_rgb8, write_jpeg_rgb8, write_npy_f32, write_png_rgb8, write_png_rgba8, ImageFormat,
};
pub use limits::{Limits, RenderKind};
pub use loaded::{Format, Loaded, OpenOptions, SeriesSummary, SourceInfo};
pub use open::{open, write};
pub use progress::{Progress, ReadProgress, ReadStep};
pub use samples::{ElementType, Endian, Rescale};
pub use transfer_json::{read_transfer_json, TfPoints};
