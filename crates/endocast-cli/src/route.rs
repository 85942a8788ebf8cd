//! Reading a route for `fly` and `bench`: our path JSON (points or key frames) or a 3D Slicer
//! Markups curve or point list.

use anyhow::{bail, Context, Result};
use endocast_core::animation::Animation;
use endocast_core::flight::Route;
use endocast_core::path::Path as SmoothPath;
use std::path::Path;

/// Sample step of the spline through a route file's points, mm (frames are taken from it at
/// any spacing).
const ROUTE_STEP_MM: f64 = 0.5;

/// Whether `file` is named as 3D Slicer Markups (`.mrk.json`, any case).
pub fn is_markups(file: &Path) -> bool {
    file.to_str()
        .is_some_and(|s| s.to_ascii_lowercase().ends_with(".mrk.json"))
}

/// The route in `file`: key frames when it has them, else its points (passed through exactly).
pub fn read_route(file: &Path) -> Result<Route> {
    let points = if is_markups(file) {
        let markups = endocast_io::markups::read_markups(file).context("cannot read the path")?;
        let Some(first) = markups.into_iter().find(|m| m.points_mm.len() >= 2) else {
            bail!(
                "{}: no curve or point list with two or more points",
                file.display()
            );
        };
        first.points_mm
    } else {
        let document =
            endocast_io::path_file::read_path_json(file).context("cannot read the path")?;
        if !document.key_frames.is_empty() {
            let animation = Animation::new(document.key_frames)
                .with_context(|| format!("{}: unusable key frames", file.display()))?;
            return Ok(Route::Keys(animation));
        }
        document.points_mm
    };
    let path = SmoothPath::from_points_exact(&points, ROUTE_STEP_MM)
        .with_context(|| format!("{}: unusable path", file.display()))?;
    Ok(Route::Path(path))
}
