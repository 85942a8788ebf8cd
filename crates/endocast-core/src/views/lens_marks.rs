//! The marks an all-round view needs to be read: the unfolded cube's six faces outlined and
//! labelled (front, left, right, up, down, back; the cross's empty cells stay background), the
//! panorama's directions named along its top edge (back at both edges: the seam). Every front
//! end draws them with [`draw`] (or [`draw_rgba`] on an RGBA buffer), so `render`, `fly`, the
//! workstation and Python show the same picture. Other projections get no marks.

use super::{Image, Rgb};
use crate::camera::{panorama, Camera, CubeLayout, Face, Projection};

/// The labels' colour.
const LABEL_COLOR: Rgb = [255, 220, 0];
/// The face outlines' colour, and how much of it covers the rendered pixel under it.
const FRAME_COLOR: (Rgb, f32) = ([200, 200, 200], 0.6);
/// Pixels between a label and its face's corner (or the panorama's top edge).
const MARGIN_PX: i64 = 3;

/// Draws `camera`'s marks into `image`, the picture `camera` took (same size); nothing for a
/// projection without marks.
pub fn draw(image: &mut Image, camera: &Camera) {
    if camera.size() != [image.width(), image.height()] {
        return;
    }
    match camera.projection() {
        Projection::Cube => cube(image, &CubeLayout::new(camera.size())),
        Projection::Panorama => panorama_labels(image),
        _ => {}
    }
}

/// [`draw`] on a `width · height · 4` RGBA buffer (row 0 at the top): the pixels where the
/// lens forms no ray (the cube's empty cells) become transparent, alpha 0 (a PNG written from
/// RGB alone shows the background there); then every pixel a mark covers takes its colour and
/// becomes opaque.
pub fn draw_rgba(rgba: &mut [u8], camera: &Camera) {
    if !camera.projection().is_all_round() {
        return;
    }
    let [w, h] = camera.size();
    if rgba.len() != 4 * w * h {
        return;
    }
    for (n, pixel) in rgba.chunks_exact_mut(4).enumerate() {
        let (x, y) = ((n % w) as f64 + 0.5, (n / w) as f64 + 0.5);
        if camera.ray(x, y).is_none() {
            pixel[3] = 0;
        }
    }
    Image::draw_on_rgba(rgba, [w, h], |image| draw(image, camera));
}

/// Font pixels per glyph pixel for labels on a view `edge_px` pixels across.
fn text_scale(edge_px: f64) -> usize {
    if edge_px < 200.0 {
        1
    } else {
        2
    }
}

/// The cube's face outlines and labels.
fn cube(image: &mut Image, layout: &CubeLayout) {
    let scale = text_scale(layout.face_px);
    for face in Face::ALL {
        let (x0, y0) = layout.corner(face);
        let (x0, y0) = (x0.round() as i64, y0.round() as i64);
        let edge = layout.face_px.round() as i64;
        outline(image, (x0, y0), edge);
        let label = face.name().to_uppercase();
        image.text_shadowed(x0 + MARGIN_PX, y0 + MARGIN_PX, &label, scale, LABEL_COLOR);
    }
}

/// The one-pixel outline of the `edge × edge` square whose top-left pixel is `corner`, blended
/// over the image.
fn outline(image: &mut Image, (x0, y0): (i64, i64), edge: i64) {
    let (color, amount) = FRAME_COLOR;
    let (x1, y1) = (x0 + edge - 1, y0 + edge - 1);
    for t in 0..edge {
        for (x, y) in [(x0 + t, y0), (x0 + t, y1), (x0, y0 + t), (x1, y0 + t)] {
            image.blend(x, y, color, amount);
        }
    }
}

/// The panorama's direction names along its top edge: each centred on its longitude, the
/// seam's "back" at both edges.
fn panorama_labels(image: &mut Image) {
    let width = image.width();
    let scale = text_scale(image.height() as f64);
    let y = MARGIN_PX;
    for (name, degrees) in [("LEFT", -90.0), ("FRONT", 0.0), ("RIGHT", 90.0)] {
        let centre = panorama::column_of(degrees, width);
        let half = (super::font::text_width(name, scale) / 2) as f64;
        image.text_shadowed((centre - half).round() as i64, y, name, scale, LABEL_COLOR);
    }
    let back_width = super::font::text_width("BACK", scale) as i64;
    image.text_shadowed(MARGIN_PX, y, "BACK", scale, LABEL_COLOR);
    let right = width as i64 - MARGIN_PX - back_width;
    image.text_shadowed(right, y, "BACK", scale, LABEL_COLOR);
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn camera(projection: Projection, field: f64, size: [usize; 2]) -> Camera {
        Camera::look_at(DVec3::ZERO, DVec3::X, DVec3::Z, 90.0, size)
            .unwrap()
            .with_projection(projection, field)
            .unwrap()
    }

    #[test]
    fn the_cubes_empty_cells_become_transparent_and_its_faces_stay_opaque() {
        let cube = camera(Projection::Cube, 90.0, [96, 72]);
        let mut rgba = vec![7; 96 * 72 * 4];
        draw_rgba(&mut rgba, &cube);
        let alpha = |x: usize, y: usize| rgba[4 * (x + 96 * y) + 3];
        // The cross's corners are empty; the front face (second row, second column) is not.
        for (x, y) in [(0, 0), (23, 23), (95, 0), (0, 71), (95, 71)] {
            assert_eq!(alpha(x, y), 0, "{x},{y}");
        }
        for (x, y) in [(36, 36), (12, 36), (84, 36), (36, 12), (36, 60)] {
            assert_ne!(alpha(x, y), 0, "{x},{y}");
        }
        // The panorama has a ray at every pixel: nothing becomes transparent.
        let panorama = camera(Projection::Panorama, 180.0, [48, 24]);
        let mut rgba = vec![7; 48 * 24 * 4];
        draw_rgba(&mut rgba, &panorama);
        assert!(rgba.chunks_exact(4).all(|p| p[3] != 0));
    }
}
