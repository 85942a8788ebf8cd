//! The training data of `endocast fly --dataset FOLDER`: each frame of the flight with its
//! depth, normals, mask and camera, written by [`endocast_io::dataset::DatasetWriter`]
//! (docs/dataset-format.md).

use anyhow::{bail, Context, Result};
use endocast_core::camera::Optics;
use endocast_core::flight::Flight;
use endocast_core::render::Renderer;
use endocast_core::views::Image;
use endocast_io::dataset::DatasetWriter;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where a flight's training data goes, and the volume it shows.
pub struct DatasetSink {
    writer: DatasetWriter,
    renderer: Arc<Renderer>,
}

/// Refuses `--dataset` with what it cannot take: a stereo flight (no one camera per frame) and
/// the dashboard (the frame is not the camera's image).
pub fn check(stereo: bool, dashboard: bool) -> Result<()> {
    if stereo {
        bail!("--dataset takes a flight without --stereo (one camera per frame)");
    }
    if dashboard {
        bail!("--dataset needs --layout endoscope (a dashboard frame is not the camera's image)");
    }
    Ok(())
}

impl DatasetSink {
    /// A new dataset in `folder` (new or empty) of frames of `renderer`'s volume seen through
    /// `optics`.
    pub fn create(folder: &Path, renderer: &Arc<Renderer>, optics: &Optics) -> Result<Self> {
        let writer = DatasetWriter::create(folder, renderer.volume(), optics)
            .context("cannot write the --dataset")?;
        Ok(Self {
            writer,
            renderer: Arc::clone(renderer),
        })
    }

    /// Writes `image`, the frame `flight` rendered last, with its depth and camera.
    pub fn push(&mut self, flight: &Flight, image: &Image) -> Result<()> {
        let (camera, depth) = flight.last_view().context("no frame rendered yet")?;
        self.writer
            .push(image, &camera, depth, self.renderer.volume())
            .context("cannot write the --dataset")
    }

    /// Writes the cameras (transforms.json, colmap/); returns the folder.
    pub fn finish(self) -> Result<PathBuf> {
        Ok(self.writer.finish()?)
    }
}
