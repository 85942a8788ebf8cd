//! Integration tests of the readers and writers, one module per topic, one test binary.

#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod analyze;
mod case;
mod corruption;
mod cross_format;
mod dicom;
mod dicom_bytes;
mod dicom_peers;
mod hostile;
mod image_out;
mod mesh;
mod metaimage;
mod mp4;
mod nifti;
mod nrrd;
mod overlay;
mod peel_real_scans;
mod scans_understood;
mod series;
mod stereo_real_scans;
mod structures_found;
mod test_volumes;
mod transfer_json;
mod video;
mod zarr;
