//! Ordering the frames of a series into a stack and its geometry.

use super::scan::{FrameHeader, ImageFile};
use crate::error::{ReadError, Result};
use crate::samples::Rescale;
use endocast_core::Geometry;
use glam::{DMat3, DVec3};
use std::path::Path;

/// Two slices closer than this (mm) are the same slice stored twice.
const DUPLICATE_MM: f64 = 1e-3;
/// Smallest tilt (degrees) between the stack direction and the slice normal worth a warning.
const TILT_WARNING_DEG: f64 = 0.05;

/// One frame of the stack: which file and frame it comes from and where it lies.
#[derive(Debug, Clone, Copy)]
pub(super) struct Slice {
    /// Index into the series' files.
    pub file: usize,
    /// Frame number inside that file.
    pub frame: u32,
    /// Its rescale to physical values.
    pub rescale: Rescale,
    /// Distance (mm) from the first slice along the stack direction.
    pub offset_mm: f64,
}

/// The series ordered in space, with everything the volume's geometry needs.
#[derive(Debug, Clone)]
pub(super) struct Stack {
    /// Slices in stack order (increasing position along the slice normal).
    pub slices: Vec<Slice>,
    /// Unit row direction (increasing column index, the `i` axis).
    pub row: DVec3,
    /// Unit column direction (increasing row index, the `j` axis).
    pub column: DVec3,
    /// Unit direction from the first to the last slice (the `k` axis); the normal when there
    /// is a single slice.
    pub stack_direction: DVec3,
    /// Position (mm) of the first pixel of the first slice.
    pub origin: DVec3,
    /// Spacing (mm) along `i`, `j` and, before any resampling, the mean step along `k`.
    pub spacing: DVec3,
}

impl Stack {
    /// Orders the frames of `files` by their position along the slice normal, drops
    /// duplicates, and checks that they form one straight stack of identical images.
    pub(super) fn build(
        root: &Path,
        files: &[ImageFile],
        warnings: &mut Vec<String>,
    ) -> Result<Self> {
        check_same_layout(root, files)?;
        let frames: Vec<(usize, &FrameHeader)> = files
            .iter()
            .enumerate()
            .flat_map(|(index, file)| file.frames.iter().map(move |frame| (index, frame)))
            .collect();
        let placed = place_frames(root, files, &frames, warnings)?;
        let [row, column] = placed.orientation;
        let normal = row.cross(column);
        let mut order: Vec<(f64, usize, &FrameHeader, DVec3)> = frames
            .iter()
            .zip(&placed.positions)
            .map(|(&(file, frame), &position)| (position.dot(normal), file, frame, position))
            .collect();
        // Stable: of two copies of a slice, the one in the first file (by path) is kept.
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
        let before = order.len();
        order.dedup_by(|later, kept| later.3.distance(kept.3) < DUPLICATE_MM);
        if order.len() < before {
            warnings.push(format!(
                "{}: {} slice(s) at a position already taken were dropped (duplicates)",
                root.display(),
                before - order.len()
            ));
        }
        let positions: Vec<DVec3> = order.iter().map(|o| o.3).collect();
        let origin = positions[0];
        let (stack_direction, offsets) = match positions.last() {
            Some(&last) if positions.len() > 1 => {
                let direction = (last - origin).normalize();
                (direction, line_offsets(root, &positions, direction)?)
            }
            _ => (normal, vec![0.0]),
        };
        let step = match offsets.last() {
            Some(&span) if offsets.len() > 1 => span / (offsets.len() - 1) as f64,
            _ => single_slice_thickness(&files[order[0].1].path, placed.thickness, warnings),
        };
        warn_tilt(root, stack_direction, normal, warnings);
        let slices = order
            .iter()
            .zip(&offsets)
            .map(|(&(_, file, frame, _), &offset_mm)| Slice {
                file,
                frame: frame.frame,
                rescale: frame.rescale,
                offset_mm,
            })
            .collect();
        let [between_rows, between_columns] = placed.pixel_spacing;
        Ok(Self {
            slices,
            row,
            column,
            stack_direction,
            origin,
            spacing: DVec3::new(between_columns, between_rows, step),
        })
    }

    /// The geometry of this stack with `count` slices `step_mm` apart (the first slice stays
    /// where it is). `rows`/`columns` are the image size.
    pub(super) fn geometry(
        &self,
        root: &Path,
        [columns, rows]: [usize; 2],
        count: usize,
        step_mm: f64,
    ) -> Result<Geometry> {
        let spacing = DVec3::new(self.spacing.x, self.spacing.y, step_mm);
        let direction = DMat3::from_cols(self.row, self.column, self.stack_direction);
        Geometry::new([columns, rows, count], spacing, self.origin, direction).map_err(|e| {
            ReadError::inconsistent(root, format!("the slices do not form a grid: {e}"))
        })
    }
}

/// Where every frame is, its orientation and pixel spacing, once validated.
struct Placement {
    positions: Vec<DVec3>,
    orientation: [DVec3; 2],
    pixel_spacing: [f64; 2],
    /// SliceThickness of the first frame, as stored.
    thickness: Option<f64>,
}

