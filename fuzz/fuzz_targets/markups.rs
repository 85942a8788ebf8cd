//! 3D Slicer Markups (.mrk.json): the markups themselves and the route `fly` makes of them.

#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = Path::new("input.mrk.json");
    let _ = endocast_io::markups::parse_markups(file, text);
    if let Ok(route) = endocast_io::route_file::parse_route(file, text) {
        let _ = route.shots(1.0, 10.0);
    }
});
