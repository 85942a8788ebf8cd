//! `endocast view` in a real window: under Xvfb (Mesa's software OpenGL) the application opens
//! the colon phantom, refines the view, grabs its own window and quits.

use crate::common::{endocast, fails_with};
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// An X server of our own, stopped on drop.
struct Xvfb(Child, String);

impl Xvfb {
    /// Starts Xvfb on a display it picks itself (`-displayfd`: it skips displays whose lock or
    /// socket is taken, and writes the number it chose once it accepts connections). `None`
    /// when Xvfb is not installed; a server that is installed but does not come up is a
    /// failure that shows its own words.
    fn start() -> Option<Self> {
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1400x900x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .ok()?;
        let stdout = child.stdout.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut line = String::new();
            let _ = BufReader::new(stdout).read_line(&mut line);
            let _ = tx.send(line);
        });
        match rx.recv_timeout(Duration::from_secs(60)) {
            Ok(line) if !line.trim().is_empty() => Some(Self(child, format!(":{}", line.trim()))),
            _ => {
                let _ = child.kill();
                let out = child.wait_with_output().unwrap();
                panic!(
                    "Xvfb did not start: {}",
                    String::from_utf8_lossy(&out.stderr)
                );
            }
        }
    }
}

impl Drop for Xvfb {
    /// SIGTERM, so that the server removes its lock file and socket (a killed one leaves
    /// both behind, and the display numbers run out over many runs); SIGKILL if it lingers.
    fn drop(&mut self) {
        let _ = Command::new("kill").arg(self.0.id().to_string()).status();
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(5) {
            if let Ok(Some(_)) = self.0.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// An RGB(A) screenshot: width, height, bytes a pixel and the pixels.
struct Shot {
    width: usize,
    height: usize,
    channels: usize,
    pixels: Vec<u8>,
}

impl Shot {
    /// The pixel at `(x, y)`, red, green and blue.
    fn at(&self, x: usize, y: usize) -> &[u8] {
        &self.pixels[(y * self.width + x) * self.channels..][..3]
    }

    /// How many of the 50 pixels right of `(x, y)` are pinkish (red over blue by 10).
    fn pinkish_from(&self, x: usize, y: usize) -> usize {
        (0..50)
            .filter(|&dx| self.at(x + dx, y)[0] > self.at(x + dx, y)[2] + 10)
            .count()
    }
}

/// Runs `endocast view SCAN ARGS --screenshot` under Xvfb `x` (TMPDIR `dir`); returns its
/// standard output and the screenshot.
fn view_screenshot(x: &Xvfb, dir: &std::path::Path, scan: &str, args: &[&str]) -> (Vec<u8>, Shot) {
    let png = dir.join("window.png");
    let mut child = Command::new(env!("CARGO_BIN_EXE_endocast"))
        .args(["view", scan, "--preset", "colonoscopy"])
        .args(args)
        .arg("--screenshot")
        .arg(&png)
        .env("DISPLAY", &x.1)
        .env("LIBGL_ALWAYS_SOFTWARE", "1")
        .env("TMPDIR", dir)
        .stdout(Stdio::piped())
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
    let decoder = png::Decoder::new(BufReader::new(std::fs::File::open(&png).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    let (width, height) = (info.width as usize, info.height as usize);
    assert!(width >= 800 && height >= 500, "{width}×{height}");
    let shot = Shot {
        width,
        height,
        channels: info.line_size / width,
        pixels,
    };
    (output.stdout, shot)
}

/// Xvfb, or `None` (skipping, with a message) where it is not installed outside CI.
fn xvfb() -> Option<Xvfb> {
    let x = Xvfb::start();
    if x.is_none() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI must install xvfb"
        );
        eprintln!("skipping: Xvfb is not installed");
    }
    x
}

/// The colon phantom, 96 voxels, written in `dir`.
fn colon(dir: &std::path::Path) -> String {
    let colon = dir.join("colon.nii.gz");
    let scan = colon.to_str().unwrap().to_owned();
    let made = endocast(&["phantom", "colon", "--size", "96", "-o", &scan]);
    assert!(made.status.success());
    scan
}

#[test]
fn view_opens_a_window_under_xvfb_and_writes_its_screenshot() {
    let Some(x) = xvfb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scan = colon(dir.path());
    let (stdout, shot) = view_screenshot(&x, dir.path(), &scan, &["--json"]);
    // --json: the session resolved the scan as `render --json` does, and its camera is there.
    let session: serde_json::Value = serde_json::from_slice(&stdout).unwrap();
    let render = endocast(&[
        "render",
        &scan,
        "--preset",
        "colonoscopy",
        "--size",
        "16x16",
        "--json",
        "-o",
        dir.path().join("r.png").to_str().unwrap(),
    ]);
    let render: serde_json::Value = serde_json::from_slice(&render.stdout).unwrap();
    for key in ["preset", "iso", "lumen", "window", "structure", "start"] {
        assert_eq!(session["study"][key], render["study"][key], "{key}");
    }
    assert_eq!(session["camera"]["eye"], render["study"]["start"]["eye"]);
    // The endoscopic view in the middle shows the colon's pink wall, not a blank window.
    let (cx, cy) = (shot.width / 2, shot.height / 2);
    assert!(
        shot.pinkish_from(cx, cy) > 10,
        "the view shows no wall: {:?}",
        shot.at(cx, cy)
    );
}

#[test]
fn view_shows_a_large_slice_and_the_realistic_look_in_a_real_window() {
    let Some(x) = xvfb() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scan = colon(dir.path());
    // --layout axial: the endoscope on the left half of the middle, the slice on the right.
    let (_, shot) = view_screenshot(&x, dir.path(), &scan, &["--layout", "axial"]);
    let (left, right) = (290, shot.width - 250);
    let quarter = |k: usize| left + (right - left) * k / 4;
    let y = shot.height / 2;
    assert!(
        shot.pinkish_from(quarter(1) - 25, y) > 10,
        "no wall in the endoscope's half"
    );
    let greys = (quarter(2) + 10..right - 10)
        .filter(|&x| {
            let [r, g, b] = [0, 1, 2].map(|c| i32::from(shot.at(x, y)[c]));
            (r - g).abs() <= 2 && (g - b).abs() <= 2
        })
        .count();
    assert!(
        greys > (right - quarter(2)) / 3,
        "no grey slice on the right: {greys}"
    );
    // --look realistic: the endoscope's view shows the wall, and not as the plain look does.
    let (_, plain) = view_screenshot(&x, dir.path(), &scan, &["--look", "plain"]);
    let (_, real) = view_screenshot(&x, dir.path(), &scan, &["--look", "realistic"]);
    let (cx, cy) = (real.width / 2, real.height / 2);
    assert!(
        real.pinkish_from(cx, cy) > 10,
        "the look shows no wall: {:?}",
        real.at(cx, cy)
    );
    let mut differ = 0;
    for y in (cy - 100..cy + 100).step_by(4) {
        for x in (cx - 100..cx + 100).step_by(4) {
            let d: i32 = (0..3)
                .map(|c| (i32::from(real.at(x, y)[c]) - i32::from(plain.at(x, y)[c])).abs())
                .sum();
            differ += usize::from(d > 24);
        }
    }
    assert!(
        differ > 250,
        "the realistic look looks plain: {differ} of 2500 pixels differ"
    );
}

#[test]
fn view_without_a_scan_or_with_a_bad_preset_fails_cleanly() {
    fails_with(&["view"], "give a scan");
    fails_with(&["view", "x.nii", "--preset", "gastroscopy"], "gastroscopy");
    let out = endocast(&["view", "--help"]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("--screenshot"));
}