fn place_frames(
    root: &Path,
    files: &[ImageFile],
    frames: &[(usize, &FrameHeader)],
    warnings: &mut Vec<String>,
) -> Result<Placement> {
    let (first_file, first) = frames[0];
    let first_path = &files[first_file].path;
    let positions: Option<Vec<DVec3>> = frames.iter().map(|(_, f)| f.position).collect();
    let orientations: Option<Vec<[DVec3; 2]>> = frames.iter().map(|(_, f)| f.orientation).collect();
    let (positions, orientation) = match (positions, orientations) {
        (Some(p), Some(o)) => (p, o[0]),
        _ if frames.len() == 1 => {
            warnings.push(format!(
                "{}: no ImagePositionPatient/ImageOrientationPatient; the image is placed \
                 at the origin, axial",
                first_path.display()
            ));
            (vec![DVec3::ZERO], [DVec3::X, DVec3::Y])
        }
        _ => {
            return Err(ReadError::format(
                root,
                "expected ImagePositionPatient and ImageOrientationPatient on every image \
                 (needed to order the slices), found images without them",
            ))
        }
    };
    let pixel_spacing = match first.pixel_spacing {
        Some(spacing) => spacing,
        None => {
            warnings.push(format!(
                "{}: no PixelSpacing (or 0\\0, \"unknown\"); assuming 1 mm pixels, so distances \
                 and sizes in millimetres may be wrong",
                first_path.display()
            ));
            [1.0, 1.0]
        }
    };
    for &(file, frame) in frames {
        let same = frame
            .pixel_spacing
            .map_or(first.pixel_spacing.is_none(), |s| {
                (s[0] - pixel_spacing[0]).abs() <= 1e-4 * pixel_spacing[0]
                    && (s[1] - pixel_spacing[1]).abs() <= 1e-4 * pixel_spacing[1]
            });
        if !same {
            return Err(differs(root, files, first_file, file, "PixelSpacing"));
        }
    }
    Ok(Placement {
        positions,
        orientation,
        pixel_spacing,
        thickness: first.thickness,
    })
}

/// The step of a volume of one slice, which has no neighbour to measure one from: its
/// SliceThickness when that is a positive number, else 1 mm with a warning.
fn single_slice_thickness(path: &Path, thickness: Option<f64>, warnings: &mut Vec<String>) -> f64 {
    let found = match thickness {
        Some(t) if t.is_finite() && t > 0.0 => return t,
        Some(t) => format!("SliceThickness {t} is not a positive number"),
        None => "no SliceThickness".to_owned(),
    };
    warnings.push(format!(
        "{}: {found}; the single slice is taken as 1 mm thick, so its depth in millimetres \
         is a guess",
        path.display()
    ));
    1.0
}

/// Rows, columns and sample format must agree across the series.
fn check_same_layout(root: &Path, files: &[ImageFile]) -> Result<()> {
    let first = &files[0];
    for (index, file) in files.iter().enumerate() {
        let (a, b) = (&first.layout, &file.layout);
        if (a.rows, a.columns) != (b.rows, b.columns) {
            return Err(differs(root, files, 0, index, "Rows/Columns"));
        }
        if a != b {
            return Err(differs(
                root,
                files,
                0,
                index,
                "pixel format (bits, sign or photometric interpretation)",
            ));
        }
    }
    Ok(())
}

fn differs(root: &Path, files: &[ImageFile], a: usize, b: usize, what: &str) -> ReadError {
    ReadError::inconsistent(
        root,
        format!(
            "{what} differs within series {} between {} and {}",
            files[a].series_uid,
            files[a].path.display(),
            files[b].path.display()
        ),
    )
}

/// Offsets (mm) of `positions` along `direction` from the first, after checking that they lie
/// on one line (within a tenth of a millimetre, about what headers round positions to).
fn line_offsets(root: &Path, positions: &[DVec3], direction: DVec3) -> Result<Vec<f64>> {
    const OFF_LINE_MM: f64 = 0.1;
    let origin = positions[0];
    let mut offsets = Vec::with_capacity(positions.len());
    for &position in positions {
        let along = (position - origin).dot(direction);
        let off_line = (position - origin - along * direction).length();
        if off_line > OFF_LINE_MM {
            return Err(ReadError::inconsistent(
                root,
                format!(
                    "slice positions do not lie on one line: {position:?} is {off_line:.2} mm \
                     off the line from the first to the last slice"
                ),
            ));
        }
        offsets.push(along);
    }
    if offsets.windows(2).any(|w| w[1] - w[0] <= 0.0) {
        return Err(ReadError::inconsistent(
            root,
            "slice positions do not advance along the stack",
        ));
    }
    Ok(offsets)
}

fn warn_tilt(root: &Path, stack_direction: DVec3, normal: DVec3, warnings: &mut Vec<String>) {
    let tilt_deg = stack_direction
        .dot(normal)
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees();
    if tilt_deg > TILT_WARNING_DEG {
        warnings.push(format!(
            "{}: gantry tilt of {tilt_deg:.1}°: slices are stacked {tilt_deg:.1}° off their \
             normal; the grid is kept sheared (not resampled in-plane)",
            root.display()
        ));
    }
}
