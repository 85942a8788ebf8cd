//! COLMAP's text model: `cameras.txt` (one camera per distinct intrinsics), `images.txt`
//! (world to camera, OpenCV convention, mm; no 2-D points) and an empty `points3D.txt`. Image
//! names are relative to the dataset's `images/` folder.

use super::FrameRecord;
use crate::atomic::write_file;
use crate::error::Result;
use endocast_core::dataset::Intrinsics;
use std::fmt::Write as _;
use std::path::Path;

/// Writes the three files into `folder`.
pub(super) fn write(folder: &Path, frames: &[FrameRecord]) -> Result<()> {
    let (cameras, ids) = cameras(frames);
    let mut text = String::from(
        "# Camera list with one line of data per camera:\n\
         #   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n",
    );
    let _ = writeln!(text, "# Number of cameras: {}", cameras.len());
    for (n, i) in cameras.iter().enumerate() {
        let [a, b, c, d] = i.distortion;
        let _ = writeln!(
            text,
            "{} {} {} {} {} {} {} {} {a} {b} {c} {d}",
            n + 1,
            i.model.name(),
            i.width,
            i.height,
            i.fx,
            i.fy,
            i.cx,
            i.cy
        );
    }
    save(&folder.join("cameras.txt"), &text)?;
    let mut text = String::from(
        "# Image list with two lines of data per image:\n\
         #   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n\
         #   POINTS2D[] as (X, Y, POINT3D_ID)\n",
    );
    let _ = writeln!(
        text,
        "# Number of images: {}, mean observations per image: 0",
        frames.len()
    );
    for (n, (frame, camera)) in frames.iter().zip(ids).enumerate() {
        let ([qw, qx, qy, qz], [tx, ty, tz]) = frame.pose.world_to_camera_opencv();
        let name = format!("{}.png", frame.stem);
        let _ = writeln!(
            text,
            "{} {qw} {qx} {qy} {qz} {tx} {ty} {tz} {camera} {name}\n",
            n + 1
        );
    }
    save(&folder.join("images.txt"), &text)?;
    let points = "# 3D point list with one line of data per point:\n\
                  #   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n\
                  # Number of points: 0, mean track length: 0\n";
    save(&folder.join("points3D.txt"), points)
}

/// The distinct intrinsics of `frames`, in order of first use, and each frame's camera id
/// (1-based).
fn cameras(frames: &[FrameRecord]) -> (Vec<Intrinsics>, Vec<usize>) {
    let mut cameras: Vec<Intrinsics> = Vec::new();
    let ids = frames
        .iter()
        .map(
            |frame| match cameras.iter().position(|c| *c == frame.intrinsics) {
                Some(n) => n + 1,
                None => {
                    cameras.push(frame.intrinsics);
                    cameras.len()
                }
            },
        )
        .collect();
    (cameras, ids)
}

fn save(path: &Path, text: &str) -> Result<()> {
    write_file(path, |w| w.write_all(text.as_bytes()))
}
