//! The options every command that reads a scan shares: series choice, limits, raw layout.

use crate::cleanse_args::CleanseArgs;
use crate::parse::{parse_dims, parse_spacing};
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_io::raw::RawSpec;
use endocast_io::{ElementType, Endian, Limits, Loaded, OpenOptions, RenderKind};
use std::path::{Path, PathBuf};

/// How to read the input scan.
#[derive(Args, Debug)]
pub struct InputArgs {
    /// The scan: a DICOM directory or file, .nii/.nii.gz, .hdr with its .img (NIfTI or Analyze
    /// 7.5), .nrrd/.nhdr, .mha/.mhd, an OME-Zarr 0.4/0.5 folder (x.zarr: its full resolution;
    /// x.zarr/1: its level 1), or a raw file.
    pub path: PathBuf,
    /// DICOM: load this SeriesInstanceUID instead of the largest series.
    #[arg(long, value_name = "UID")]
    pub series: Option<String>,
    /// Refuse volumes with more voxels than this (default: half the memory at 2 bytes a voxel).
    #[arg(long, value_name = "N")]
    pub max_voxels: Option<u64>,
    /// For files that declare no patient orientation (raw, NRRD without a space, OME-Zarr not
    /// written by endocast): where the index axes point, e.g. LPI for slices stored from the
    /// top of the head down.
    #[arg(long, value_name = "CODE")]
    pub orientation: Option<String>,
    /// DICOM: read a series with missing slices (a gap of whole steps in evenly spaced slices),
    /// filling them by interpolation (warned); refused without it.
    #[arg(long)]
    pub fill_missing_slices: bool,
    /// NRRD/MetaImage: allow a detached data file outside the header's folder.
    #[arg(long)]
    pub allow_outside_data: bool,
    /// Raw input: dimensions X,Y,Z (makes the file be read as headerless samples).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_dims)]
    pub raw_dims: Option<[usize; 3]>,
    /// Raw input: voxel spacing in mm.
    #[arg(long, value_name = "X,Y,Z", default_value = "1,1,1", value_parser = parse_spacing)]
    pub raw_spacing: [f64; 3],
    /// Raw input: sample type (uint8, int8, uint16, int16, uint32, int32, float32, float64, ...).
    #[arg(long, value_name = "TYPE", default_value = "int16")]
    pub raw_type: String,
    /// Raw input: byte order of the samples.
    #[arg(long, value_name = "little|big", default_value = "little")]
    pub raw_endian: String,
    /// Raw input: bytes to skip before the first sample.
    #[arg(long, value_name = "BYTES", default_value_t = 0)]
    pub raw_header_bytes: u64,
    #[command(flatten)]
    pub cleanse: CleanseArgs,
}

impl InputArgs {
    /// The resource limits: the defaults, with `--max-voxels` when given.
    pub fn limits(&self) -> Limits {
        self.max_voxels
            .map_or_else(Limits::default, Limits::with_max_voxels)
    }

    /// Refuses before the frames are allocated when `frames` views of `size` for `output`,
    /// rendered as `kind` says, would take more memory than the limits allow.
    pub fn check_frames(
        &self,
        output: &Path,
        size: [usize; 2],
        kind: RenderKind,
        frames: u64,
    ) -> Result<()> {
        self.limits()
            .check_frames(output, size, kind, frames)
            .context("the image is too large")?;
        Ok(())
    }

    /// Reads the scan these options name, cleansed when `--cleanse on` asks for it.
    pub fn open(&self) -> Result<Loaded> {
        let mut loaded = self.open_as_stored()?;
        loaded.volume = self.cleanse.apply(loaded.volume)?;
        Ok(loaded)
    }

    fn open_as_stored(&self) -> Result<Loaded> {
        let mut options = OpenOptions::default();
        options.series.clone_from(&self.series);
        options.limits = self.limits();
        options.raw = self.raw_spec()?;
        options.orientation.clone_from(&self.orientation);
        options.fill_missing_slices = self.fill_missing_slices;
        options.allow_outside_data = self.allow_outside_data;
        endocast_io::open(&self.path, &options).context("cannot read the scan")
    }

    fn raw_spec(&self) -> Result<Option<RawSpec>> {
        let Some(dims) = self.raw_dims else {
            return Ok(None);
        };
        let Some(element) = ElementType::from_name(&self.raw_type) else {
            bail!("unknown --raw-type {:?}", self.raw_type);
        };
        let endian = match self.raw_endian.to_ascii_lowercase().as_str() {
            "little" | "le" => Endian::Little,
            "big" | "be" => Endian::Big,
            other => bail!("--raw-endian must be little or big, not {other:?}"),
        };
        Ok(Some(RawSpec {
            dims,
            spacing_mm: self.raw_spacing,
            element,
            endian,
            header_bytes: self.raw_header_bytes,
        }))
    }
}
