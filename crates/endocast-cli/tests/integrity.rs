//! What the tool does with hostile sizes, names and signals: a frame too large for memory is a
//! clear error before anything is allocated (so are frame and thread counts beyond the limits),
//! an interrupted `fly` leaves no temporary file, a killed one leaves its folder of frames old
//! and whole, `-o x.jpg` writes a JPEG (other endings are refused), and no control character
//! from a file reaches the terminal.

use crate::common::{endocast, fails_with};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The 48³ straight tube and a path along its axis, in `dir`.
fn tube_and_path(dir: &Path) -> (String, String) {
    let tube = dir.join("tube.nii.gz").to_str().unwrap().to_owned();
    let path = dir.join("p.json").to_str().unwrap().to_owned();
    let runs = [
        vec!["phantom", "straight-tube", "--size", "48", "-o", &tube],
        vec![
            "path", &tube, "--iso", "-480", "--from", "0,0,-18", "--to", "0,0,18", "-o", &path,
        ],
    ];
    for args in runs {
        let out = endocast(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    (tube, path)
}

fn temporary_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".tmp"))
        .collect()
}

#[test]
fn a_huge_size_is_a_clear_error_before_reading_or_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let (tube, path) = tube_and_path(dir.path());
    let view = dir.path().join("v.png");
    let view = view.to_str().unwrap();
    fails_with(
        &["render", &tube, "--size", "100000x100000", "-o", view],
        "rendering a frame of 100000×100000 pixels",
    );
    // 16384² is a valid camera, but 28 bytes a pixel is more than this limit allows.
    fails_with(
        &[
            "render",
            "/no/scan.nii",
            "--size",
            "16384x16384",
            "--max-voxels",
            "1000",
            "-o",
            view,
        ],
        "too large",
    );
    let film = dir.path().join("f.gif");
    fails_with(
        &[
            "fly",
            &tube,
            "--path",
            &path,
            "--size",
            "100000x100000",
            "-o",
            film.to_str().unwrap(),
        ],
        "use a smaller --size",
    );
}

#[test]
fn sigterm_during_fly_removes_the_temporary_film() {
    let dir = tempfile::tempdir().unwrap();
    let (tube, path) = tube_and_path(dir.path());
    let film = dir.path().join("f.gif");
    // Thousands of frames: far longer than the test waits.
    let mut child = Command::new(env!("CARGO_BIN_EXE_endocast"))
        .args([
            "fly", &tube, "--path", &path, "--iso", "-480", "--size", "96x96",
        ])
        .args(["--frame-step", "0.01", "-o", film.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while temporary_files(dir.path()).is_empty() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no temporary film appeared"
        );
        assert!(child.try_wait().unwrap().is_none(), "fly ended early");
        std::thread::sleep(Duration::from_millis(20));
    }
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(128 + 15), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    assert_eq!(temporary_files(dir.path()), Vec::<String>::new());
    assert!(!film.exists());
}

#[test]
fn jpg_output_is_a_jpeg_and_unknown_endings_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (tube, path) = tube_and_path(dir.path());
    let jpg = dir.path().join("v.jpg");
    let out = endocast(&[
        "render",
        &tube,
        "--size",
        "64x48",
        "-o",
        jpg.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&jpg).unwrap();
    assert_eq!(&bytes[..3], &[0xFF, 0xD8, 0xFF]);
    let bmp = dir.path().join("v.bmp");
    fails_with(
        &[
            "render",
            &tube,
            "--size",
            "64x48",
            "-o",
            bmp.to_str().unwrap(),
        ],
        "image output .bmp: write .png or .jpg",
    );
    assert!(!bmp.exists());
    let film = dir.path().join("f.jpg");
    fails_with(
        &["fly", &tube, "--path", &path, "-o", film.to_str().unwrap()],
        "write .gif, .mp4, or a folder of PNGs",
    );
}

#[test]
fn header_text_reaches_the_terminal_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let nrrd = dir.path().join("evil.nrrd");
    let header = "NRRD0004\ntype: \u{1b}[2J\u{1b}[31mshort\u{7}\ndimension: 3\nsizes: 2 2 2\n\
                  encoding: raw\n\n";
    std::fs::write(&nrrd, header).unwrap();
    let out = endocast(&["info", nrrd.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("evil.nrrd"), "{stderr}");
    assert!(
        !stderr.contains('\u{1b}') && !stderr.contains('\u{7}'),
        "raw control characters: {stderr:?}"
    );
}

