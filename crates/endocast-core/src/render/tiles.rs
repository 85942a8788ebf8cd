//! The image cut into square tiles, the unit of parallel work, and the frame put together from
//! the tiles' finished pixels.
//!
//! Tiles rather than bands of rows: a frame has about a thousand of them at 512×512, so the
//! threads run out of work together (bands of 16 rows left one thread idle for 4–5 % of a
//! frame), and each tile turns its own rays' results into display pixels, so nothing but a
//! copy per row is left to do after the parallel part.

use super::frame::{Frame, Layers, Premultiplied, RenderStats, DEPTH_LAYERS};
use super::options::{Cancelled, Progress};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

impl Frame {
    /// The bytes a pixel takes at the peak of a render into a frame with `layers`: the frame's
    /// buffers and the tiles' (the finished pixels and, with layers, their optional layers),
    /// every tile being held until the frame is put together from them.
    pub fn rendering_bytes_per_pixel(layers: Layers) -> usize {
        let extra = if layers.is_empty() {
            0
        } else {
            size_of::<Extra>()
        };
        Self::bytes_per_pixel(layers) + size_of::<Pixel>() + extra
    }
}

/// Edge of the square pixel tiles rendered as one task.
pub(crate) const TILE: usize = 16;

/// One finished pixel as the frame stores it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pixel {
    /// Premultiplied colour and transmittance.
    pub color: Premultiplied,
    /// Distance to the first isosurface hit, mm (NaN where none).
    pub depth_mm: f32,
    /// Physical value of MIP/MinIP (NaN otherwise).
    pub value: f32,
}

impl Default for Pixel {
    fn default() -> Self {
        Self {
            color: Premultiplied::default(),
            depth_mm: f32::NAN,
            value: f32::NAN,
        }
    }
}

/// A pixel's optional layers (see [`Layers`]); those not asked for are left NaN.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Extra {
    pub hit_mm: [f32; 3],
    pub normal: [f32; 3],
    pub depths_mm: [f32; DEPTH_LAYERS],
}

impl Default for Extra {
    fn default() -> Self {
        Self {
            hit_mm: [f32::NAN; 3],
            normal: [f32::NAN; 3],
            depths_mm: [f32::NAN; DEPTH_LAYERS],
        }
    }
}

/// A rendered tile: its pixels row by row, their optional layers (empty when none is asked
/// for) and its counters.
#[derive(Debug, Clone, Default)]
pub(crate) struct Tile {
    pub pixels: Vec<Pixel>,
    pub extras: Vec<Extra>,
    pub stats: RenderStats,
}

/// What may stop a render between tiles, and who hears of each finished tile.
#[derive(Clone, Copy, Default)]
pub(crate) struct Control<'a> {
    pub cancel: Option<&'a AtomicBool>,
    pub progress: Option<&'a (dyn Fn(Progress) + Sync)>,
}

impl Control<'_> {
    /// Whether the render was asked to stop.
    #[inline]
    pub fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|flag| flag.load(Ordering::Relaxed))
    }
}

/// The tiles of a `width × height` image, numbered row of tiles by row of tiles.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tiling {
    width: usize,
    height: usize,
    across: usize,
}

/// The pixel rectangle of one tile: columns `x0..x1`, rows `y0..y1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct TileRect {
    pub x0: usize,
    pub x1: usize,
    pub y0: usize,
    pub y1: usize,
}

impl TileRect {
    /// Where pixel `(x, y)` of the image lies in the tile's pixels (row by row).
    pub fn index(&self, x: usize, y: usize) -> usize {
        (x - self.x0) + (self.x1 - self.x0) * (y - self.y0)
    }
}

impl Tiling {
    /// The tiling of an image of `[width, height]` pixels.
    pub fn new([width, height]: [usize; 2]) -> Self {
        Self {
            width,
            height,
            across: width.div_ceil(TILE),
        }
    }

    /// Number of tiles.
    pub fn len(&self) -> usize {
        self.across * self.height.div_ceil(TILE)
    }

    /// The rectangle of tile `index` (edge tiles are cut to the image).
    pub fn rect(&self, index: usize) -> TileRect {
        let (x0, y0) = (index % self.across * TILE, index / self.across * TILE);
        TileRect {
            x0,
            x1: (x0 + TILE).min(self.width),
            y0,
            y1: (y0 + TILE).min(self.height),
        }
    }

