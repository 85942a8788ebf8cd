//! The 360° panorama: an equirectangular map of the directions around the eye. The column is
//! the longitude around the camera's up vector — the view direction in the middle column, the
//! right a quarter of the width further, the seam (±180°) behind the eye at the left and right
//! edges — and the row the latitude above the camera's horizon, from +field/2 at the top to
//! −field/2 at the bottom, both linear in the angle.
//!
//! Equirectangular rather than cylindrical: its rows reach the poles, so a field of 180° shows
//! every direction once (a central-perspective cylinder's `tan` latitude never reaches the
//! walls above and below the eye, and a tube's wall is there), every row has one angular
//! height, and the 2 : 1 image is the format 360° viewers read. A smaller field crops it to a
//! band about the horizon (less stretched near the poles). Pixels are square when
//! `width = height · 360° / field`.

use glam::DVec3;
use std::f64::consts::TAU;

/// The unit direction at image point `(x, y)` of a `width × height` panorama spanning
/// `field_rad` of latitude, for a camera with axes `camera` (forward, right, up); `None`
/// outside the image's rows.
pub fn direction(
    [forward, right, up]: [DVec3; 3],
    [width, height]: [usize; 2],
    field_rad: f64,
    (x, y): (f64, f64),
) -> Option<DVec3> {
    let v = 0.5 - y / height as f64;
    if v.abs() > 0.5 {
        return None;
    }
    let longitude = (x / width as f64 - 0.5) * TAU;
    let latitude = v * field_rad;
    let horizontal = forward * longitude.cos() + right * longitude.sin();
    Some(horizontal * latitude.cos() + up * latitude.sin())
}

/// The image point where direction `d` (not zero) is seen, or `None` beyond the field's
/// latitudes. The longitude of a direction on the camera's up axis is taken as 0.
pub fn position(
    [forward, right, up]: [DVec3; 3],
    [width, height]: [usize; 2],
    field_rad: f64,
    d: DVec3,
) -> Option<(f64, f64)> {
    let (along, across, above) = (d.dot(forward), d.dot(right), d.dot(up));
    let latitude = above.atan2(along.hypot(across));
    if latitude.abs() > field_rad / 2.0 * (1.0 + 1e-12) {
        return None;
    }
    let longitude = across.atan2(along);
    Some((
        (longitude / TAU + 0.5) * width as f64,
        (0.5 - latitude / field_rad) * height as f64,
    ))
}

/// The column of longitude `degrees` (0: the view direction, 90: the right, ±180: the seam) in
/// an image `width` pixels wide.
pub fn column_of(degrees: f64, width: usize) -> f64 {
    (degrees.to_radians() / TAU + 0.5) * width as f64
}
