//! Flying edges' first pass, a slab of planes at a time: which voxels of a box of the volume are
//! inside, one bit each, rows of `i` in 64-bit words. A row's crossed edges (to the next voxel
//! of the row, row or plane) are then the set bits of an exclusive or, counted by `count_ones`
//! and visited without looking at the voxels between them; the cubes the surface cuts are found
//! the same way. A slab's bits and voxels stay in the cache while the later passes read them.

use crate::navigate::Lumen;
use crate::Volume;
use std::ops::RangeInclusive;

/// Which voxels lie inside the surface.
pub(super) enum Inside<'a> {
    /// The voxels whose stored value lies in this range (stored values map linearly to
    /// physical ones, so one side of an isovalue is one range of them).
    Values(RangeInclusive<u16>),
    /// The voxels of a lumen.
    Lumen(&'a Lumen),
}

/// A slab of planes of a box of the volume with its voxels' inside bits (bit `i % 64` of word
/// `i / 64` of a row; the bits past the row's end are 0); loaded slab after slab into the same
/// buffer.
pub(super) struct Grid<'a> {
    /// The volume.
    pub volume: &'a Volume,
    /// Which voxels are inside.
    inside: &'a Inside<'a>,
    /// The slab's lowest voxel in the volume.
    pub lo: [usize; 3],
    /// The slab's size in voxels (at least 2 along `i` and `j`; its planes along `k`).
    pub dims: [usize; 3],
    /// Words a row.
    words: usize,
    /// The bits, rows `j + ny·k` one after another.
    bits: Vec<u64>,
    /// One row's inside flags, a byte each, before they are packed into bits.
    flags: Vec<u8>,
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
            words: dims[0].div_ceil(64),
            bits: Vec::new(),
            flags: vec![0; dims[0].next_multiple_of(8)],
        }
    }

    /// Classifies the `planes` planes from volume plane `k0` on. When the slab starts at the
    /// last plane of the one before, that plane's bits are moved rather than classified again.
    pub fn load(&mut self, k0: usize, planes: usize) {
        let [nx, ny, old] = self.dims;
        let plane = self.words * ny;
        let carried = usize::from(old > 0 && self.lo[2] + old - 1 == k0 && planes > 0);
        if carried == 1 {
            self.bits.copy_within((old - 1) * plane..old * plane, 0);
        }
        self.bits.resize(planes * plane, 0);
        self.lo[2] = k0;
        self.dims[2] = planes;
        let (volume, inside, lo, words) = (self.volume, self.inside, self.lo, self.words);
        let rows = self.bits.chunks_mut(words).enumerate().skip(carried * ny);
        for (r, row) in rows {
            let flags = &mut self.flags[..nx];
            classify(
                volume,
                [lo[0], lo[1] + r % ny, lo[2] + r / ny],
                inside,
                flags,
            );
            pack(&self.flags, row);
        }
    }

    /// The bits of row `(j, k)` (`k` counted from the slab's first plane).
    pub fn row(&self, j: usize, k: usize) -> &[u64] {
        &self.bits[(j + self.dims[1] * k) * self.words..][..self.words]
    }

    /// The four rows around the row of cubes `(j, k)`, as `[dy + 2·dz]`.
    pub fn cube_rows(&self, j: usize, k: usize) -> CubeRow<'_> {
        CubeRow {
            rows: [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dy, dz)| self.row(j + dy, k + dz)),
            n: self.dims[0],
        }
    }
}

/// Word `w` of the crossed edges along a row of `n` bits: bit `i` set when voxels `i` and
/// `i + 1` differ.
pub(super) fn along(row: &[u64], n: usize, w: usize) -> u64 {
    let next = row.get(w + 1).map_or(0, |&x| x << 63);
    (row[w] ^ (row[w] >> 1 | next)) & below(n - 1, w)
}

/// Word `w` of a mask of the bits below `n`.
fn below(n: usize, w: usize) -> u64 {
    match n.saturating_sub(64 * w) {
        0 => 0,
        m if m >= 64 => !0,
        m => (1 << m) - 1,
    }
}