/// The frames of a folder written by `fly`: their count and the size of the first.
fn frames_in(folder: &Path) -> (usize, (u32, u32)) {
    let mut names: Vec<_> = std::fs::read_dir(folder)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert!(names.iter().all(|n| n.starts_with("frame_")), "{names:?}");
    let file = std::fs::File::open(folder.join(&names[0])).unwrap();
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    (names.len(), reader.info().size())
}

#[test]
fn a_kill_during_fly_into_a_folder_leaves_the_old_frames_whole() {
    let dir = tempfile::tempdir().unwrap();
    let (tube, path) = tube_and_path(dir.path());
    let folder = dir.path().join("frames");
    let f = folder.to_str().unwrap();
    let fly = ["fly", &tube, "--path", &path, "--iso", "-480", "-o", f];
    let out = endocast(&[&fly[..], &["--size", "40x32", "--frame-step", "6"]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let old = frames_in(&folder);
    assert_eq!(old.1, (40, 32));
    // Thousands of frames of another size, killed (no handler runs) once some are written.
    let mut child = Command::new(env!("CARGO_BIN_EXE_endocast"))
        .args(fly)
        .args(["--size", "48x48", "--frame-step", "0.01"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while written_frames(dir.path()) < old.0 + 2 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no frames appeared"
        );
        assert!(child.try_wait().unwrap().is_none(), "fly ended early");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(frames_in(&folder), old, "the old frames, whole and alone");
    // The next flight into the folder replaces them whole, and what the killed one left goes.
    let out = endocast(&[&fly[..], &["--size", "24x24", "--frame-step", "12"]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let new = frames_in(&folder);
    assert_eq!(new.1, (24, 24));
    assert!(new.0 < old.0, "{new:?} after {old:?}");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(
        names.len(),
        3,
        "the tube, the path and the frames: {names:?}"
    );
}

/// Frames written anywhere under `dir` (the target folder or a temporary one beside it).
fn written_frames(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .map(|p| std::fs::read_dir(p).map_or(0, Iterator::count))
        .sum()
}

#[test]
fn a_folder_holding_a_folder_is_not_replaced_by_frames() {
    let dir = tempfile::tempdir().unwrap();
    let (tube, path) = tube_and_path(dir.path());
    let folder = dir.path().join("work");
    std::fs::create_dir_all(folder.join("notes")).unwrap();
    let f = folder.to_str().unwrap();
    fails_with(
        &["fly", &tube, "--path", &path, "--size", "16x16", "-o", f],
        "holds notes besides frames and files",
    );
    assert!(folder.join("notes").is_dir());
}

#[test]
fn counts_beyond_the_limits_are_refused_before_anything_is_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let (tube, path) = tube_and_path(dir.path());
    let bench = ["bench", "--phantom-size", "32", "--size", "8x8"];
    fails_with(
        &[&bench[..], &["--frames", "1000000000"]].concat(),
        "--frames: the frame count needs 1000000000 but the limit is 100000",
    );
    let view = dir.path().join("v.png");
    let render = [
        "render",
        &tube,
        "--size",
        "8x8",
        "-o",
        view.to_str().unwrap(),
    ];
    fails_with(
        &[&render[..], &["--threads", "100000"]].concat(),
        "--threads: the worker threads (8 a core at most) needs 100000",
    );
    // 36 mm every nanometre.
    let film = dir.path().join("f.gif");
    fails_with(
        &[
            "fly",
            &tube,
            "--path",
            &path,
            "--size",
            "8x8",
            "--frame-step",
            "1e-9",
            "-o",
            film.to_str().unwrap(),
        ],
        "--frame-step: the frame count needs",
    );
}

#[test]
fn a_render_too_large_for_the_address_space_is_refused_not_aborted() {
    let dir = tempfile::tempdir().unwrap();
    let (tube, _) = tube_and_path(dir.path());
    let view = dir.path().join("v.png");
    // 4 GiB of address space: 14000² pixels take far more.
    let out = Command::new("prlimit")
        .args(["--as=4294967296", env!("CARGO_BIN_EXE_endocast")])
        .args([
            "render",
            &tube,
            "--size",
            "14000x14000",
            "-o",
            view.to_str().unwrap(),
        ])
        .output()
        .expect("prlimit (util-linux) runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("rendering a frame of 14000×14000 pixels"),
        "{stderr}"
    );
    assert!(!view.exists());
}
