//! Integration tests of the readers and writers, one module per topic, one test binary.

mod common;
mod dicom;
