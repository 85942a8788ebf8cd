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
    let colon = dir.path().join("colon.nii.gz");
    let scan = colon.to_str().unwrap();
    let made = endocast(&["phantom", "colon", "--size", "96", "-o", scan]);
    assert!(made.status.success());
    let mut child = Command::new(env!("CARGO_BIN_EXE_endocast"))
        .args([
            "view",
            scan,
            "--preset",
            "colonoscopy",
            "--json",
            "--screenshot",
        ])
        .arg(&png)
        .env("DISPLAY", &x.1)
        .env("LIBGL_ALWAYS_SOFTWARE", "1")
        .env("TMPDIR", dir.path())
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
    // --json: the session resolved the scan as `render --json` does, and its camera is there.
    let session: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let render = endocast(&[
        "render",
        scan,
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
    let decoder = png::Decoder::new(BufReader::new(std::fs::File::open(&png).unwrap()));
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
