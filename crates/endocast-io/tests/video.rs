//! Frame sinks: PNG folders, animated GIFs and MP4 through ffmpeg (the built-in MP4 encoder:
//! `mp4.rs`).

use endocast_core::views::Image;
use endocast_io::video::{open_sink, SinkKind, VideoOptions};
use std::path::Path;
use std::process::{Command, Stdio};

/// Frame `n` of a small test flight: a horizontal gradient whose red channel steps with `n`.
pub fn frame(n: usize, width: usize, height: usize) -> Vec<u8> {
    (0..width * height)
        .flat_map(|p| [(n * 40 % 256) as u8, (p % width * 255 / width) as u8, 90])
        .collect()
}

/// Files in `dir`, sorted.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn kinds_follow_the_path() {
    let kind = |p: &str| SinkKind::for_path(Path::new(p));
    assert_eq!(kind("a/flight.gif").unwrap(), SinkKind::Gif);
    assert_eq!(kind("FLIGHT.MP4").unwrap(), SinkKind::Mp4);
    assert_eq!(kind("frames").unwrap(), SinkKind::PngFolder);
    assert_eq!(kind("run.2").unwrap(), SinkKind::PngFolder);
    let err = kind("flight.avi").unwrap_err().to_string();
    assert!(err.contains(".gif") && err.contains("flight.avi"), "{err}");
    let mut bad = VideoOptions::default();
    bad.fps = f64::NAN;
    assert!(open_sink(Path::new("x.gif"), &bad).is_err());
}

#[test]
fn gif_round_trip_decodes_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flight.gif");
    let mut options = VideoOptions::default();
    options.fps = 20.0;
    let mut sink = open_sink(&path, &options).unwrap();
    let (w, h) = (40, 30);
    for n in 0..5 {
        sink.push(&frame(n, w, h), w, h).unwrap();
    }
    let image = Image::from_rgb(w, h, frame(5, w, h)).unwrap();
    sink.push_image(&image).unwrap();
    assert_eq!(sink.frames(), 6);
    assert!(
        !path.exists(),
        "written under a temporary name until finished"
    );
    assert_eq!(sink.finish().unwrap(), path);
    assert_eq!(listing(dir.path()), ["flight.gif"]);

    let mut decoder = gif::DecodeOptions::new();
    decoder.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = decoder
        .read_info(std::fs::File::open(&path).unwrap())
        .unwrap();
    assert_eq!((decoder.width(), decoder.height()), (40, 30));
    let mut count = 0;
    while let Some(f) = decoder.read_next_frame().unwrap() {
        assert_eq!((f.width, f.height, f.delay), (40, 30, 5));
        // Quantisation keeps the colours close: the red channel of pixel (20, 10).
        let i = 4 * (20 + 40 * 10);
        let red = i32::from(f.buffer[i]);
        assert!(
            (red - count * 40 % 256).abs() <= 8,
            "frame {count}: red {red}"
        );
        count += 1;
    }
    assert_eq!(count, 6);
}

#[test]
fn png_folder_holds_one_file_per_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    let mut sink = open_sink(&out, &VideoOptions::default()).unwrap();
    for n in 0..4 {
        sink.push(&frame(n, 8, 6), 8, 6).unwrap();
    }
    sink.finish().unwrap();
    let names = [
        "frame_00000.png",
        "frame_00001.png",
        "frame_00002.png",
        "frame_00003.png",
    ];
    assert_eq!(listing(&out), names);
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(out.join("frame_00002.png")).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut buf).unwrap();
    assert_eq!(buf, frame(2, 8, 6));
    // A shorter flight into the same folder leaves no frames of the old one behind; other
    // files stay.
    std::fs::write(out.join("notes.txt"), "keep").unwrap();
    let mut sink = open_sink(&out, &VideoOptions::default()).unwrap();
    for n in 0..2 {
        sink.push(&frame(n, 8, 6), 8, 6).unwrap();
    }
    sink.finish().unwrap();
    assert_eq!(
        listing(&out),
        ["frame_00000.png", "frame_00001.png", "notes.txt"]
    );
}

