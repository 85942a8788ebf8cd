//! From a pixel of the flat image back to the endoscope (Yao et al.'s reversible mapping, used
//! the other way): the arc length of the pixel's column, and the camera on the path there
//! looking at the pixel's wall point along the ray that found it, so nothing stands between
//! them; and the column of an arc length, where a front end marks the endoscope.

use super::Dissection;
use crate::flight::up_for;
use crate::path::Path;
use crate::pose::Pose;

/// Why a pixel of the flat image gives no camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PickError {
    /// The pixel lies in the labelled margins, not on the wall's plot.
    #[error("pixel ({0}, {1}) is outside the flat wall")]
    OutsidePlot(usize, usize),
    /// The pixel's ray met no wall within its reach (NaN in the map).
    #[error("pixel ({0}, {1}) shows no wall: its ray met none")]
    NoWall(usize, usize),
}

impl Dissection {
    /// The arc length along the dissected `path` of image column `x`, mm from its start (as the
    /// rays were cast: a whole number of steps, the last clamped to the path's end); `None`
    /// outside the plot. `path` is the path the dissection was made along.
    pub fn arc_mm_of_column(&self, x: usize, path: &Path) -> Option<f64> {
        let column = x
            .checked_sub(self.plot.x)
            .filter(|&c| c < self.plot.columns)?;
        Some((column as f64 * self.scale.along_mm_per_px).min(path.len_mm()))
    }

    /// The image column nearest arc length `arc_mm` along the path; `None` before its start or
    /// beyond its last column (and for NaN).
    pub fn column_of_arc(&self, arc_mm: f64) -> Option<usize> {
        let column = (arc_mm / self.scale.along_mm_per_px).round();
        let inside = column >= 0.0 && column < self.plot.columns as f64;
        inside.then(|| self.plot.x + column as usize)
    }

    /// The camera that shows the wall point of pixel `(x, y)`: its eye on `path` (the path the
    /// dissection was made along) at the column's arc length, where the pixel's ray started,
    /// looking at the point, up toward the patient's head as the review's patch views are.
    pub fn pose_of_pixel(&self, path: &Path, x: usize, y: usize) -> Result<Pose, PickError> {
        let rows = self.plot.y..self.plot.y + self.plot.rows;
        let arc_mm = self
            .arc_mm_of_column(x, path)
            .filter(|_| rows.contains(&y))
            .ok_or(PickError::OutsidePlot(x, y))?;
        let wall_mm = self.map.at(x, y).ok_or(PickError::NoWall(x, y))?;
        let eye_mm = path.point_at(arc_mm);
        Ok(Pose {
            eye_mm,
            look_at_mm: wall_mm,
            up: up_for(wall_mm - eye_mm),
        })
    }
}
