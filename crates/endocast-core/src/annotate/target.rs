//! The target of a bronchoscopy route (a nodule, `endocast path --target`) drawn in the
//! endoscope's view, depth-aware: a solid ring where nothing the view shows lies in front of
//! it, a dashed, dimmer ring where it lies behind the wall the view shows (the point of virtual
//! bronchoscopy: where the target is behind the bronchial wall), each with its straight
//! distance from the eye. The ring is the outline of a sphere of [`TARGET_RADIUS_MM`] around
//! the target, so it grows as the scope comes near.

use super::{SurfaceView, Visibility};
use crate::views::font::{text_width, GLYPH_HEIGHT};
use crate::views::{Image, Rgb};
use glam::DVec3;

/// Colour of the target in sight.
pub const TARGET_COLOR: Rgb = [255, 70, 200];
/// Colour of the target behind the wall: the same hue, paler (dimmed, yet clear on the pink
/// wall it is seen through).
pub const HIDDEN_TARGET_COLOR: Rgb = [215, 150, 235];
/// Radius of the sphere whose outline the ring is, mm (a nodule of 10 mm).
pub const TARGET_RADIUS_MM: f64 = 5.0;
/// The ring's radius is kept within these, pixels (a far target stays visible, a near one
/// does not fill the view).
const RING_PX: (f64, f64) = (6.0, 60.0);
/// Half the width of the ring's line, pixels.
const LINE_PX: f64 = 1.3;
/// The hidden ring's dash-and-gap period along the ring, pixels (at least four around it),
/// and the share of it the dash takes (the line's round ends fill some of the gap).
const DASH_PERIOD_PX: f64 = 10.0;
const DASH_SHARE: f64 = 0.4;
/// The off-view arrow's length and its tip's distance from the image's edge, pixels.
const ARROW_PX: f64 = 18.0;
const ARROW_MARGIN_PX: f64 = 6.0;

/// Where the target stands in a view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TargetSight {
    /// Nothing the view shows lies in front of it (the lumen opens towards it, or it lies on
    /// the wall seen): drawn as a solid ring.
    InSight {
        /// Its image position, pixels.
        at: (f64, f64),
        /// Straight distance from the eye, mm.
        distance_mm: f64,
    },
    /// Behind the wall the view shows there: drawn as a dashed, dimmer ring.
    BehindWall {
        /// Its image position, pixels.
        at: (f64, f64),
        /// Straight distance from the eye, mm.
        distance_mm: f64,
    },
    /// Outside the image or behind the camera: an arrow at the image's edge points the way.
    OutOfView {
        /// Straight distance from the eye, mm.
        distance_mm: f64,
    },
}

impl TargetSight {
    /// Where `target_mm` (world mm) stands in `view`.
    pub fn of(view: &SurfaceView<'_>, target_mm: DVec3) -> Self {
        let distance_mm = view.camera.eye_mm().distance(target_mm);
        let at = view.camera.project(target_mm);
        match (view.visibility(target_mm), at) {
            (Visibility::OutOfView, _) | (_, None) => Self::OutOfView { distance_mm },
            (Visibility::Occluded, Some(at)) => Self::BehindWall { at, distance_mm },
            (Visibility::Visible | Visibility::Removed, Some(at)) => {
                Self::InSight { at, distance_mm }
            }
        }
    }

    /// The straight distance from the eye, mm.
    pub fn distance_mm(&self) -> f64 {
        match *self {
            Self::InSight { distance_mm, .. }
            | Self::BehindWall { distance_mm, .. }
            | Self::OutOfView { distance_mm } => distance_mm,
        }
    }
}

/// Draws the target `target_mm` (world mm) into `image`, the picture of `view` (same size):
/// a ring around its image position with its distance from the eye ("target 23.5 mm"; "behind
/// the wall" added when hidden). Returns where it stands.
pub fn draw_target(image: &mut Image, view: &SurfaceView<'_>, target_mm: DVec3) -> TargetSight {
    let sight = TargetSight::of(view, target_mm);
    let (at, color, dashed, caption) = match sight {
        TargetSight::InSight { at, distance_mm } => (
            at,
            TARGET_COLOR,
            false,
            format!("target {distance_mm:.1} mm"),
        ),
        TargetSight::BehindWall { at, distance_mm } => (
            at,
            HIDDEN_TARGET_COLOR,
            true,
            format!("target {distance_mm:.1} mm, behind the wall"),
        ),
        TargetSight::OutOfView { distance_mm } => {
            edge_arrow(image, view, target_mm, distance_mm);
            return sight;
        }
    };
    let radius = ring_radius_px(view, target_mm, at);
    ring(image, at, radius, color, dashed);
    image.disc(at, LINE_PX + 1.0, [0; 3]);
    image.disc(at, LINE_PX, color);
    let scale = label_scale(image, &caption);
    // Above the ring, kept inside the image (below it where the ring touches the top).
    let (width, height) = (
        (text_width(&caption, scale)) as f64,
        (GLYPH_HEIGHT * scale) as f64,
    );
    let above = at.1 - radius - 3.0 - height;
    let top = if above >= 0.0 {
        above
    } else {
        at.1 + radius + 3.0
    };
    let left = (at.0 - radius)
        .min(image.width() as f64 - width - 1.0)
        .max(1.0);
    image.text_shadowed(left as i64, top as i64, &caption, scale, color);
    sight
}

