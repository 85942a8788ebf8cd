//! The mesh readers (STL binary and ASCII, OBJ, PLY) on arbitrary bytes: `Ok` or a clean
//! `Err`, never a panic or a runaway allocation. The first byte picks the file's extension.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&kind, bytes)) = data.split_first() else {
        return;
    };
    let name = ["input.stl", "input.obj", "input.ply"][usize::from(kind % 3)];
    let path = endocast_fuzz::file_with(name, bytes);
    let _ = endocast_io::mesh::read_mesh(&path);
});
