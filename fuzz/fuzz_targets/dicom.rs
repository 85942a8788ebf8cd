//! The dicom reader on arbitrary bytes: `Ok` or a clean `Err`, never a panic or a runaway
//! allocation.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = endocast_fuzz::file_with("input.dcm", data);
    let _ = endocast_io::dicom::read(&path, &endocast_fuzz::options());
});
