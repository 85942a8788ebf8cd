//! `--case FILE` of `render` and `fly`: a case's annotations drawn as decals on the views,
//! after checking that the case was made on the scan being rendered; and `--target X,Y,Z`, a
//! bronchoscopy target ringed in the views (`fly` takes its path file's target without it).

use crate::parse::parse_vec3;
use anyhow::{Context, Result};
use clap::Args;
use endocast_core::annotate::{
    draw, draw_target, Annotations, DrawOptions, ScanIdentity, SurfaceView,
};
use endocast_core::camera::Camera;
use endocast_core::views::Image;
use endocast_core::Volume;
use endocast_io::case::Case;
use glam::DVec3;
use std::path::{Path, PathBuf};

/// The case whose annotations are drawn.
#[derive(Args, Debug, Clone, Default)]
pub struct CaseArgs {
    /// Draws the annotations of this case file (from `endocast annotate` or `endocast view`)
    /// where the view sees the tissue they were put on. The case must be of this scan.
    #[arg(long, value_name = "FILE")]
    pub case: Option<PathBuf>,
    /// A target to draw in the endoscope view, world mm (LPS; e.g. the nodule of `endocast
    /// path --preset bronchoscopy --target`): a solid ring where the view sees it, a dashed,
    /// dimmer one where it lies behind the wall the view shows, with its distance from the
    /// eye. `fly` draws its --path file's "target" without it.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub target: Option<[f64; 3]>,
}

impl CaseArgs {
    /// The case's annotations, after checking it was made on `volume`; `None` without
    /// `--case`.
    pub fn annotations(&self, volume: &Volume) -> Result<Option<Annotations>> {
        let Some(path) = &self.case else {
            return Ok(None);
        };
        let case = Case::read(path)?;
        case.check_scan(&ScanIdentity::of(volume), path)?;
        Ok(Some(case.annotations(path)?))
    }

    /// The target to draw: `--target`, else the one the path file `route` names (if any).
    pub fn target(&self, route: Option<&Path>) -> Result<Option<DVec3>> {
        if let Some(target) = self.target {
            return Ok(Some(DVec3::from(target)));
        }
        let Some(route) = route else {
            return Ok(None);
        };
        endocast_io::route_file::read_target(route).context("cannot read the path's target")
    }
}

/// Draws `marks` into `image`, the picture of `camera` with `depth_mm`, where the view sees
/// their tissue (a scan of `spacing_mm` voxels).
pub fn draw_marks(
    image: &mut Image,
    marks: &Annotations,
    camera: &Camera,
    depth_mm: &[f32],
    spacing_mm: DVec3,
) {
    let view = SurfaceView::new(camera, depth_mm, spacing_mm);
    draw(image, &view, marks.items(), &DrawOptions::default());
}

/// Rings `target_mm` in `image`, the picture of `camera` with `depth_mm` (see
/// [`draw_target`]).
pub fn draw_target_mark(
    image: &mut Image,
    target_mm: DVec3,
    camera: &Camera,
    depth_mm: &[f32],
    spacing_mm: DVec3,
) {
    let view = SurfaceView::new(camera, depth_mm, spacing_mm);
    draw_target(image, &view, target_mm);
}
