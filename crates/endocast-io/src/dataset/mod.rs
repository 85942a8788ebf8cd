//! Training data from a flight (issue 37), written to a folder as docs/dataset-format.md
//! describes: per frame `images/NNNNN.png` (the frame), `depth/NNNNN.png` (16-bit, along the
//! ray), `depth_z/NNNNN.png` (16-bit, along the view axis), `normals/NNNNN.png` (camera frame,
//! `(n + 1) / 2`), `masks/NNNNN.png` (255 where the wall is seen); and for the whole flight
//! nerfstudio's `transforms.json` and COLMAP's text model in `colmap/`. The numbers come from
//! [`endocast_core::dataset`]; every front end writes through [`DatasetWriter`].

mod colmap;
mod transforms;

#[cfg(test)]
mod tests;

use crate::error::{ReadError, Result};
use crate::image_out::{write_png_gray16, write_png_gray8, write_png_rgb8, write_png_rgb8_data};
use endocast_core::camera::{Camera, Optics};
use endocast_core::dataset::{
    depth_scale_mm, depth_to_u16, DatasetError, Extrinsics, FrameLayers, Intrinsics,
};
use endocast_core::views::Image;
use endocast_core::Volume;
use glam::DVec3;
use std::path::{Path, PathBuf};

/// The per-frame folders, in the order the files are written.
const FOLDERS: [&str; 6] = ["images", "depth", "depth_z", "normals", "masks", "colmap"];

/// One written frame: its file stem and camera.
#[derive(Debug, Clone)]
struct FrameRecord {
    stem: String,
    intrinsics: Intrinsics,
    pose: Extrinsics,
}

/// Writes a dataset frame by frame; [`DatasetWriter::finish`] writes the cameras.
#[derive(Debug)]
pub struct DatasetWriter {
    folder: PathBuf,
    /// Millimetres per code of the 16-bit depth images.
    depth_scale_mm: f64,
    frames: Vec<FrameRecord>,
}

impl DatasetWriter {
    /// A dataset in `folder` — a new folder or an empty one, never one with files in it (a
    /// dataset is not written over another) — of frames of `volume` seen through `optics`
    /// (refused before anything is written when the formats have no model for them): depths
    /// up to twice the volume's diagonal are stored, in codes of [`depth_scale_mm`] of that
    /// range.
    pub fn create(folder: &Path, volume: &Volume, optics: &Optics) -> Result<Self> {
        let probe = optics.camera(DVec3::ZERO, DVec3::X, DVec3::Z, [1, 1]);
        if let Ok(camera) = probe {
            Intrinsics::of(&camera).map_err(|e| unsupported(folder, &e))?;
        }
        check_folder(folder)?;
        for name in FOLDERS {
            let path = folder.join(name);
            std::fs::create_dir_all(&path).map_err(|e| ReadError::io(&path, e))?;
        }
        let (lo, hi) = volume.geometry().world_bounds();
        Ok(Self {
            folder: folder.to_path_buf(),
            depth_scale_mm: depth_scale_mm(2.0 * (hi - lo).length()),
            frames: Vec::new(),
        })
    }

    /// Millimetres per code of the 16-bit depth images.
    pub fn depth_scale_mm(&self) -> f64 {
        self.depth_scale_mm
    }

    /// Writes the next frame: `image` as `camera` saw `volume`, with `depth_mm` along each ray
    /// (NaN where no wall). Refused, before anything is written, for a camera the formats have
    /// no model for.
    pub fn push(
        &mut self,
        image: &Image,
        camera: &Camera,
        depth_mm: &[f32],
        volume: &Volume,
    ) -> Result<()> {
        let intrinsics = Intrinsics::of(camera).map_err(|e| unsupported(&self.folder, &e))?;
        let pose = Extrinsics::of(camera).map_err(|e| unsupported(&self.folder, &e))?;
        let [w, h] = camera.size();
        if [image.width(), image.height()] != [w, h] || depth_mm.len() != w * h {
            return Err(ReadError::inconsistent(
                &self.folder,
                format!("a frame of {w}×{h} pixels came with another image or depth size"),
            ));
        }
        let stem = format!("{:05}", self.frames.len());
        let file = |folder: &str| self.folder.join(folder).join(format!("{stem}.png"));
        let layers = FrameLayers::new(camera, depth_mm, volume);
        let (w, h) = (w as u32, h as u32);
        let scale = self.depth_scale_mm;
        write_png_rgb8(&file("images"), w, h, image.rgb())?;
        write_png_gray16(
            &file("depth"),
            w,
            h,
            &depth_to_u16(&layers.depth_ray_mm, scale),
        )?;
        write_png_gray16(
            &file("depth_z"),
            w,
            h,
            &depth_to_u16(&layers.depth_z_mm, scale),
        )?;
        write_png_rgb8_data(&file("normals"), w, h, &layers.normals_rgb8())?;
        write_png_gray8(&file("masks"), w, h, &layers.mask())?;
        self.frames.push(FrameRecord {
            stem,
            intrinsics,
            pose,
        });
        Ok(())
    }

    /// Writes `transforms.json` and `colmap/` for the frames written; returns the folder.
    pub fn finish(self) -> Result<PathBuf> {
        let json = transforms::to_json(&self.frames, self.depth_scale_mm);
        let path = self.folder.join("transforms.json");
        crate::atomic::write_file(&path, |w| w.write_all(json.as_bytes()))?;
        colmap::write(&self.folder.join("colmap"), &self.frames)?;
        Ok(self.folder)
    }
}

/// A camera the formats cannot take, as an error about `folder`.
fn unsupported(folder: &Path, error: &DatasetError) -> ReadError {
    ReadError::unsupported(folder, error.to_string())
}

/// Fails unless `folder` is a folder with nothing in it, or nothing at all yet.
fn check_folder(folder: &Path) -> Result<()> {
    match std::fs::read_dir(folder) {
        Ok(mut entries) => match entries.next() {
            None => Ok(()),
            Some(_) => Err(ReadError::unsupported(
                folder,
                "dataset folder with files in it: give a new or empty folder (a dataset is \
                 never written over another)",
            )),
        },
        Err(_) if folder.exists() => Err(ReadError::unsupported(
            folder,
            "dataset folder that is a file: give a new or empty folder",
        )),
        Err(_) => Ok(()),
    }
}