/// How many bits are set in the words `word(0 .. words)`.
pub(super) fn count(words: usize, word: impl Fn(usize) -> u64) -> u32 {
    (0..words).map(|w| word(w).count_ones()).sum()
}

/// Calls `f` with every set bit of the words `word(0 .. words)`, in order.
pub(super) fn for_each_one(words: usize, word: impl Fn(usize) -> u64, mut f: impl FnMut(usize)) {
    for w in 0..words {
        let mut bits = word(w);
        while bits != 0 {
            f(64 * w + bits.trailing_zeros() as usize);
            bits &= bits - 1;
        }
    }
}

/// The four rows of voxels around a row of cubes.
pub(super) struct CubeRow<'g> {
    rows: [&'g [u64]; 4],
    /// Voxels a row.
    n: usize,
}

impl CubeRow<'_> {
    /// The cases of the cubes that the surface cuts, in order (bit `c` of a case set: corner
    /// `c` inside; corner `dx + 2·dy + 4·dz`).
    pub fn cut(&self) -> impl Iterator<Item = u8> + '_ {
        (0..self.rows[0].len()).flat_map(move |w| {
            let mut cubes = self.cut_word(w);
            std::iter::from_fn(move || {
                let i = 64 * w + cubes.trailing_zeros() as usize;
                cubes &= cubes.wrapping_sub(1);
                (i < 64 * (w + 1)).then(|| self.case(i))
            })
        })
    }

    /// Word `w` of the cut cubes: cube `i` is cut unless its eight corners (columns `i` and
    /// `i + 1` of the four rows) are alike.
    fn cut_word(&self, w: usize) -> u64 {
        let [a, b, c, d] = self.rows;
        let mixed = |w: usize| (a[w] ^ b[w]) | (a[w] ^ c[w]) | (a[w] ^ d[w]);
        let next = if w + 1 < a.len() {
            mixed(w + 1) << 63
        } else {
            0
        };
        let m = mixed(w);
        (m | m >> 1 | next | along(a, self.n, w)) & below(self.n - 1, w)
    }

    /// The case of cube `i`.
    fn case(&self, i: usize) -> u8 {
        let (w, b) = (i / 64, i % 64);
        let pair = |row: &[u64]| {
            let high = if b == 63 { row[w + 1] << 1 } else { 0 };
            ((row[w] >> b | high) & 3) as u8
        };
        let [a, b2, c, d] = self.rows.map(pair);
        a | b2 << 2 | c << 4 | d << 6
    }
}

/// Writes the inside flags (0 or 1) of the row starting at voxel `start` into `row`.
fn classify(volume: &Volume, start: [usize; 3], inside: &Inside, row: &mut [u8]) {
    match inside {
        Inside::Values(range) => {
            let [nx, ny, _] = volume.dims();
            let at = start[0] + nx * (start[1] + ny * start[2]);
            let (lo, width) = (*range.start(), range.end().wrapping_sub(*range.start()));
            for (flag, &s) in row.iter_mut().zip(&volume.voxels()[at..]) {
                *flag = u8::from(s.wrapping_sub(lo) <= width);
            }
        }
        Inside::Lumen(lumen) => {
            for (i, flag) in row.iter_mut().enumerate() {
                *flag = u8::from(lumen.contains([start[0] + i, start[1], start[2]]));
            }
        }
    }
}

/// Packs flags (0 or 1, a byte each; a multiple of eight, zero past the row) into `bits`.
fn pack(flags: &[u8], bits: &mut [u64]) {
    bits.fill(0);
    for (n, eight) in flags.chunks_exact(8).enumerate() {
        let word = u64::from_le_bytes(eight.try_into().unwrap_or_default());
        // Moves byte b's low bit to bit 56 + b, without carries (bytes are 0 or 1).
        let byte = word.wrapping_mul(0x0102_0408_1020_4080) >> 56;
        bits[n / 8] |= byte << (8 * (n % 8));
    }
}