#[test]
fn bad_frames_are_refused_and_leave_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.gif");
    let mut sink = open_sink(&path, &VideoOptions::default()).unwrap();
    assert!(sink.push(&[0; 11], 2, 2).is_err());
    assert!(sink.push(&[], 0, 0).is_err());
    sink.push(&frame(0, 4, 4), 4, 4).unwrap();
    let err = sink.push(&frame(0, 4, 5), 4, 5).unwrap_err().to_string();
    assert!(err.contains("4×5") && err.contains("4×4"), "{err}");
    drop(sink); // unfinished: no file, no temporary
    assert!(listing(dir.path()).is_empty());
    let empty = open_sink(&path, &VideoOptions::default()).unwrap();
    assert!(empty
        .finish()
        .unwrap_err()
        .to_string()
        .contains("no frames"));
    assert!(listing(dir.path()).is_empty());
    let folder = open_sink(&dir.path().join("none"), &VideoOptions::default()).unwrap();
    assert!(folder.finish().is_err());
}

#[test]
fn mp4_through_a_missing_ffmpeg_says_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flight.mp4");
    let mut options = VideoOptions::default();
    options.ffmpeg = Some(dir.path().join("no-such-ffmpeg"));
    let err = open_sink(&path, &options).err().unwrap().to_string();
    assert!(
        err.contains("no-such-ffmpeg") && err.contains("built-in") && err.contains("flight.mp4"),
        "{err}"
    );
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn mp4_through_ffmpeg() {
    let found = Command::new("ffmpeg")
        .arg("-version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !found {
        eprintln!("skipped: ffmpeg is not on PATH");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flight.mp4");
    let mut options = VideoOptions::default();
    options.ffmpeg = Some("ffmpeg".into());
    let mut sink = open_sink(&path, &options).unwrap();
    // An odd size: padded to even for 4:2:0.
    for n in 0..12 {
        sink.push(&frame(n, 33, 25), 33, 25).unwrap();
    }
    sink.finish().unwrap();
    assert_eq!(listing(dir.path()), ["flight.mp4"]);
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[4..8], b"ftyp", "an MP4 starts with its ftyp box");
}

/// Writes an executable shell script standing in for ffmpeg: `-version` succeeds; otherwise it
/// runs `body` with the output file (the last argument) in `$out`.
#[cfg(unix)]
fn fake_ffmpeg(dir: &Path, body: &str) -> std::path::PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join("fake-ffmpeg");
    let script = format!(
        "#!/bin/sh\n[ \"$1\" = -version ] && exit 0\nfor a in \"$@\"; do out=$a; done\n{body}\n"
    );
    std::fs::write(&path, script).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

#[cfg(unix)]
#[test]
fn mp4_streams_frames_to_ffmpeg_and_renames_on_success() {
    let tools = tempfile::tempdir().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flight.mp4");
    let mut options = VideoOptions::default();
    // Records its arguments and the number of bytes it was fed.
    options.ffmpeg = Some(fake_ffmpeg(
        tools.path(),
        "echo \"$*\" > \"$out\"; wc -c >> \"$out\"",
    ));
    let mut sink = open_sink(&path, &options).unwrap();
    for n in 0..12 {
        sink.push(&frame(n, 33, 25), 33, 25).unwrap();
    }
    assert!(!path.exists());
    sink.finish().unwrap();
    assert_eq!(listing(dir.path()), ["flight.mp4"]);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("-s 33x25 -r 25 -i -"), "{text}");
    assert!(text.contains("-c:v libx264 -pix_fmt yuv420p"), "{text}");
    let fed: usize = text.lines().last().unwrap().trim().parse().unwrap();
    assert_eq!(fed, 12 * 33 * 25 * 3);
}

#[cfg(unix)]
#[test]
fn a_failing_ffmpeg_leaves_no_file_and_shows_its_message() {
    let tools = tempfile::tempdir().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flight.mp4");
    let mut options = VideoOptions::default();
    options.ffmpeg = Some(fake_ffmpeg(
        tools.path(),
        "cat > /dev/null; echo partial > \"$out\"; echo 'Unknown encoder libx264' >&2; exit 1",
    ));
    let mut sink = open_sink(&path, &options).unwrap();
    sink.push(&frame(0, 8, 8), 8, 8).unwrap();
    let err = sink.finish().unwrap_err().to_string();
    assert!(err.contains("Unknown encoder libx264"), "{err}");
    assert!(listing(dir.path()).is_empty());
    // Dropped before finishing: ffmpeg is stopped and its partial output removed.
    options.ffmpeg = Some(fake_ffmpeg(
        tools.path(),
        "echo partial > \"$out\"; cat > /dev/null",
    ));
    let mut sink = open_sink(&path, &options).unwrap();
    sink.push(&frame(0, 8, 8), 8, 8).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(100));
    drop(sink);
    assert!(listing(dir.path()).is_empty());
}
