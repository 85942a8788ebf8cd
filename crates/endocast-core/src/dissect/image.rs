//! The flat image's layout and labels: the wall in a plot area, framed by a millimetre axis
//! along the path (ticks and labels below), the angle around it (left) and the scale in words
//! (top).

use crate::views::{font, Image, Rgb, ViewError};

/// Margins around the plot, pixels: room for the angle labels, the title and the mm axis.
const LEFT: usize = 34;
const TOP: usize = 14;
const RIGHT: usize = 12;
const BOTTOM: usize = 24;
/// Length of a tick mark, pixels.
const TICK: i64 = 4;
/// Fewest pixels between two labelled ticks of the mm axis.
const MIN_TICK_PX: f64 = 48.0;
/// The tick spacings the mm axis picks from, mm.
const TICK_STEPS_MM: [f64; 12] = [
    1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0,
];
/// Background of the margins, of empty pixels in the plot, and the labels' colour.
const MARGIN: Rgb = [0, 0, 0];
/// Pixels whose ray met no wall: dark blue-grey, apart from both the margin and dark wall.
pub(super) const EMPTY: Rgb = [34, 38, 52];
const INK: Rgb = [230, 230, 230];

/// Where the wall sits in the flat image: column `c`, row `r` of the dissection is pixel
/// `(x + c, y + r)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Plot {
    /// Left edge, pixels.
    pub x: usize,
    /// Top edge, pixels.
    pub y: usize,
    /// Columns: one per arc-length step along the path.
    pub columns: usize,
    /// Rows: one per angle step around it.
    pub rows: usize,
}

impl Plot {
    /// The plot of `columns × rows` in its margins.
    pub(super) fn new(columns: usize, rows: usize) -> Self {
        Self {
            x: LEFT,
            y: TOP,
            columns,
            rows,
        }
    }

    /// The whole image's size, pixels (width, height).
    pub fn image_size(&self) -> (usize, usize) {
        (self.x + self.columns + RIGHT, self.y + self.rows + BOTTOM)
    }
}

/// The flat image's scale, as the labels state it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    /// Millimetres of arc length per column.
    pub along_mm_per_px: f64,
    /// Degrees around the path per row.
    pub around_deg_per_px: f64,
    /// Millimetres of wall per row at the median distance from the path to the wall.
    pub around_mm_per_px: f64,
}

/// An image for `plot`, the plot area filled with [`EMPTY`], the margins labelled.
pub(super) fn blank(plot: &Plot, scale: &Scale) -> Result<Image, ViewError> {
    let (width, height) = plot.image_size();
    let mut image = Image::new(width, height, MARGIN)?;
    for y in plot.y..plot.y + plot.rows {
        for x in plot.x..plot.x + plot.columns {
            image.put(x as i64, y as i64, EMPTY);
        }
    }
    title(&mut image, plot, scale);
    along_axis(&mut image, plot, scale.along_mm_per_px);
    around_axis(&mut image, plot);
    Ok(image)
}

/// The scale in words over the plot, e.g. `0.5 mm/PX ALONG, 1 DEG/PX AROUND (0.1 mm AT WALL)`.
fn title(image: &mut Image, plot: &Plot, scale: &Scale) {
    let text = format!(
        "{} mm/px along, {} deg/px around ({} mm at wall)",
        short(scale.along_mm_per_px),
        short(scale.around_deg_per_px),
        short(scale.around_mm_per_px),
    );
    image.text(plot.x as i64, 3, &text, 1, INK);
}

/// Ticks and mm labels under the plot, at round arc lengths from the path's start.
fn along_axis(image: &mut Image, plot: &Plot, mm_per_px: f64) {
    let tick_mm = TICK_STEPS_MM
        .into_iter()
        .find(|t| t / mm_per_px >= MIN_TICK_PX)
        .unwrap_or(TICK_STEPS_MM[TICK_STEPS_MM.len() - 1]);
    let bottom = (plot.y + plot.rows) as i64;
    let length_mm = plot.columns.saturating_sub(1) as f64 * mm_per_px;
    let mut n = 0.0;
    while n * tick_mm <= length_mm {
        let x = plot.x as i64 + (n * tick_mm / mm_per_px).round() as i64;
        image.line(
            (x as f64, bottom as f64),
            (x as f64, (bottom + TICK) as f64),
            INK,
        );
        let label = format!("{}", n * tick_mm);
        let half = (font::text_width(&label, 1) / 2) as i64;
        image.text(x - half, bottom + TICK + 2, &label, 1, INK);
        n += 1.0;
    }
    let unit_x = (plot.x + plot.columns) as i64 - font::text_width("mm", 1) as i64;
    image.text(unit_x, bottom + TICK + 10, "mm", 1, INK);
}

/// Ticks and degree labels left of the plot: 0° is the frames' up vector, 90° their right.
fn around_axis(image: &mut Image, plot: &Plot) {
    for degrees in [0, 90, 180, 270, 360] {
        let y = plot.y as i64 + (f64::from(degrees) / 360.0 * plot.rows as f64).round() as i64;
        let left = plot.x as i64;
        image.line(
            ((left - TICK) as f64, y as f64),
            (left as f64, y as f64),
            INK,
        );
        let label = degrees.to_string();
        let x = left - TICK - 2 - font::text_width(&label, 1) as i64;
        image.text(x, y - font::GLYPH_HEIGHT as i64 / 2, &label, 1, INK);
    }
}

/// A number with at most two decimals and no trailing zeros.
fn short(v: f64) -> String {
    let text = format!("{v:.2}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}
