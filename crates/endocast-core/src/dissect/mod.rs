//! Virtual dissection, the "filet" view of CT colonography (Silva et al. 2006): the lumen cut
//! open along its path and laid flat, length along the path across, the circumference down,
//! with a map from every pixel back to its 3D wall point (Yao et al. 2010).
//!
//! One column per fixed step of arc length, one row per fixed step of angle: each pixel's ray
//! leaves the path perpendicular to it, in the path's rotation-minimising frame (angle 0 along
//! its up vector, the cut), and stops at the first crossing of the wall's isovalue, clamped so
//! that rays of different columns never cross at bends ([`rays`] says why). The wall is shaded
//! as the iso view shades it, lit along the ray.
//!
//! ```
//! use endocast_core::dissect::{dissect, DissectOptions, Wall};
//! use endocast_core::path::Path;
//! use endocast_core::phantom::{Phantom, PhantomOptions};
//! use glam::DVec3;
//!
//! // The straight tube runs along z through the centre; its radius is 0.2 · 32 = 6.4 mm.
//! let volume = Phantom::StraightTube.build(&PhantomOptions { size: 32, ..Default::default() });
//! let axis = [DVec3::new(0.0, 0.0, -10.0), DVec3::new(0.0, 0.0, 10.0)];
//! let path = Path::from_points_exact(&axis, 0.5).unwrap();
//! let flat = dissect(&volume, &path, &Wall { iso: -480.0, color: [1.0, 0.7, 0.6] },
//!     &DissectOptions::default()).unwrap();
//! let plot = flat.plot;
//! let wall = flat.map.at(plot.x + 10, plot.y + 30).unwrap();
//! assert!((wall.truncate().length() - 6.4).abs() < 0.1);
//! ```

mod cast;
mod image;
mod map;
mod pick;
mod rays;
#[cfg(test)]
mod tests;

pub use image::{Plot, Scale};
pub use map::WallMap;
pub use pick::PickError;

use crate::path::Path;
use crate::render::{RenderSettings, MAX_IMAGE_EDGE};
use crate::views::{Image, ViewError};
use crate::Volume;
use cast::Caster;
use rayon::prelude::*;

/// Default rows: one per degree around the path.
pub const DEFAULT_ROWS: usize = 360;
/// Default reach of a ray, mm: beyond the widest colon (about 9 cm across when distended).
pub const DEFAULT_REACH_MM: f64 = 60.0;
/// Default arc length per column, mm: finer than the voxels of most CT colonography scans.
pub const DEFAULT_STEP_MM: f64 = 0.5;
/// Fewest rows that still show the wall's circumference.
const MIN_ROWS: usize = 8;

/// How the wall is laid flat.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DissectOptions {
    /// Arc length per column, mm. Default [`DEFAULT_STEP_MM`].
    pub step_mm: f64,
    /// Rows, one per `360° / rows` around the path. Default [`DEFAULT_ROWS`].
    pub rows: usize,
    /// How far from the path a ray looks for the wall, mm. Default [`DEFAULT_REACH_MM`].
    pub reach_mm: f64,
}

impl Default for DissectOptions {
    fn default() -> Self {
        Self {
            step_mm: DEFAULT_STEP_MM,
            rows: DEFAULT_ROWS,
            reach_mm: DEFAULT_REACH_MM,
        }
    }
}

/// The wall the rays look for: its isovalue and colour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wall {
    /// The isovalue, in the volume's physical units (HU for CT).
    pub iso: f64,
    /// The surface colour before shading, 0–1.
    pub color: [f32; 3],
}

impl Wall {
    /// The wall of the iso view `settings` draw: their isovalue and surface colour.
    pub fn of(settings: &RenderSettings) -> Self {
        Self {
            iso: settings.iso_hu,
            color: settings.iso_color,
        }
    }
}

/// Why no dissection was made.
#[derive(Debug, thiserror::Error)]
pub enum DissectError {
    /// An option is NaN, infinite or out of its range.
    #[error("{0} must be a finite positive number, not {1}")]
    BadOption(&'static str, f64),
    /// The wall's isovalue is NaN or infinite.
    #[error("the wall's isovalue must be a finite number, not {0}")]
    BadIso(f64),
    /// Too few or too many rows.
    #[error("the rows around the path must number {MIN_ROWS} to {max}, not {0}", max = MAX_IMAGE_EDGE)]
    BadRows(usize),
    /// The path is too long for an image at this step.
    #[error(
        "the path of {length_mm:.0} mm needs {columns} columns at {step_mm} mm each, more than \
         an image holds ({max}): give a larger step",
        max = MAX_IMAGE_EDGE
    )]
    TooManyColumns {
        /// The path's length, mm.
        length_mm: f64,
        /// The step asked for, mm.
        step_mm: f64,
        /// Columns it would take.
        columns: f64,
    },
    /// No ray found the wall.
    #[error(
        "no ray from the path met the wall (isovalue {0}) within the reach: is the path inside \
         the lumen, and in this scan's coordinates?"
    )]
    NoWall(f64),
    /// The image could not be made.
    #[error(transparent)]
    Image(#[from] ViewError),
}

