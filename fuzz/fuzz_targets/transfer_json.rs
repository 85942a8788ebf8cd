//! Transfer-function JSON files (`--tf FILE.json`).

#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = endocast_io::transfer_json::parse_transfer_json(Path::new("input.json"), text);
});
