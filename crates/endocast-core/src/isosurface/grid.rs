//! Flying edges' first pass, a slab of planes at a time: which voxels of a box of the volume are
//! inside, one byte each, and for every row of voxels along `i` the span of its crossed `i`
//! edges (the trim that lets the later passes skip the stretches of a row where nothing
//! crosses). A slab's flags stay in the cache while the later passes read them and its voxels.

use crate::navigate::Lumen;
use crate::Volume;
use std::ops::{Range, RangeInclusive};

/// Which voxels lie inside the surface.
pub(super) enum Inside<'a> {
    /// The voxels whose stored value lies in this range (stored values map linearly to
    /// physical ones, so one side of an isovalue is one range of them).
    Values(RangeInclusive<u16>),
    /// The voxels of a lumen.
    Lumen(&'a Lumen),
}

/// The crossed edges along one row: how many, and the span of their positions (edge `i` joins
/// voxels `i` and `i + 1`); an empty span is `n - 1 .. 0` so that unions are a min and a max.
#[derive(Debug, Clone, Copy)]
pub(super) struct Span {
    /// How many edges are crossed.
    pub count: u32,
    /// The first crossed edge.
    pub first: u32,
    /// One past the last crossed edge.
    pub end: u32,
}

impl Span {
    /// No crossed edge in a row of `n` voxels.
    fn none(n: usize) -> Self {
        Self {
            count: 0,
            first: (n - 1) as u32,
            end: 0,
        }
    }
}

/// A slab of planes of a box of the volume with its voxels' inside flags, rows of `i` stored
/// one after another; loaded slab after slab into the same buffers.
pub(super) struct Grid<'a> {
    /// The volume.
    pub volume: &'a Volume,
    /// Which voxels are inside.
    inside: &'a Inside<'a>,
    /// The slab's lowest voxel in the volume.
    pub lo: [usize; 3],
    /// The slab's size in voxels (at least 2 along `i` and `j`; its planes along `k`).
    pub dims: [usize; 3],
    /// 1 for an inside voxel, 0 for an outside one.
    flags: Vec<u8>,
    /// The crossed `i` edges of each row (`j + ny·k`).
    spans: Vec<Span>,
}

impl<'a> Grid<'a> {
    /// An empty grid over the rows of `i` of the box at `lo` with `dims[0]` by `dims[1]` voxels
    /// a plane; [`Grid::load`] fills its planes.
    pub fn new(
        volume: &'a Volume,
        inside: &'a Inside<'a>,
        lo: [usize; 3],
        dims: [usize; 2],
    ) -> Self {
        Self {
            volume,
            inside,
            lo,
            dims: [dims[0], dims[1], 0],
            flags: Vec::new(),
            spans: Vec::new(),
        }
    }

    /// Classifies the `planes` planes from volume plane `k0` on. When the slab starts at the
    /// last plane of the one before, that plane's flags are moved rather than classified again.
    pub fn load(&mut self, k0: usize, planes: usize) {
        let [nx, ny, old] = self.dims;
        let carried = usize::from(old > 0 && self.lo[2] + old - 1 == k0 && planes > 0);
        if carried == 1 {
            self.flags
                .copy_within((old - 1) * nx * ny..old * nx * ny, 0);
            self.spans.copy_within((old - 1) * ny..old * ny, 0);
        }
        self.flags.resize(planes * nx * ny, 0);
        self.spans.resize(planes * ny, Span::none(nx));
        self.lo[2] = k0;
        self.dims[2] = planes;
        let (volume, inside, lo) = (self.volume, self.inside, self.lo);
        let flag_planes = self
            .flags
            .chunks_mut(nx * ny)
            .zip(self.spans.chunks_mut(ny));
        for (k, (plane, spans)) in flag_planes.enumerate().skip(carried) {
            for (j, (row, span)) in plane.chunks_mut(nx).zip(spans).enumerate() {
                classify(volume, [lo[0], lo[1] + j, lo[2] + k], inside, row);
                *span = span_of(row);
            }
        }
    }

    /// The flags of row `(j, k)` (`k` counted from the slab's first plane).
    pub fn row(&self, j: usize, k: usize) -> &[u8] {
        let nx = self.dims[0];
        &self.flags[(j + self.dims[1] * k) * nx..][..nx]
    }

    /// The crossed `i` edges of row `(j, k)`.
    pub fn span(&self, j: usize, k: usize) -> Span {
        self.spans[j + self.dims[1] * k]
    }