/// A dissection: the flat image, the map from its pixels to the wall, and their scale.
#[derive(Debug, Clone)]
pub struct Dissection {
    /// The flat image: the wall in [`Dissection::plot`], labelled margins around it.
    pub image: Image,
    /// The wall point of each pixel of [`Dissection::image`] (NaN in the margins).
    pub map: WallMap,
    /// Where the wall lies in the image.
    pub plot: Plot,
    /// The image's scale.
    pub scale: Scale,
    /// Share of the plot's pixels that show wall, 0–1.
    pub hit_fraction: f64,
}

/// Lays the wall around `path` in `volume` flat (see the module documentation).
pub fn dissect(
    volume: &Volume,
    path: &Path,
    wall: &Wall,
    options: &DissectOptions,
) -> Result<Dissection, DissectError> {
    check(wall, options)?;
    let step_mm = options.step_mm;
    let columns = column_count(path.len_mm(), step_mm)?;
    let columns = rays::columns(path, columns, step_mm);
    let caster = Caster::new(volume, wall.iso, wall.color);
    let rows = options.rows;
    // Every ray to the wall first, then each hit kept where no neighbouring fan is crossed
    // on the way (the clamp of `rays::reaches`, which needs the fans' walls).
    let mut hits: Vec<Vec<Option<cast::Hit>>> = columns
        .par_iter()
        .map(|column| {
            (0..rows)
                .map(|row| {
                    let dir = rays::direction(column, rays::angle(row, rows));
                    caster.cast(column.origin, dir, options.reach_mm)
                })
                .collect()
        })
        .collect();
    let walls: Vec<Vec<f64>> = columns
        .iter()
        .zip(&hits)
        .map(|(c, column)| {
            let distance =
                |h: &Option<cast::Hit>| h.map_or(f64::INFINITY, |h| h.point.distance(c.origin));
            column.iter().map(distance).collect()
        })
        .collect();
    hits.par_iter_mut().enumerate().for_each(|(i, column)| {
        let reaches = rays::reaches(&columns, i, options.reach_mm, &walls);
        for ((hit, wall), reach) in column.iter_mut().zip(&walls[i]).zip(reaches) {
            if *wall > reach {
                *hit = None;
            }
        }
    });
    lay_flat(&columns, &hits, step_mm, wall.iso)
}

/// Refuses a NaN isovalue, a step or reach that is not a positive number, or a row count no
/// image has.
fn check(wall: &Wall, options: &DissectOptions) -> Result<(), DissectError> {
    let step = options.step_mm;
    if !(step.is_finite() && step > 0.0) {
        return Err(DissectError::BadOption("the column step (mm)", step));
    }
    if !wall.iso.is_finite() {
        return Err(DissectError::BadIso(wall.iso));
    }
    if !(options.reach_mm.is_finite() && options.reach_mm > 0.0) {
        return Err(DissectError::BadOption("the reach (mm)", options.reach_mm));
    }
    if !(MIN_ROWS..=MAX_IMAGE_EDGE).contains(&options.rows) {
        return Err(DissectError::BadRows(options.rows));
    }
    Ok(())
}

/// Columns for a path of `length_mm` at `step_mm`: one at each whole step from the start,
/// within what an image holds.
fn column_count(length_mm: f64, step_mm: f64) -> Result<usize, DissectError> {
    let columns = (length_mm / step_mm).floor() + 1.0;
    if columns > MAX_IMAGE_EDGE as f64 {
        return Err(DissectError::TooManyColumns {
            length_mm,
            step_mm,
            columns,
        });
    }
    Ok(columns as usize)
}

/// The image and map of the rays' hits (`hits[column][row]`).
fn lay_flat(
    columns: &[rays::Column],
    hits: &[Vec<Option<cast::Hit>>],
    step_mm: f64,
    iso: f64,
) -> Result<Dissection, DissectError> {
    let rows = hits.first().map_or(0, Vec::len);
    let plot = Plot::new(columns.len(), rows);
    let mut distances: Vec<f64> = columns
        .iter()
        .zip(hits)
        .flat_map(|(c, column)| column.iter().flatten().map(|h| h.point.distance(c.origin)))
        .collect();
    if distances.is_empty() {
        return Err(DissectError::NoWall(iso));
    }
    let hits_count = distances.len();
    let hit_fraction = hits_count as f64 / (columns.len() * rows) as f64;
    let median = *distances
        .select_nth_unstable_by(hits_count / 2, f64::total_cmp)
        .1;
    let scale = Scale {
        along_mm_per_px: step_mm,
        around_deg_per_px: 360.0 / rows as f64,
        around_mm_per_px: std::f64::consts::TAU * median / rows as f64,
    };
    let mut image = image::blank(&plot, &scale)?;
    let (width, height) = plot.image_size();
    let mut map = WallMap::empty(width, height);
    for (c, column) in hits.iter().enumerate() {
        for (r, hit) in column.iter().enumerate() {
            let Some(hit) = hit else { continue };
            let (x, y) = (plot.x + c, plot.y + r);
            let rgb = (hit.color.clamp(glam::Vec3::ZERO, glam::Vec3::ONE) * 255.0).round();
            image.put(x as i64, y as i64, [rgb.x as u8, rgb.y as u8, rgb.z as u8]);
            map.set(x, y, hit.point);
        }
    }
    Ok(Dissection {
        image,
        map,
        plot,
        scale,
        hit_fraction,
    })
}
