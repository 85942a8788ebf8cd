//! End-to-end tests of the `endocast` binary, one module per topic, one test binary.

mod bad_input;
mod common;
mod info_shared_data;
mod phantom_convert;
