//! `--case FILE` of `render` and `fly`: a case's annotations drawn as decals on the views,
//! after checking that the case was made on the scan being rendered.

use anyhow::Result;
use clap::Args;
use endocast_core::annotate::{draw, Annotations, DrawOptions, ScanIdentity, SurfaceView};
use endocast_core::camera::Camera;
use endocast_core::views::Image;
use endocast_core::Volume;
use endocast_io::case::Case;
use glam::DVec3;
use std::path::PathBuf;

/// The case whose annotations are drawn.
#[derive(Args, Debug, Clone, Default)]
pub struct CaseArgs {
    /// Draws the annotations of this case file (from `endocast annotate` or `endocast view`)
    /// where the view sees the tissue they were put on. The case must be of this scan.
    #[arg(long, value_name = "FILE")]
    pub case: Option<PathBuf>,
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
