//! Transfer-function JSON files: the benchmark's files (shared with the VTK peer) read back.

use endocast_io::read_transfer_json;
use std::path::PathBuf;

/// `bench/tf/NAME` in the workspace.
fn bench_tf(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../bench/tf")
        .join(name)
}

#[test]
fn bench_transfer_functions_read() {
    let ramp = read_transfer_json(&bench_tf("colon_ramp.json")).unwrap();
    assert_eq!(
        ramp.opacity,
        vec![(-1024.0, 0.0), (-700.0, 0.0), (-100.0, 0.6), (3071.0, 0.6)]
    );
    assert_eq!(ramp.color.len(), 5);
    assert_eq!(ramp.color[2], (-300.0, [0.93, 0.72, 0.62]));
    let complex = read_transfer_json(&bench_tf("colon_complex.json")).unwrap();
    assert_eq!(complex.opacity.len(), 13);
    assert_eq!(complex.opacity[2], (-520.0, 0.15));
    assert_eq!(complex.color.len(), 7);
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let e = read_transfer_json(&bench_tf("absent.json")).unwrap_err();
    assert!(matches!(e, endocast_io::ReadError::Io { .. }));
    assert!(e.to_string().contains("absent.json"), "{e}");
}
