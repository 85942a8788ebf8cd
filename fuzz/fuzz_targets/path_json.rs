//! Path files (docs/path-format.md) and every route they can give: the path document, the route
//! of points or key frames `fly` samples, and the camera path.

#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let file = Path::new("input.json");
    let _ = endocast_io::path_file::parse_path_json(file, text);
    let _ = endocast_io::route_file::parse_camera_path(file, text);
    if let Ok(route) = endocast_io::route_file::parse_route(file, text) {
        let _ = route.shots(1.0, 10.0);
    }
});