    /// Renders every tile with `render` in parallel and puts them together into `frame` (rows
    /// in parallel too), reusing its buffers where they have the size already; `layers` are
    /// the optional layers the tiles hold.
    ///
    /// Each tile first looks at `control`'s cancel flag: once it is set, the tiles not yet
    /// started return at once, and the call returns [`Cancelled`] leaving `frame` as it was.
    /// After each tile the progress callback hears how many are done.
    pub fn render_into(
        &self,
        render: impl Fn(TileRect) -> Tile + Sync,
        frame: &mut Frame,
        layers: Layers,
        control: Control<'_>,
    ) -> Result<(), Cancelled> {
        let total = self.len();
        let done = AtomicUsize::new(0);
        let tiles: Vec<Option<Tile>> = (0..total)
            .into_par_iter()
            .map(|index| {
                if control.cancelled() {
                    return None;
                }
                let tile = render(self.rect(index));
                let finished = done.fetch_add(1, Ordering::Relaxed) + 1;
                if let Some(progress) = control.progress {
                    progress(Progress {
                        done: finished,
                        total,
                    });
                }
                Some(tile)
            })
            .collect();
        let Some(tiles) = tiles.into_iter().collect::<Option<Vec<Tile>>>() else {
            return Err(Cancelled);
        };
        let (width, height) = (self.width, self.height);
        frame.resize([width, height], layers);
        frame
            .color
            .par_chunks_mut(width)
            .zip(frame.depth_mm.par_chunks_mut(width))
            .zip(frame.value.par_chunks_mut(width))
            .enumerate()
            .for_each(|(y, ((color, depth), value))| {
                for (x0, pixels) in self.row(&tiles, y, |tile| &tile.pixels) {
                    for (x, p) in (x0..).zip(pixels) {
                        (color[x], depth[x], value[x]) = (p.color, p.depth_mm, p.value);
                    }
                }
            });
        if !layers.is_empty() {
            self.assemble_extras(&tiles, frame, layers);
        }
        frame.stats = RenderStats::default();
        for tile in &tiles {
            frame.stats.add(&tile.stats);
        }
        Ok(())
    }

    /// Row `y`'s part of each tile in its row of tiles, left to right: the first column and
    /// the tile's items `of` that row.
    fn row<'t, T: 't>(
        &self,
        tiles: &'t [Tile],
        y: usize,
        of: impl Fn(&'t Tile) -> &'t [T] + 't,
    ) -> impl Iterator<Item = (usize, &'t [T])> + 't {
        let width = self.width;
        let row_of_tiles = &tiles[y / TILE * self.across..][..self.across];
        row_of_tiles.iter().enumerate().map(move |(t, tile)| {
            let x0 = t * TILE;
            let w = (x0 + TILE).min(width) - x0;
            (x0, &of(tile)[y % TILE * w..][..w])
        })
    }

    /// The optional layers' part of [`Self::render_into`], a pass per layer asked for.
    fn assemble_extras(&self, tiles: &[Tile], frame: &mut Frame, layers: Layers) {
        if layers.contains(Layers::HIT_POSITION) {
            self.copy_layer(tiles, &mut frame.hit_mm, |e| e.hit_mm);
        }
        if layers.contains(Layers::NORMAL) {
            self.copy_layer(tiles, &mut frame.normal, |e| e.normal);
        }
        if layers.contains(Layers::DEPTHS) {
            self.copy_layer(tiles, &mut frame.layer_depths_mm, |e| e.depths_mm);
        }
    }

    /// Puts one optional layer of the tiles together into `layer` (rows in parallel).
    fn copy_layer<T: Send>(
        &self,
        tiles: &[Tile],
        layer: &mut [T],
        of: impl Fn(&Extra) -> T + Sync,
    ) {
        layer
            .par_chunks_mut(self.width)
            .enumerate()
            .for_each(|(y, row)| {
                for (x0, extras) in self.row(tiles, y, |tile| &tile.extras) {
                    for (x, e) in (x0..).zip(extras) {
                        row[x] = of(e);
                    }
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_odd_images_once_and_assemble_in_place() {
        for size in [[1, 1], [16, 16], [17, 5], [40, 33]] {
            let tiling = Tiling::new(size);
            let mut covered = vec![0u8; size[0] * size[1]];
            let mut frame = Frame::default();
            let rendered = tiling.render_into(
                |r| {
                    let mut tile = Tile::default();
                    for y in r.y0..r.y1 {
                        for x in r.x0..r.x1 {
                            tile.pixels.push(Pixel {
                                depth_mm: (x + 1000 * y) as f32,
                                ..Pixel::default()
                            });
                        }
                    }
                    tile.stats.rays = tile.pixels.len() as u64;
                    tile
                },
                &mut frame,
                Layers::NONE,
                Control::default(),
            );
            assert_eq!(rendered, Ok(()));
            for index in 0..tiling.len() {
                let r = tiling.rect(index);
                for y in r.y0..r.y1 {
                    for x in r.x0..r.x1 {
                        covered[x + size[0] * y] += 1;
                    }
                }
            }
            assert!(covered.iter().all(|&c| c == 1), "{size:?}");
            assert_eq!(frame.stats.rays, (size[0] * size[1]) as u64);
            for (i, d) in frame.depth_mm.iter().enumerate() {
                let (x, y) = (i % size[0], i / size[0]);
                assert_eq!(*d, (x + 1000 * y) as f32, "{size:?}");
            }
        }
    }
}