/// An arrow near the image's edge pointing the way to `target_mm` (outside the view), with its
/// distance; nothing when it lies straight behind the camera.
fn edge_arrow(image: &mut Image, view: &SurfaceView<'_>, target_mm: DVec3, distance_mm: f64) {
    let camera = view.camera;
    let to = target_mm - camera.eye_mm();
    let (dx, dy) = (to.dot(camera.right()), -to.dot(camera.up()));
    let length = dx.hypot(dy);
    if length.is_nan() || length <= 1e-9 {
        return;
    }
    let (w, h) = (image.width() as f64, image.height() as f64);
    let reach = 0.5 * w.min(h) - ARROW_MARGIN_PX;
    let along = |r: f64| (0.5 * w + dx / length * r, 0.5 * h + dy / length * r);
    let (tail, tip) = (along(reach - ARROW_PX), along(reach));
    for (radius, color) in [(LINE_PX + 1.0, [0; 3]), (LINE_PX, TARGET_COLOR)] {
        for n in 0..=(2.0 * ARROW_PX) as usize {
            image.disc(along(reach - 0.5 * n as f64), radius, color);
        }
    }
    image.arrow(tail, tip, 0.4 * ARROW_PX, TARGET_COLOR);
    let caption = format!("target {distance_mm:.0} mm");
    let scale = label_scale(image, &caption);
    let (width, height) = (
        text_width(&caption, scale) as f64,
        (GLYPH_HEIGHT * scale) as f64,
    );
    // Centred inside the arrow's tail, clear of it.
    let clear = 0.5 * (width * dx.abs() + height * dy.abs()) / length + 4.0;
    let centre = along(reach - ARROW_PX - clear);
    let left = (centre.0 - 0.5 * width).clamp(1.0, (w - width - 1.0).max(1.0));
    let top = (centre.1 - 0.5 * height).clamp(1.0, (h - height - 1.0).max(1.0));
    image.text_shadowed(left as i64, top as i64, &caption, scale, TARGET_COLOR);
}

/// The font scale of `caption` on `image`: double on images taller than 300 pixels where it
/// fits across, single otherwise.
fn label_scale(image: &Image, caption: &str) -> usize {
    let fits = text_width(caption, 2) + 2 <= image.width();
    if image.height() > 300 && fits {
        2
    } else {
        1
    }
}

/// The radius of the outline of the target's sphere in the image, pixels (within
/// [`RING_PX`]).
pub fn ring_radius_px(view: &SurfaceView<'_>, target_mm: DVec3, at: (f64, f64)) -> f64 {
    let rim = target_mm + view.camera.up() * TARGET_RADIUS_MM;
    let radius = view
        .camera
        .project(rim)
        .map_or(RING_PX.0, |(x, y)| (x - at.0).hypot(y - at.1));
    if radius.is_finite() {
        radius.clamp(RING_PX.0, RING_PX.1)
    } else {
        RING_PX.0
    }
}

