//! The raw reader on arbitrary bytes: the first 12 bytes choose the layout (dimensions, spacing,
//! sample type, byte order, header bytes) and an orientation code, the rest is the file.

#![no_main]

use endocast_io::raw::RawSpec;
use endocast_io::{ElementType, Endian};
use libfuzzer_sys::fuzz_target;

const TYPES: [&str; 10] = [
    "u8", "i8", "u16", "i16", "u32", "i32", "u64", "i64", "f32", "f64",
];
const ORIENTATIONS: [&str; 6] = ["", "LPS", "RAS", "LPI", "XYZ", "LLS"];

fuzz_target!(|data: &[u8]| {
    let Some((layout, file)) = data.split_first_chunk::<12>() else {
        return;
    };
    let spec = RawSpec {
        dims: [layout[0], layout[1], layout[2]].map(|d| usize::from(d % 64)),
        spacing_mm: [layout[3], layout[4], layout[5]].map(|s| f64::from(s) / 16.0),
        element: ElementType::from_name(TYPES[usize::from(layout[6]) % TYPES.len()])
            .expect("a known type"),
        endian: if layout[7] % 2 == 0 {
            Endian::Little
        } else {
            Endian::Big
        },
        header_bytes: u64::from(u16::from_le_bytes([layout[8], layout[9]])),
    };
    let orientation = ORIENTATIONS[usize::from(layout[10]) % ORIENTATIONS.len()];
    let mut options = endocast_fuzz::options();
    options.raw = Some(spec);
    options.orientation = (!orientation.is_empty()).then(|| orientation.to_owned());
    let path = endocast_fuzz::file_with("input.raw", file);
    let _ = endocast_io::raw::read(&path, &options);
});
