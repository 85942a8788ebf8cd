//! The image cut into square tiles, the unit of parallel work, and the frame put together from
//! the tiles' finished pixels.
//!
//! Tiles rather than bands of rows: a frame has about a thousand of them at 512×512, so the
//! threads run out of work together (bands of 16 rows left one thread idle for 4–5 % of a
//! frame), and each tile turns its own rays' results into display pixels, so nothing but a
//! copy per row is left to do after the parallel part.

use super::frame::{Frame, RenderStats};
use rayon::prelude::*;

/// Edge of the square pixel tiles rendered as one task.
pub(crate) const TILE: usize = 16;

/// One finished pixel as the frame stores it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Pixel {
    /// 8-bit colour over the background.
    pub rgb: [u8; 3],
    /// Accumulated opacity.
    pub alpha: f32,
    /// Distance to the first isosurface hit, mm (NaN where none).
    pub depth_mm: f32,
    /// Physical value of MIP/MinIP (NaN otherwise).
    pub value: f32,
}

/// A rendered tile: its pixels row by row, and its counters.
#[derive(Debug, Clone, Default)]
pub(crate) struct Tile {
    pub pixels: Vec<Pixel>,
    pub stats: RenderStats,
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
    /// in parallel too), reusing its buffers where they have the size already.
    pub fn render_into(&self, render: impl Fn(TileRect) -> Tile + Sync, frame: &mut Frame) {
        let tiles: Vec<Tile> = (0..self.len())
            .into_par_iter()
            .map(|index| render(self.rect(index)))
            .collect();
        let (width, height) = (self.width, self.height);
        (frame.width, frame.height) = (width, height);
        frame.rgb.resize(3 * width * height, 0);
        for buffer in [&mut frame.alpha, &mut frame.depth_mm, &mut frame.value] {
            buffer.resize(width * height, 0.0);
        }
        frame
            .rgb
            .par_chunks_mut(3 * width)
            .zip(frame.alpha.par_chunks_mut(width))
            .zip(frame.depth_mm.par_chunks_mut(width))
            .zip(frame.value.par_chunks_mut(width))
            .enumerate()
            .for_each(|(y, (((rgb, alpha), depth), value))| {
                // This row's part of each tile in its row of tiles, left to right.
                let row_of_tiles = &tiles[y / TILE * self.across..][..self.across];
                for (t, tile) in row_of_tiles.iter().enumerate() {
                    let x0 = t * TILE;
                    let w = (x0 + TILE).min(width) - x0;
                    let pixels = &tile.pixels[y % TILE * w..][..w];
                    for (x, p) in (x0..).zip(pixels) {
                        rgb[3 * x..3 * x + 3].copy_from_slice(&p.rgb);
                        (alpha[x], depth[x], value[x]) = (p.alpha, p.depth_mm, p.value);
                    }
                }
            });
        frame.stats = RenderStats::default();
        for tile in &tiles {
            frame.stats.add(&tile.stats);
        }
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
            tiling.render_into(
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
            );
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