/// A ring of `radius` pixels around `centre` with a dark rim; dashed when `dashed`.
fn ring(image: &mut Image, centre: (f64, f64), radius: f64, color: Rgb, dashed: bool) {
    let circumference = std::f64::consts::TAU * radius;
    let steps = (circumference / 0.5).ceil() as usize;
    let periods = (circumference / DASH_PERIOD_PX).round().max(4.0);
    for pass in [(LINE_PX + 1.0, [0; 3]), (LINE_PX, color)] {
        for n in 0..steps {
            let turn = n as f64 / steps as f64;
            if dashed && (turn * periods).fract() >= DASH_SHARE {
                continue;
            }
            let angle = std::f64::consts::TAU * turn;
            let p = (
                centre.0 + radius * angle.cos(),
                centre.1 + radius * angle.sin(),
            );
            image.disc(p, pass.0, pass.1);
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

    use super::*;
    use crate::camera::Camera;
    use crate::phantom::{self, PhantomOptions};
    use crate::render::{Mode, RenderSettings, Renderer};
    use std::sync::Arc;

    /// The fraction of the ring's circle (radius `radius` around `at`) painted `color`.
    fn ring_painted(image: &Image, at: (f64, f64), radius: f64, color: Rgb) -> f64 {
        let samples = 96u32;
        let painted = (0..samples)
            .filter(|&n| {
                let angle = std::f64::consts::TAU * (f64::from(n) + 0.5) / f64::from(samples);
                let (x, y) = (at.0 + radius * angle.cos(), at.1 + radius * angle.sin());
                image.pixel(x as usize, y as usize) == Some(color)
            })
            .count();
        painted as f64 / f64::from(samples)
    }

    /// On the sphere shell (inner wall known exactly), from its centre: a target inside the
    /// cavity is in sight, one beyond the wall behind it; each is drawn where the camera
    /// projects it, solid or dashed.
    #[test]
    fn the_target_is_ringed_where_it_projects_solid_in_sight_and_dashed_behind_the_wall() {
        let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
            size: 48,
            ..PhantomOptions::default()
        });
        let centre = volume.geometry().world_of(shell.centre_vox);
        let spacing = volume.geometry().spacing_mm();
        let settings = RenderSettings {
            mode: Mode::Iso,
            iso_hu: -480.0,
            ..RenderSettings::default()
        };
        let prepared = Arc::new(Renderer::new(volume)).prepare(&settings).unwrap();
        let camera = Camera::look_at(centre, centre + DVec3::Z, DVec3::Y, 90.0, [96, 96]).unwrap();
        let frame = prepared.render(&camera);
        let view = SurfaceView::new(&camera, &frame.depth_mm, spacing);
        let aside = DVec3::new(0.3, -0.2, 1.0).normalize();
        let cases = [
            (shell.inner_radius_vox - 6.0, TARGET_COLOR),
            (shell.outer_radius_vox + 4.0, HIDDEN_TARGET_COLOR),
        ];
        let mut painted = Vec::new();
        for (distance, color) in cases {
            let target = centre + aside * distance;
            let mut image = Image::from_frame(&frame, settings.background).unwrap();
            let sight = draw_target(&mut image, &view, target);
            let at = camera.project(target).unwrap();
            match sight {
                TargetSight::InSight { at: drawn, .. }
                | TargetSight::BehindWall { at: drawn, .. } => {
                    assert!((drawn.0 - at.0).abs() < 1e-9 && (drawn.1 - at.1).abs() < 1e-9);
                }
                TargetSight::OutOfView { .. } => panic!("{sight:?}"),
            }
            assert_eq!(
                color == TARGET_COLOR,
                matches!(sight, TargetSight::InSight { .. })
            );
            assert!((sight.distance_mm() - distance).abs() < 1e-9);
            assert_eq!(image.pixel(at.0 as usize, at.1 as usize), Some(color));
            let radius = ring_radius_px(&view, target, at);
            painted.push(ring_painted(&image, at, radius, color));
        }
        assert!(painted[0] > 0.9, "the ring in sight is solid: {painted:?}");
        assert!(
            (0.3..0.7).contains(&painted[1]),
            "the ring behind the wall is dashed: {painted:?}"
        );
        // Behind the camera and to its right: an arrow at the right edge points the way, its
        // distance beside it (a wider image, so that the caption fits beside the arrow).
        let wide = Camera::look_at(centre, centre + DVec3::Z, DVec3::Y, 90.0, [256, 256]).unwrap();
        let empty = vec![f32::NAN; 256 * 256];
        let view = SurfaceView::new(&wide, &empty, spacing);
        let behind = centre - DVec3::Z * 5.0 + wide.right() * 3.0;
        let mut image = Image::new(256, 256, [0; 3]).unwrap();
        assert!(matches!(
            draw_target(&mut image, &view, behind),
            TargetSight::OutOfView { .. }
        ));
        let marked = |columns: std::ops::Range<usize>| {
            let rows = 0..image.height();
            rows.flat_map(|y| columns.clone().map(move |x| (x, y)))
                .filter(|&(x, y)| image.pixel(x, y) == Some(TARGET_COLOR))
                .count()
        };
        assert!(marked(230..256) > 10 && marked(0..128) == 0);
    }

    /// The caption halves its font where double would run past the image's edge.
    #[test]
    fn a_caption_too_wide_for_double_size_is_written_single() {
        let caption = "target 34.5 mm, behind the wall";
        let scale = |w, h| label_scale(&Image::new(w, h, [0; 3]).unwrap(), caption);
        assert_eq!(scale(512, 512), 2);
        assert_eq!(scale(320, 320), 1, "371 px of text on 320");
        assert_eq!(scale(512, 256), 1, "small images write single");
    }
}
