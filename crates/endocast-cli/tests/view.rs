//! `endocast view` in a real window: under Xvfb (Mesa's software OpenGL) the application opens
//! the colon phantom, refines the view, grabs its own window and quits.

use crate::common::{endocast, fails_with};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// An X server of our own on a free display number; killed on drop.
struct Xvfb(Child, String);

impl Xvfb {
    fn start() -> Option<Self> {
        for n in 90..110 {
            if std::path::Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
                continue;
            }
            let display = format!(":{n}");
            let child = Command::new("Xvfb")
                .args([&display, "-screen", "0", "1400x900x24", "-nolisten", "tcp"])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .ok()?;
            let start = Instant::now();
            while start.elapsed() < Duration::from_secs(10) {
                if std::path::Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
                    return Some(Self(child, display));
                }
                std::thread::sleep(Duration::from_millis(50));
            }
            return None;
        }
        None
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn view_opens_a_window_under_xvfb_and_writes_its_screenshot() {
    let Some(x) = Xvfb::start() else {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI must install xvfb"
        );
        eprintln!("skipping: Xvfb is not installed");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("window.png");
    let mut child = Command::new(env!("CARGO_BIN_EXE_endocast"))
        .args(["view", "--phantom", "colon", "--size", "96", "--screenshot"])
        .arg(&png)
        .env("DISPLAY", &x.1)
        .env("LIBGL_ALWAYS_SOFTWARE", "1")
        .env("TMPDIR", dir.path())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(240) {
            let _ = child.kill();
            panic!("endocast view did not finish in 4 minutes");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let output = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(status.success(), "{stderr}");
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert!(
        info.width >= 800 && info.height >= 500,
        "{}×{}",
        info.width,
        info.height
    );
    // The endoscopic view in the middle shows the colon's pink wall, not a blank window.
    let channels = info.line_size / info.width as usize;
    let (w, h) = (info.width as usize, info.height as usize);
    let centre = |dx: usize| &pixels[((h / 2) * w + w / 2 + dx) * channels..][..3];
    let pinkish = (0..50)
        .filter(|&dx| centre(dx)[0] > centre(dx)[2] + 10)
        .count();
    assert!(pinkish > 10, "the view shows no wall: {:?}", centre(0));
}

#[test]
fn view_without_a_scan_or_with_a_bad_preset_fails_cleanly() {
    fails_with(&["view"], "give a scan");
    fails_with(&["view", "x.nii", "--preset", "gastroscopy"], "gastroscopy");
    let out = endocast(&["view", "--help"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("--screenshot"));
}
