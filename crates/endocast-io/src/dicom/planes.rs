//! The main stack of a series: the largest group of parallel images of one size. Images in
//! another plane or of another size (a localiser, a reformat stored in the same series) are set
//! aside and named in a warning, instead of the whole series being refused.

use super::scan::{FrameHeader, ImageFile};
use glam::DVec3;
use std::path::Path;

/// Headers round cosines to about six digits; orientations closer than this are the same plane.
const ORIENTATION_TOLERANCE: f64 = 1e-4;
/// How many set-aside images a warning names.
const EXAMPLES: usize = 3;

/// The images of one plane and size.
struct Plane {
    orientation: Option<[DVec3; 2]>,
    size: (u16, u16),
    frames: usize,
}

impl Plane {
    fn holds(&self, file: &ImageFile, frame: &FrameHeader) -> bool {
        let same = match (self.orientation, frame.orientation) {
            (Some([r0, c0]), Some([r1, c1])) => {
                r0.abs_diff_eq(r1, ORIENTATION_TOLERANCE)
                    && c0.abs_diff_eq(c1, ORIENTATION_TOLERANCE)
            }
            (None, None) => true,
            _ => false,
        };
        same && self.size == (file.layout.rows, file.layout.columns)
    }

    /// E.g. `coronal (row 1,0,0, column 0,0,-1), 256×256`.
    fn describe(&self) -> String {
        let (rows, columns) = self.size;
        let orientation = match self.orientation {
            None => "without ImageOrientationPatient".to_owned(),
            Some([row, column]) => format!(
                "{} (row {}, column {})",
                plane_name(row.cross(column)),
                cosines(row),
                cosines(column)
            ),
        };
        format!("{orientation}, {columns}×{rows}")
    }
}

/// Keeps, of every file, the frames of the largest plane (the first found on a tie: files are
/// sorted by path) and drops files left without frames. When anything is set aside, a warning
/// says how many images, in which planes, and names the first few.
pub(super) fn main_stack(
    root: &Path,
    mut files: Vec<ImageFile>,
    warnings: &mut Vec<String>,
) -> Vec<ImageFile> {
    let mut planes: Vec<Plane> = Vec::new();
    let assigned: Vec<Vec<usize>> = files
        .iter()
        .map(|file| {
            file.frames
                .iter()
                .map(|frame| plane_of(&mut planes, file, frame))
                .collect()
        })
        .collect();
    if planes.len() < 2 {
        return files;
    }
    let main = (0..planes.len())
        .rev()
        .max_by_key(|&p| planes[p].frames)
        .unwrap_or(0);
    let mut set_aside: Vec<String> = Vec::new();
    for (file, planes_of_frames) in files.iter_mut().zip(&assigned) {
        let multi_frame = file.frames.len() > 1;
        let name = file
            .path
            .strip_prefix(root)
            .unwrap_or(&file.path)
            .display()
            .to_string();
        let mut index = 0;
        file.frames.retain(|frame| {
            let keep = planes_of_frames[index] == main;
            index += 1;
            if !keep {
                set_aside.push(if multi_frame {
                    format!("{name} frame {}", frame.frame + 1)
                } else {
                    name.clone()
                });
            }
            keep
        });
    }
    files.retain(|file| !file.frames.is_empty());
    warnings.push(aside_warning(root, &planes, main, &set_aside));
    files
}

/// The index of the plane holding `frame` of `file`, added when new.
fn plane_of(planes: &mut Vec<Plane>, file: &ImageFile, frame: &FrameHeader) -> usize {
    let index = match planes.iter().position(|p| p.holds(file, frame)) {
        Some(index) => index,
        None => {
            planes.push(Plane {
                orientation: frame.orientation,
                size: (file.layout.rows, file.layout.columns),
                frames: 0,
            });
            planes.len() - 1
        }
    };
    planes[index].frames += 1;
    index
}

fn aside_warning(root: &Path, planes: &[Plane], main: usize, set_aside: &[String]) -> String {
    let others: Vec<String> = planes
        .iter()
        .enumerate()
        .filter(|&(p, _)| p != main)
        .map(|(_, plane)| format!("{} {}", plane.frames, plane.describe()))
        .collect();
    let mut examples = set_aside[..set_aside.len().min(EXAMPLES)].join(", ");
    if set_aside.len() > EXAMPLES {
        examples.push_str(", ...");
    }
    format!(
        "{}: the series mixes planes; kept its main stack of {} images ({}) and set aside {} \
         image(s) not parallel to it or of another size ({}): {examples}",
        root.display(),
        planes[main].frames,
        planes[main].describe(),
        set_aside.len(),
        others.join("; "),
    )
}

/// Axial, coronal or sagittal by the normal's largest component, "oblique" when none
/// dominates (no component above cos 45°).
fn plane_name(normal: DVec3) -> &'static str {
    let n = normal.abs();
    let largest = n.max_element();
    if largest < std::f64::consts::FRAC_1_SQRT_2 {
        "oblique"
    } else if largest == n.z {
        "axial"
    } else if largest == n.y {
        "coronal"
    } else {
        "sagittal"
    }
}

/// `1,0,0` (three decimals at most).
fn cosines(v: DVec3) -> String {
    v.to_array()
        .iter()
        .map(|c| {
            let text = format!("{:.3}", c + 0.0);
            text.trim_end_matches('0').trim_end_matches('.').to_owned()
        })
        .collect::<Vec<_>>()
        .join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_are_named_by_their_normal() {
        assert_eq!(plane_name(DVec3::Z), "axial");
        assert_eq!(plane_name(-DVec3::Y), "coronal");
        assert_eq!(plane_name(DVec3::X), "sagittal");
        assert_eq!(plane_name(DVec3::new(1.0, 1.0, 1.0).normalize()), "oblique");
        assert_eq!(cosines(DVec3::new(1.0, -0.0, -0.5)), "1,0,-0.5");
    }
}
