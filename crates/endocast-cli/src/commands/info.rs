//! `endocast info`: what a scan is, where it sits in the patient, and what went wrong reading it.

use crate::input::InputArgs;
use anyhow::Result;
use clap::Args;
use endocast_core::look::MAX_TEXELS;
use endocast_core::{Modality, Volume};
use endocast_io::{Limits, Loaded};
use serde::Serialize;

/// Arguments of `endocast info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// Everything `info` reports; the text and JSON outputs are two views of it.
#[derive(Serialize)]
struct Report {
    path: String,
    format: &'static str,
    stored_type: String,
    modality: String,
    dimensions: [usize; 3],
    spacing_mm: [f64; 3],
    origin_mm: [f64; 3],
    /// Columns: unit world (LPS) vectors of the i, j, k axes.
    direction_columns: [[f64; 3]; 3],
    orientation: String,
    orthogonal: bool,
    world_bounds_mm: [[f64; 3]; 2],
    value_range: [f64; 2],
    value_unit: &'static str,
    value_map: ValueMapReport,
    voxel_bytes: usize,
    series_uid: Option<String>,
    series_found: Vec<SeriesReport>,
    limits: LimitsReport,
    warnings: Vec<String>,
}

/// The resource limits in force, so that a user can see what a refusal was measured against.
#[derive(Serialize)]
struct LimitsReport {
    /// The memory the defaults derive from (physical, cgroup or address-space limit), bytes;
    /// `None` when unreadable.
    memory_counted_bytes: Option<u64>,
    max_voxels: u64,
    max_slices: u64,
    /// Memory the frames of one view may take, bytes.
    max_frame_bytes: u64,
    /// The largest plain still, in pixels (e.g. `--size` W×H with W·H at most this).
    max_image_pixels: u64,
    max_frames: u64,
    max_threads: usize,
    /// The longest edge of a texture image, pixels.
    max_texture_edge: usize,
}

impl LimitsReport {
    fn new(limits: &Limits) -> Self {
        Self {
            memory_counted_bytes: Limits::memory_counted(),
            max_voxels: limits.max_voxels,
            max_slices: limits.max_slices,
            max_frame_bytes: limits.max_frame_bytes,
            max_image_pixels: limits.max_image_pixels(),
            max_frames: limits.max_frames,
            max_threads: limits.max_threads,
            max_texture_edge: MAX_TEXELS,
        }
    }

    /// One line: `limits:       memory counted 15.6 GiB, voxels 2092957696, ...`.
    fn text(&self) -> String {
        let gib = |bytes: u64| format!("{:.1} GiB", bytes as f64 / f64::from(1u32 << 30));
        format!(
            "limits:       memory counted {}, voxels {}, slices {}, frame memory {}, image \
             pixels {}, frames {}, threads {}, texture edge {}\n",
            self.memory_counted_bytes.map_or("unknown".into(), gib),
            self.max_voxels,
            self.max_slices,
            gib(self.max_frame_bytes),
            self.max_image_pixels,
            self.max_frames,
            self.max_threads,
            self.max_texture_edge
        )
    }
}

#[derive(Serialize)]
struct ValueMapReport {
    scale: f64,
    offset: f64,
}

#[derive(Serialize)]
struct SeriesReport {
    uid: String,
    description: String,
    modality: String,
    images: usize,
}

/// Runs `endocast info`.
pub fn run(args: &InfoArgs) -> Result<()> {
    let loaded = args.input.open()?;
    let path = args.input.path.display().to_string();
    let report = Report::new(&path, &loaded, &args.input.limits());
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report.text());
    }
    Ok(())
}

