//! Integration tests of the readers and writers, one module per topic, one test binary.

mod common;
mod dicom;
mod metaimage;
mod nifti;
mod nrrd;
mod test_volumes;