    /// The four rows around the row of cubes `(j, k)`, as `[dy + 2·dz]`.
    pub fn cube_rows(&self, j: usize, k: usize) -> CubeRow<'_> {
        CubeRow {
            rows: [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dy, dz)| self.row(j + dy, k + dz)),
            spans: [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dy, dz)| self.span(j + dy, k + dz)),
        }
    }
}

/// The four rows of voxels around a row of cubes.
pub(super) struct CubeRow<'g> {
    rows: [&'g [u8]; 4],
    spans: [Span; 4],
}

impl CubeRow<'_> {
    /// The inside bits of column `i` at the places its corners take in a cube's case (corner
    /// `dx + 2·dy + 4·dz` at `dx = 0`).
    #[inline]
    fn column(&self, i: usize) -> u8 {
        let r = &self.rows;
        r[0][i] | r[1][i] << 2 | r[2][i] << 4 | r[3][i] << 6
    }

    /// The case of cube `i` (bit `c` set: corner `c` inside).
    #[inline]
    fn case(&self, i: usize) -> u8 {
        self.column(i) | self.column(i + 1) << 1
    }

    /// The cases of the cubes of `range` that the surface cuts, in order (stretches of eight
    /// cubes whose corners are all inside or all outside are passed over at once).
    pub fn cut(&self, range: Range<usize>) -> impl Iterator<Item = u8> + '_ {
        let mut i = range.start;
        std::iter::from_fn(move || {
            while i < range.end {
                if i + 8 <= range.end && self.uniform8(i) {
                    i += 8;
                    continue;
                }
                let case = self.case(i);
                i += 1;
                if case != 0 && case != 0xff {
                    return Some(case);
                }
            }
            None
        })
    }

    /// True when the corners of cubes `i .. i + 8` (columns `i ..= i + 8`) are all alike.
    fn uniform8(&self, i: usize) -> bool {
        let word = |r: &[u8]| {
            let mut bytes = [0u8; 8];
            bytes.copy_from_slice(&r[i..i + 8]);
            u64::from_le_bytes(bytes)
        };
        let first = word(self.rows[0]);
        let alike = matches!(first, 0 | 0x0101_0101_0101_0101);
        alike
            && self.rows[1..].iter().all(|r| word(r) == first)
            && self.rows.iter().all(|r| r[i + 8] == self.rows[0][i])
    }

    /// The cubes that may be cut: outside this range each of the four rows is constant, and all
    /// four are alike.
    pub fn trim(&self) -> Range<usize> {
        let last = self.rows[0].len() - 1;
        let uniform = |i: usize| matches!(self.column(i), 0 | 0b0101_0101);
        let first = self.spans.iter().map(|s| s.first as usize).min();
        let end = self.spans.iter().map(|s| s.end as usize).max();
        let lo = if uniform(0) { first.unwrap_or(0) } else { 0 };
        let hi = if uniform(last) {
            end.unwrap_or(0)
        } else {
            last
        };
        lo..hi.max(lo)
    }
}

/// Writes the inside flags of the row starting at voxel `start` into `row`.
fn classify(volume: &Volume, start: [usize; 3], inside: &Inside, row: &mut [u8]) {
    match inside {
        Inside::Values(range) => {
            let [nx, ny, _] = volume.dims();
            let at = start[0] + nx * (start[1] + ny * start[2]);
            let (lo, hi) = (*range.start(), *range.end());
            for (flag, &s) in row.iter_mut().zip(&volume.voxels()[at..]) {
                *flag = u8::from(s >= lo && s <= hi);
            }
        }
        Inside::Lumen(lumen) => {
            for (i, flag) in row.iter_mut().enumerate() {
                *flag = u8::from(lumen.contains([start[0] + i, start[1], start[2]]));
            }
        }
    }
}

/// The crossed edges of a row of flags.
fn span_of(row: &[u8]) -> Span {
    if row.iter().all(|&f| f == row[0]) {
        return Span::none(row.len());
    }
    let crossed = |w: &[u8]| w[0] != w[1];
    let count = differences(&row[1..], row);
    let first = row.windows(2).position(crossed).unwrap_or(row.len() - 1);
    let end = row.windows(2).rposition(crossed).map_or(0, |i| i + 1);
    Span {
        count: count as u32,
        first: first as u32,
        end: end as u32,
    }
}

/// How many places two rows of flags differ at (a sum of exclusive ors, which vectorises).
pub(super) fn differences(a: &[u8], b: &[u8]) -> usize {
    let sum: u32 = a.iter().zip(b).map(|(x, y)| u32::from(x ^ y)).sum();
    sum as usize
}