impl Report {
    fn new(path: &str, loaded: &Loaded, limits: &Limits) -> Self {
        let volume: &Volume = &loaded.volume;
        let g = volume.geometry();
        let (lo, hi) = volume.physical_range();
        let (min_w, max_w) = g.world_bounds();
        let map = volume.value_map();
        Self {
            path: path.to_string(),
            format: loaded.source.format.name(),
            stored_type: loaded.source.stored_type.clone(),
            modality: volume.modality().name().to_string(),
            dimensions: g.dims(),
            spacing_mm: g.spacing_mm().to_array(),
            origin_mm: g.origin_mm().to_array(),
            direction_columns: g.direction().to_cols_array_2d(),
            orientation: g.orientation_code(),
            orthogonal: g.is_orthogonal(),
            world_bounds_mm: [min_w.to_array(), max_w.to_array()],
            value_range: [lo, hi],
            value_unit: if *volume.modality() == Modality::Ct {
                "HU"
            } else {
                ""
            },
            value_map: ValueMapReport {
                scale: map.scale(),
                offset: map.offset(),
            },
            voxel_bytes: volume.voxel_bytes(),
            series_uid: loaded.source.series_uid.clone(),
            series_found: loaded
                .source
                .series_found
                .iter()
                .map(|s| SeriesReport {
                    uid: s.uid.clone(),
                    description: s.description.clone(),
                    modality: s.modality.clone(),
                    images: s.images,
                })
                .collect(),
            limits: LimitsReport::new(limits),
            warnings: loaded.warnings.clone(),
        }
    }

    fn text(&self) -> String {
        let v3 = |v: [f64; 3]| format!("({}, {}, {})", num(v[0]), num(v[1]), num(v[2]));
        let [nx, ny, nz] = self.dimensions;
        let [sx, sy, sz] = self.spacing_mm.map(num);
        let mut out = format!(
            "file:         {}\nformat:       {} ({})\nmodality:     {}\n\
             dimensions:   {nx} × {ny} × {nz}\nspacing:      {sx} × {sy} × {sz} mm\n\
             origin:       {} mm (LPS)\ndirection:    i {}  j {}  k {}{}\n\
             orientation:  {}\nworld bounds: {} … {} mm\nvalues:       {} … {}{}\n\
             stored:       u16, physical = {}\nmemory:       {:.1} MiB\n",
            self.path,
            self.format,
            self.stored_type,
            self.modality,
            v3(self.origin_mm),
            v3(self.direction_columns[0]),
            v3(self.direction_columns[1]),
            v3(self.direction_columns[2]),
            if self.orthogonal { "" } else { "  (sheared)" },
            self.orientation,
            v3(self.world_bounds_mm[0]),
            v3(self.world_bounds_mm[1]),
            self.value_range[0],
            self.value_range[1],
            if self.value_unit.is_empty() {
                String::new()
            } else {
                format!(" {}", self.value_unit)
            },
            linear_map(self.value_map.scale, self.value_map.offset),
            self.voxel_bytes as f64 / (1024.0 * 1024.0),
        );
        if let Some(uid) = &self.series_uid {
            out += &format!("series:       {uid}\n");
        }
        if self.series_found.len() > 1 {
            out += "series found:\n";
            for s in &self.series_found {
                out += &format!(
                    "  {} {} images {} {}\n",
                    s.uid, s.images, s.modality, s.description
                );
            }
        }
        out += &self.limits.text();
        for w in &self.warnings {
            out += &format!("warning:      {w}\n");
        }
        out
    }
}

/// `x` with at most four decimals, trailing zeros dropped, and no negative zero.
fn num(x: f64) -> String {
    let text = format!("{x:.4}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".into()
    } else {
        text.into()
    }
}

/// `stored × scale + offset`, leaving out a scale of 1 and an offset of 0 (a negative offset
/// is subtracted).
fn linear_map(scale: f64, offset: f64) -> String {
    let mut text = String::from("stored");
    if scale != 1.0 {
        text += &format!(" × {scale}");
    }
    if offset < 0.0 {
        text += &format!(" − {}", -offset);
    } else if offset > 0.0 {
        text += &format!(" + {offset}");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_drop_trailing_zeros_and_negative_zero() {
        assert_eq!(num(3.0), "3");
        assert_eq!(num(1.07421875), "1.0742");
        assert_eq!(num(-0.00001), "0");
        assert_eq!(num(-275.0), "-275");
        assert_eq!(num(0.25), "0.25");
    }

    #[test]
    fn the_value_map_reads_as_a_formula() {
        assert_eq!(linear_map(1.0, -1000.0), "stored − 1000");
        assert_eq!(linear_map(1.0, 0.0), "stored");
        assert_eq!(linear_map(0.5, 3.0), "stored × 0.5 + 3");
    }
}
