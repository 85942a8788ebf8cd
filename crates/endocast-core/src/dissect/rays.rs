//! The dissection's rays: one column per arc-length step along the path and one row per angle
//! around it, each ray leaving the path perpendicular to it, in the column's rotation-minimising
//! frame, its reach clamped so that no two columns' rays cross.
//!
//! Why a clamp, and not rays bent toward the centre of curvature: every ray of a column lies in
//! the column's cutting plane (through the path point, normal to the tangent). Two columns'
//! planes meet in a line; a ray stopped where it first reaches another column's plane stays on
//! its own side of that line, so the clamped fans of two columns share no point beyond it: no
//! wall point shows twice in the flat image and the columns keep their order along the wall.
//! Curved cutting surfaces reach more of the wall inside a bend sharper than the lumen's
//! radius, but they must be integrated ray by ray and follow the curvature of a noisy
//! centreline; the clamp is exact, needs only the frames, and where it stops a ray before the
//! wall (the inner side of such a bend) the pixel is left empty, never filled with wall that a
//! neighbouring column shows too.

use crate::path::Path;
use glam::DVec3;
use std::f64::consts::TAU;

/// One column of the flat image: where its rays start and the frame they fan out in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Column {
    /// Arc length from the path's start, mm.
    pub arc_mm: f64,
    /// The path point the rays start from, world mm.
    pub origin: DVec3,
    /// Unit tangent: the normal of the column's cutting plane.
    pub tangent: DVec3,
    /// Unit up vector of the rotation-minimising frame: the ray of angle 0, the image's top.
    pub up: DVec3,
    /// `tangent × up`: the ray of angle 90°.
    pub right: DVec3,
}

/// The columns every `step_mm` of arc length from the path's start (the end is included when
/// the length is a whole number of steps).
pub(super) fn columns(path: &Path, count: usize, step_mm: f64) -> Vec<Column> {
    (0..count)
        .map(|n| {
            let arc_mm = (n as f64 * step_mm).min(path.len_mm());
            let frame = path.frame_at(arc_mm);
            Column {
                arc_mm,
                origin: frame.position_mm,
                tangent: frame.tangent,
                up: frame.up,
                right: frame.tangent.cross(frame.up),
            }
        })
        .collect()
}

/// The angle of `row` of `rows`, radians from the up vector toward the right one (each row at
/// the middle of its share of the circle).
pub(super) fn angle(row: usize, rows: usize) -> f64 {
    TAU * (row as f64 + 0.5) / rows as f64
}

/// The unit direction of `column`'s ray at `angle` (radians).
pub(super) fn direction(column: &Column, angle: f64) -> DVec3 {
    column.up * angle.cos() + column.right * angle.sin()
}

/// Another column's cutting plane as seen from one column's rays: a ray `origin + r · d`
/// reaches it at `r = offset / (d · tangent)`.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    /// The other column's index.
    column: usize,
    /// `(other origin − origin) · other tangent`, mm.
    offset: f64,
    /// The other tangent, which a ray's direction is dotted with.
    tangent: DVec3,
}

/// Whether `point` (on `column`'s cutting plane) lies inside `column`'s fan: nearer its origin
/// than the wall along the fan's ray toward it (`walls`: each row's distance to the wall, mm,
/// infinite where its ray met none).
fn in_fan(column: &Column, walls: &[f64], point: DVec3) -> bool {
    let v = point - column.origin;
    let turn = v.dot(column.right).atan2(v.dot(column.up)).rem_euclid(TAU);
    let row = ((turn / TAU * walls.len() as f64) as usize).min(walls.len() - 1);
    v.length() < walls[row]
}

/// The reach of each of the `rows` rays of column `i`, mm: `reach_mm`, or less where the ray
/// first meets the cutting plane of a column within `2 · reach_mm` of arc inside that column's
/// fan (see the module documentation). `walls[j][row]` is the distance from column `j` to the
/// wall along its ray `row` (infinite where none): a plane crossed beyond the other column's
/// wall (a far column of a path that comes back on itself, with tissue between the passes) does
/// not clamp.
pub(super) fn reaches(columns: &[Column], i: usize, reach_mm: f64, walls: &[Vec<f64>]) -> Vec<f64> {
    let own = columns[i];
    let crossings: Vec<Crossing> = columns
        .iter()
        .enumerate()
        .filter(|&(j, c)| j != i && (c.arc_mm - own.arc_mm).abs() <= 2.0 * reach_mm)
        .map(|(column, c)| Crossing {
            column,
            offset: (c.origin - own.origin).dot(c.tangent),
            tangent: c.tangent,
        })
        .filter(|c| {
            // The nearest the plane comes along any of the rays: |offset| / |tangent in plane|.
            let in_plane = (c.tangent - own.tangent * c.tangent.dot(own.tangent)).length();
            c.offset.abs() < reach_mm * in_plane
        })
        .collect();
    let rows = walls[i].len();
    (0..rows)
        .map(|row| {
            let d = direction(&own, angle(row, rows));
            crossings.iter().fold(reach_mm, |reach, c| {
                let r = c.offset / d.dot(c.tangent);
                let at = own.origin + d * r;
                if r > 0.0 && r < reach && in_fan(&columns[c.column], &walls[c.column], at) {
                    r
                } else {
                    reach
                }
            })
        })
        .collect()
}
