//! Annotations as decals on a view's image: only where the view shows the surface they were
//! drawn on.

use super::{Annotation, Shape, SurfaceView, Visibility};
use crate::views::font::GLYPH_HEIGHT;
use crate::views::Image;
use glam::DVec3;

/// How annotations are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrawOptions {
    /// Half the width of strokes and measurement lines, pixels. Default 1.2.
    pub line_radius_px: f64,
    /// Radius of a point's dot and a measurement's ends, pixels. Default 3.
    pub dot_radius_px: f64,
    /// Font pixels per glyph pixel; 0 picks 1 for images up to 300 pixels high, else 2.
    pub text_scale: usize,
}

impl Default for DrawOptions {
    fn default() -> Self {
        Self {
            line_radius_px: 1.2,
            dot_radius_px: 3.0,
            text_scale: 0,
        }
    }
}

/// Draws `annotations` into `image` (the picture of `view`, same size) where `view` shows
/// their surface; returns how many were drawn at least in part.
pub fn draw<'a>(
    image: &mut Image,
    view: &SurfaceView<'_>,
    annotations: impl IntoIterator<Item = &'a Annotation>,
    options: &DrawOptions,
) -> usize {
    let scale = match options.text_scale {
        0 if image.height() <= 300 => 1,
        0 => 2,
        s => s,
    };
    let pen = Pen {
        view,
        options,
        scale,
    };
    annotations
        .into_iter()
        .filter(|a| pen.annotation(image, a))
        .count()
}

/// What every decal is drawn with.
struct Pen<'v, 'a> {
    view: &'v SurfaceView<'a>,
    options: &'v DrawOptions,
    scale: usize,
}

impl Pen<'_, '_> {
    /// The image position of `p_mm` where the view shows it.
    fn seen(&self, p_mm: DVec3) -> Option<(f64, f64)> {
        (self.view.visibility(p_mm) == Visibility::Visible)
            .then(|| self.view.camera.project(p_mm))
            .flatten()
    }

    /// Draws one annotation; true when any part of it showed.
    fn annotation(&self, image: &mut Image, a: &Annotation) -> bool {
        let shown: Vec<Option<(f64, f64)>> = match &a.shape {
            Shape::Point(p) => vec![self.seen(*p)],
            Shape::Stroke(points) => points.iter().map(|p| self.seen(*p)).collect(),
            Shape::Distance(p, q) => vec![self.seen(*p), self.seen(*q)],
        };
        if shown.iter().all(Option::is_none) {
            return false;
        }
        match &a.shape {
            Shape::Stroke(_) => self.polyline(image, &shown, a.color),
            Shape::Point(_) => self.dots(image, &shown, a.color),
            Shape::Distance(..) => {
                self.polyline(image, &shown, a.color);
                self.dots(image, &shown, a.color);
            }
        }
        let caption = a.caption();
        let anchor = self.view.camera.project(a.anchor());
        let anchored = matches!(a.shape, Shape::Distance(..)) && shown.iter().all(Option::is_some);
        let at = if anchored {
            anchor
        } else {
            shown.iter().flatten().next().copied()
        };
        if let (false, Some((x, y))) = (caption.is_empty(), at) {
            let gap = self.options.dot_radius_px + 2.0;
            let top = y - gap - (GLYPH_HEIGHT * self.scale) as f64;
            image.text_shadowed((x + gap) as i64, top as i64, &caption, self.scale, a.color);
        }
        true
    }

    /// Thick segments between consecutive shown points (a stroke is broken where it is hidden).
    fn polyline(&self, image: &mut Image, shown: &[Option<(f64, f64)>], color: [u8; 3]) {
        for pair in shown.windows(2) {
            if let [Some(a), Some(b)] = pair {
                let steps = ((b.0 - a.0).hypot(b.1 - a.1) / 0.5)
                    .ceil()
                    .clamp(1.0, 4096.0) as usize;
                for n in 0..=steps {
                    let t = n as f64 / steps as f64;
                    let p = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
                    image.disc(p, self.options.line_radius_px, color);
                }
            }
        }
        if let [Some(only)] = shown {
            image.disc(*only, self.options.line_radius_px, color);
        }
    }

    /// A dot with a dark rim at every shown point.
    fn dots(&self, image: &mut Image, shown: &[Option<(f64, f64)>], color: [u8; 3]) {
        let r = self.options.dot_radius_px;
        for p in shown.iter().flatten() {
            image.disc(*p, r + 1.0, [0; 3]);
            image.disc(*p, r, color);
        }
    }
}
