//! The lumen: the 6-connected region of voxels around a seed whose value lies on the lumen side
//! of a threshold (air in a colon or airway, contrast in a vessel, CSF in a ventricle).
//!
//! A [`Lumen`] keeps one bit per voxel of its own bounding box, not of the volume: a colon in a
//! 512 × 512 × 478 abdomen needs about 4 MB. The flood fill that finds it is a scanline fill
//! (one stack entry per run of voxels along `i`, not per voxel) with a one-bit-per-voxel visited
//! set over the volume, so its memory is bounded by `voxels / 8` bytes plus the stack of runs.

use super::bit_grid::BitGrid;
use super::error::{check_finite, NavError};
pub use super::side::LumenSide;
use crate::{ValueMap, Volume};

/// A lumen touching more faces of the volume than this leaks (see [`Lumen::leak`]).
pub const LEAK_FACES: usize = 3;
/// A lumen holding more than this fraction of the volume leaks (see [`Lumen::leak`]).
pub const LEAK_FRACTION: f64 = 0.25;

/// Which stored values lie on the lumen side: a table over all 65 536 `u16` values, so the fill
/// compares nothing and any value map (even a negative scale) is handled alike.
struct ValueTest {
    table: Vec<bool>,
}

impl ValueTest {
    fn new(map: ValueMap, threshold: f64, side: LumenSide) -> Self {
        let table = (0..=u16::MAX)
            .map(|s| side.holds(map.physical(s), threshold))
            .collect();
        Self { table }
    }

    #[inline]
    fn holds(&self, stored: u16) -> bool {
        self.table[usize::from(stored)]
    }

    /// The test on the voxel at each linear index of `volume`.
    fn on<'a>(&'a self, volume: &'a Volume) -> impl Fn(usize) -> bool + 'a {
        let voxels = volume.voxels();
        move |n| self.holds(voxels[n])
    }
}

/// What one flood fill found: its seed, size and inclusive bounding box.
#[derive(Debug, Clone, Copy)]
struct Component {
    seed: [usize; 3],
    count: usize,
    lo: [usize; 3],
    hi: [usize; 3],
}

impl Component {
    fn touches_border(&self, dims: [usize; 3]) -> bool {
        (0..3).any(|a| self.lo[a] == 0 || self.hi[a] + 1 == dims[a])
    }
}

/// The 6-connected lumen component around a seed voxel.
#[derive(Debug, Clone, PartialEq)]
pub struct Lumen {
    /// Lowest voxel index of the bounding box.
    lo: [usize; 3],
    /// The component's voxels, relative to `lo`.
    mask: BitGrid,
    count: usize,
    volume_dims: [usize; 3],
    seed: [usize; 3],
    threshold: f64,
    side: LumenSide,
}

impl Lumen {
    /// The component of voxels 6-connected to `seed` whose physical value lies on `side` of
    /// `threshold` (HU for CT). Errors: a NaN/infinite threshold, a seed outside the volume, a
    /// seed whose own value is on the wall side.
    pub fn from_seed(
        volume: &Volume,
        seed: [usize; 3],
        threshold: f64,
        side: LumenSide,
    ) -> Result<Self, NavError> {
        check_seed(volume, seed, threshold, side, || true)?;
        let dims = volume.dims();
        let test = ValueTest::new(volume.value_map(), threshold, side);
        let mut visited = BitGrid::new(dims);
        let component = fill(dims, test.on(volume), seed, &mut visited);
        Ok(Self::from_visited(
            &visited, component, dims, threshold, side,
        ))
    }

    /// The component of `seed` among the voxels on `side` of `threshold` that `allowed` (one bit
    /// per voxel of the volume) also holds: a structure cut out of a lumen that, grown on the
    /// threshold alone, would join its neighbours (the aorta out of everything above 130 HU).
    /// Errors as [`Lumen::from_seed`]; a seed outside `allowed` is in the wall.
    pub(crate) fn within(
        volume: &Volume,
        seed: [usize; 3],
        threshold: f64,
        side: LumenSide,
        allowed: &BitGrid,
    ) -> Result<Self, NavError> {
        check_seed(volume, seed, threshold, side, || allowed.get(seed))?;
        let dims = volume.dims();
        let test = ValueTest::new(volume.value_map(), threshold, side);
        let on_side = test.on(volume);
        let mut visited = BitGrid::new(dims);
        let holds = |n: usize| allowed.get_linear(n) && on_side(n);
        let component = fill(dims, holds, seed, &mut visited);
        Ok(Self::from_visited(
            &visited, component, dims, threshold, side,
        ))
    }

    /// The largest lumen component of the volume, preferring components that do not touch the
    /// volume's border when `prefer_interior`: in CT the air around the patient touches the
    /// border and the colon or airways inside do not. When every component touches the border
    /// (a tube cut by the field of view) the largest of all is taken. `Ok(None)` when no voxel
    /// lies on the lumen side.
    pub fn largest(
        volume: &Volume,
        threshold: f64,
        side: LumenSide,
        prefer_interior: bool,
    ) -> Result<Option<Self>, NavError> {
        check_finite("threshold", threshold, false)?;
        let dims = volume.dims();
        let (mut best_all, mut best_inner): (Option<Component>, Option<Component>) = (None, None);
        let bigger = |best: Option<Component>, c: Component| match best {
            Some(b) if b.count >= c.count => Some(b),
            _ => Some(c),
        };
        for c in components(volume, threshold, side) {
            best_all = bigger(best_all, c);
            if !c.touches_border(dims) {
                best_inner = bigger(best_inner, c);
            }
        }
        let chosen = if prefer_interior {
            best_inner.or(best_all)
        } else {
            best_all
        };
        chosen
            .map(|c| Self::from_seed(volume, c.seed, threshold, side))
            .transpose()
    }

    /// The largest of the `tries` largest components that `accept` takes (the colon: gas, not
    /// aerated lung, inside the body). `Ok(None)` when it takes none of them.
    pub fn largest_accepted(
        volume: &Volume,
        threshold: f64,
        side: LumenSide,
        tries: usize,
        accept: impl Fn(&Lumen) -> bool,
    ) -> Result<Option<Self>, NavError> {
        check_finite("threshold", threshold, false)?;
        let mut all = components(volume, threshold, side);
        all.sort_by_key(|c| std::cmp::Reverse(c.count));
        for c in all.into_iter().take(tries) {
            let lumen = Self::from_seed(volume, c.seed, threshold, side)?;
            if accept(&lumen) {
                return Ok(Some(lumen));
            }
        }
        Ok(None)
    }

    /// The largest component of the voxels on `side` of `threshold` that `allowed` (one bit per
    /// voxel of the volume) also holds, among those whose inclusive bounding box `accept` takes:
    /// the nasal cavity among the air holes of a head's slices. `Ok(None)` when it takes none.
    pub(crate) fn largest_within(
        volume: &Volume,
        threshold: f64,
        side: LumenSide,
        allowed: &BitGrid,
        accept: impl Fn([usize; 3], [usize; 3]) -> bool,
    ) -> Result<Option<Self>, NavError> {
        check_finite("threshold", threshold, false)?;
        let test = ValueTest::new(volume.value_map(), threshold, side);
        let on_side = test.on(volume);
        let holds = |n: usize| allowed.get_linear(n) && on_side(n);
        let best = components_where(volume.dims(), holds)
            .into_iter()
            .filter(|c| accept(c.lo, c.hi))
            .max_by_key(|c| c.count);
        best.map(|c| Self::within(volume, c.seed, threshold, side, allowed))
            .transpose()
    }

    /// The largest component that reaches into the inclusive voxel box `lo..=hi` and does not
    /// touch the volume's border: the lateral ventricles from a box at the brain's centre,
    /// whatever dark CSF, skull or background lies around the brain. `Ok(None)` when every
    /// lumen voxel of the box belongs to a component that touches the border.
    pub fn largest_through_box(
        volume: &Volume,
        threshold: f64,
        side: LumenSide,
        region: ([usize; 3], [usize; 3]),
    ) -> Result<Option<Self>, NavError> {
        Self::largest_through_box_in(volume, threshold, side, region, None)
    }

    /// [`Lumen::largest_through_box`] among the voxels `allowed` (one bit per voxel of the
    /// volume) holds, when given: the ventricles cut off from the CSF at the brain's surface.
    pub(crate) fn largest_through_box_in(
        volume: &Volume,
        threshold: f64,
        side: LumenSide,
        (lo, hi): ([usize; 3], [usize; 3]),
        allowed: Option<&BitGrid>,
    ) -> Result<Option<Self>, NavError> {
        check_finite("threshold", threshold, false)?;
        let dims = volume.dims();
        let hi = [0, 1, 2].map(|a| hi[a].min(dims[a] - 1));
        let test = ValueTest::new(volume.value_map(), threshold, side);
        let on_side = test.on(volume);
        let holds = |n: usize| on_side(n) && allowed.is_none_or(|a| a.get_linear(n));
        let mut visited = BitGrid::new(dims);
        let mut best: Option<Component> = None;
        for k in lo[2]..=hi[2] {
            for j in lo[1]..=hi[1] {
                for i in lo[0]..=hi[0] {
                    let v = [i, j, k];
                    if visited.get(v) || !holds(volume.index(i, j, k)) {
                        continue;
                    }
                    let c = fill(dims, holds, v, &mut visited);
                    if !c.touches_border(dims) && best.is_none_or(|b| c.count > b.count) {
                        best = Some(c);
                    }
                }
            }
        }
        best.map(|c| match allowed {
            Some(allowed) => Self::within(volume, c.seed, threshold, side, allowed),
            None => Self::from_seed(volume, c.seed, threshold, side),
        })
        .transpose()
    }

    /// The object of `volume`: the largest component of the voxels not 6-connected to the
    /// volume's border through voxels on `side` of `threshold` (the background around it), its
    /// holes filled whatever they hold: a skull-stripped brain with the dark CSF inside it.
    /// It keeps the background's threshold and side. `Ok(None)` when the background fills the
    /// volume.
    pub(crate) fn object(
        volume: &Volume,
        threshold: f64,
        side: LumenSide,
    ) -> Result<Option<Self>, NavError> {
        check_finite("threshold", threshold, false)?;
        let dims = volume.dims();
        let test = ValueTest::new(volume.value_map(), threshold, side);
        let on_side = test.on(volume);
        let mut background = BitGrid::new(dims);
        for n in 0..dims[0] * dims[1] * dims[2] {
            let v = [n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])];
            let border = (0..3).any(|a| v[a] == 0 || v[a] + 1 == dims[a]);
            if border && on_side(n) && !background.get_linear(n) {
                fill(dims, &on_side, v, &mut background);
            }
        }
        let inside = |n: usize| !background.get_linear(n);
        let Some(largest) = components_where(dims, inside)
            .into_iter()
            .max_by_key(|c| c.count)
        else {
            return Ok(None);
        };
        let mut visited = BitGrid::new(dims);
        let c = fill(dims, inside, largest.seed, &mut visited);
        Ok(Some(Self::from_visited(&visited, c, dims, threshold, side)))
    }

    /// Copies the component's bits out of the volume-wide visited set into its bounding box.
    fn from_visited(
        visited: &BitGrid,
        c: Component,
        volume_dims: [usize; 3],
        threshold: f64,
        side: LumenSide,
    ) -> Self {
        let box_dims = [0, 1, 2].map(|a| c.hi[a] - c.lo[a] + 1);
        let mut mask = BitGrid::new(box_dims);
        for k in 0..box_dims[2] {
            for j in 0..box_dims[1] {
                for i in 0..box_dims[0] {
                    if visited.get([c.lo[0] + i, c.lo[1] + j, c.lo[2] + k]) {
                        mask.set([i, j, k]);
                    }
                }
            }
        }
        Self {
            lo: c.lo,
            mask,
            count: c.count,
            volume_dims,
            seed: c.seed,
            threshold,
            side,
        }
    }

    /// True when voxel `v` belongs to the lumen (false outside the volume).
    #[inline]
    pub fn contains(&self, v: [usize; 3]) -> bool {
        let rel = [0, 1, 2].map(|a| v[a].wrapping_sub(self.lo[a]));
        (0..3).all(|a| rel[a] < self.mask.dims[a]) && self.mask.get(rel)
    }

    /// True when the voxel at `offset` from the bounding box's lowest corner belongs to the
    /// lumen; offsets outside the box (negative ones too) are not.
    #[inline]
    pub(crate) fn contains_in_box(&self, offset: [isize; 3]) -> bool {
        let inside = (0..3).all(|a| offset[a] >= 0 && (offset[a] as usize) < self.mask.dims[a]);
        inside && self.mask.get(offset.map(|o| o as usize))
    }

    /// True when `v` is a wall-surface voxel: not in the lumen, but 6-adjacent to a lumen voxel.
    pub fn is_wall(&self, v: [usize; 3]) -> bool {
        if self.contains(v) {
            return false;
        }
        (0..3).any(|a| {
            let mut lower = v;
            let mut upper = v;
            lower[a] = lower[a].wrapping_sub(1);
            upper[a] += 1;
            self.contains(lower) || self.contains(upper)
        })
    }

    /// The inclusive bounding box of the lumen's voxels: lowest and highest voxel index.
    pub fn bounds(&self) -> ([usize; 3], [usize; 3]) {
        let hi = [0, 1, 2].map(|a| self.lo[a] + self.mask.dims[a] - 1);
        (self.lo, hi)
    }

    /// How many of the volume's six faces the lumen touches.
    pub fn faces_touched(&self) -> usize {
        let (lo, hi) = self.bounds();
        (0..3)
            .map(|a| usize::from(lo[a] == 0) + usize::from(hi[a] + 1 == self.volume_dims[a]))
            .sum()
    }

    /// The lumen as a leak out of the structure (see [`NavError::LumenLeaks`]): touching more
    /// than [`LEAK_FACES`] faces of the volume, or holding more than [`LEAK_FRACTION`] of it.
    /// A tube cut by the field of view touches one or two faces; the air around a body, all
    /// four sides.
    pub fn leak(&self) -> Option<NavError> {
        let faces = self.faces_touched();
        let total: usize = self.volume_dims.iter().product();
        let fraction = self.count as f64 / total as f64;
        (faces > LEAK_FACES || fraction > LEAK_FRACTION).then_some(NavError::LumenLeaks {
            threshold: self.threshold,
            side: self.side,
            faces,
            percent: 100.0 * fraction,
        })
    }

    /// Number of voxels in the lumen.
    pub fn voxel_count(&self) -> usize {
        self.count
    }

    /// The dimensions of the volume the lumen was found in.
    pub fn volume_dims(&self) -> [usize; 3] {
        self.volume_dims
    }

    /// The seed voxel it was grown from.
    pub fn seed(&self) -> [usize; 3] {
        self.seed
    }

    /// The threshold, physical units (HU for CT).
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// Which side of the threshold is lumen.
    pub fn side(&self) -> LumenSide {
        self.side
    }

    /// The same lumen on a volume whose axis `n` is this one's axis `axes[n]` (the same voxels
    /// stored in another order; `axes` a permutation of 0, 1, 2).
    pub(crate) fn with_axes(&self, axes: [usize; 3]) -> Self {
        let pick = |v: [usize; 3]| axes.map(|a| v[a]);
        let lo = pick(self.lo);
        let mut mask = BitGrid::new(pick(self.mask.dims));
        for v in self.voxels() {
            let w = pick(v);
            mask.set([0, 1, 2].map(|a| w[a] - lo[a]));
        }
        Self {
            lo,
            mask,
            count: self.count,
            volume_dims: pick(self.volume_dims),
            seed: pick(self.seed),
            threshold: self.threshold,
            side: self.side,
        }
    }

    /// Every lumen voxel, `i` fastest (sorted by linear index).
    pub fn voxels(&self) -> impl Iterator<Item = [usize; 3]> + '_ {
        let [nx, ny, nz] = self.mask.dims;
        (0..nz)
            .flat_map(move |k| (0..ny).flat_map(move |j| (0..nx).map(move |i| [i, j, k])))
            .filter(|&rel| self.mask.get(rel))
            .map(|rel| [0, 1, 2].map(|a| rel[a] + self.lo[a]))
    }
}

/// A dense numbering of a lumen's voxels, `0..voxel_count` in linear order (the order of
/// [`Lumen::voxels`]), so per-voxel work arrays hold lumen voxels only, not the whole box: one
/// count per 64 voxels of the box.
pub(crate) struct LumenNumbering<'a> {
    lumen: &'a Lumen,
    /// Lumen voxels before each 64-bit word of the mask.
    before: Vec<usize>,
}

impl<'a> LumenNumbering<'a> {
    pub(crate) fn new(lumen: &'a Lumen) -> Self {
        let mut total = 0;
        let before = lumen
            .mask
            .words
            .iter()
            .map(|w| {
                let here = total;
                total += w.count_ones() as usize;
                here
            })
            .collect();
        Self { lumen, before }
    }

    /// The lumen numbered.
    pub(crate) fn lumen(&self) -> &'a Lumen {
        self.lumen
    }

    /// The number of voxel `v` (volume index), or `None` when it is not in the lumen.
    #[inline]
    pub(crate) fn number(&self, v: [usize; 3]) -> Option<usize> {
        if !self.lumen.contains(v) {
            return None;
        }
        let rel = [0, 1, 2].map(|a| v[a] - self.lumen.lo[a]);
        let n = self.lumen.mask.index(rel);
        let below = self.lumen.mask.words[n >> 6] & ((1u64 << (n & 63)) - 1);
        Some(self.before[n >> 6] + below.count_ones() as usize)
    }
}

/// The `count` largest 6-connected components of the bits set in `grid` (largest first), each
/// as a grid of its own over the same box.
pub(crate) fn largest_components(grid: &BitGrid, count: usize) -> Vec<BitGrid> {
    let dims = grid.dims;
    let set = |n: usize| grid.get_linear(n);
    let mut all = components_where(dims, set);
    all.sort_by_key(|c| std::cmp::Reverse(c.count));
    all.into_iter()
        .take(count)
        .map(|c| {
            let mut own = BitGrid::new(dims);
            fill(dims, set, c.seed, &mut own);
            own
        })
        .collect()
}

/// Every component of the voxels on `side` of `threshold`, in the order their first voxel comes.
fn components(volume: &Volume, threshold: f64, side: LumenSide) -> Vec<Component> {
    let test = ValueTest::new(volume.value_map(), threshold, side);
    components_where(volume.dims(), test.on(volume))
}

/// Every component of the voxels (of a `dims` grid) whose linear index `holds` accepts, in the
/// order their first voxel comes.
fn components_where(dims: [usize; 3], holds: impl Fn(usize) -> bool) -> Vec<Component> {
    let mut visited = BitGrid::new(dims);
    let mut found = Vec::new();
    for n in 0..dims[0] * dims[1] * dims[2] {
        if !holds(n) || visited.get_linear(n) {
            continue;
        }
        let v = [n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])];
        found.push(fill(dims, &holds, v, &mut visited));
    }
    found
}

/// Scanline flood fill from `seed` (a lumen voxel not yet visited) over 6-connected voxels whose
/// linear index `holds` accepts, marking them in `visited`. Each stack entry starts a run along
/// `i`; the stack holds at most a few entries per run of the component, never one per voxel.
fn fill(
    dims: [usize; 3],
    holds: impl Fn(usize) -> bool,
    seed: [usize; 3],
    visited: &mut BitGrid,
) -> Component {
    let [nx, ny, nz] = dims;
    let open =
        |v: [usize; 3], visited: &BitGrid| holds(v[0] + nx * (v[1] + ny * v[2])) && !visited.get(v);
    let mut c = Component {
        seed,
        count: 0,
        lo: seed,
        hi: seed,
    };
    let mut stack = vec![seed];
    while let Some([i, j, k]) = stack.pop() {
        if !open([i, j, k], visited) {
            continue;
        }
        let (mut a, mut b) = (i, i);
        while a > 0 && open([a - 1, j, k], visited) {
            a -= 1;
        }
        while b + 1 < nx && open([b + 1, j, k], visited) {
            b += 1;
        }
        for x in a..=b {
            visited.set([x, j, k]);
        }
        c.count += b - a + 1;
        c.lo = [c.lo[0].min(a), c.lo[1].min(j), c.lo[2].min(k)];
        c.hi = [c.hi[0].max(b), c.hi[1].max(j), c.hi[2].max(k)];
        let rows = [
            (j.wrapping_sub(1), k),
            (j + 1, k),
            (j, k.wrapping_sub(1)),
            (j, k + 1),
        ];
        for (y, z) in rows.into_iter().filter(|&(y, z)| y < ny && z < nz) {
            // One entry per maximal run of open voxels in the neighbouring row.
            let mut in_run = false;
            for x in a..=b {
                let o = open([x, y, z], visited);
                if o && !in_run {
                    stack.push([x, y, z]);
                }
                in_run = o;
            }
        }
    }
    c
}

/// Checks that `seed` lies in the volume and in the lumen: on `side` of a finite `threshold`
/// and where `inside` (asked only for a seed in the volume) says the lumen may be.
fn check_seed(
    volume: &Volume,
    seed: [usize; 3],
    threshold: f64,
    side: LumenSide,
    inside: impl FnOnce() -> bool,
) -> Result<(), NavError> {
    check_finite("threshold", threshold, false)?;
    let dims = volume.dims();
    let value = volume
        .physical(seed[0], seed[1], seed[2])
        .ok_or(NavError::SeedOutside { seed, dims })?;
    if !side.holds(value, threshold) || !inside() {
        return Err(NavError::SeedInWall {
            seed,
            value,
            side,
            threshold,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::navigate::test_util::random_volume;
    use crate::phantom::{self, PhantomOptions};

    /// Brute-force 6-connected component by breadth-first search, for comparison.
    fn reference(volume: &Volume, seed: [usize; 3], threshold: f64) -> Vec<[usize; 3]> {
        let dims = volume.dims();
        let lumen = |v: [usize; 3]| {
            volume
                .physical(v[0], v[1], v[2])
                .is_some_and(|x| x < threshold)
        };
        let mut seen = std::collections::HashSet::from([seed]);
        let mut queue = std::collections::VecDeque::from([seed]);
        while let Some(v) = queue.pop_front() {
            for a in 0..3 {
                for up in [false, true] {
                    let mut w = v;
                    w[a] = if up { w[a] + 1 } else { w[a].wrapping_sub(1) };
                    if w[a] < dims[a] && lumen(w) && seen.insert(w) {
                        queue.push_back(w);
                    }
                }
            }
        }
        let mut all: Vec<_> = seen.into_iter().collect();
        all.sort_by_key(|v| (v[2], v[1], v[0]));
        all
    }

    #[test]
    fn fill_matches_breadth_first_search_on_random_volumes() {
        for seed in 0..6 {
            let volume = random_volume([13, 11, 9], glam::DVec3::ONE, seed, 0.6);
            let start = volume
                .voxels()
                .iter()
                .position(|&s| volume.value_map().physical(s) < 0.0)
                .unwrap();
            let dims = volume.dims();
            let v = [
                start % dims[0],
                start / dims[0] % dims[1],
                start / (dims[0] * dims[1]),
            ];
            let lumen = Lumen::from_seed(&volume, v, 0.0, LumenSide::Below).unwrap();
            let expected = reference(&volume, v, 0.0);
            assert_eq!(lumen.voxels().collect::<Vec<_>>(), expected);
            assert_eq!(lumen.voxel_count(), expected.len());
            let (lo, hi) = lumen.bounds();
            for a in 0..3 {
                assert_eq!(lo[a], expected.iter().map(|e| e[a]).min().unwrap());
                assert_eq!(hi[a], expected.iter().map(|e| e[a]).max().unwrap());
            }
        }
    }

    #[test]
    fn tube_lumen_wall_and_errors() {
        let (volume, tube) = phantom::straight_tube(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        let lumen = Lumen::from_seed(&volume, [16, 16, 16], -480.0, LumenSide::Below).unwrap();
        // Voxel centres strictly inside the analytic radius are lumen (the ramp crosses −480
        // HU exactly on the surface).
        let centre = tube.centreline.point_at(0.0);
        let inside = (0..32usize)
            .flat_map(|j| (0..32usize).map(move |i| (i, j)))
            .filter(|&(i, j)| {
                let d = glam::DVec2::new(i as f64 - centre.x, j as f64 - centre.y).length();
                d < tube.radius_vox
            })
            .count();
        assert_eq!(lumen.voxel_count(), inside * 32);
        assert!(lumen.contains([16, 16, 0]) && !lumen.contains([0, 0, 0]));
        assert!(!lumen.contains([16, 16, 32]));
        let edge = (0..16).find(|&i| lumen.contains([i, 16, 5])).unwrap();
        assert!(lumen.is_wall([edge - 1, 16, 5]));
        assert!(!lumen.is_wall([edge, 16, 5]) && !lumen.is_wall([0, 0, 5]));
        assert!(matches!(
            Lumen::from_seed(&volume, [0, 0, 0], -480.0, LumenSide::Below),
            Err(NavError::SeedInWall { value: 40.0, .. })
        ));
        let message = Lumen::from_seed(&volume, [0, 0, 0], -480.0, LumenSide::Below)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("40.0") && message.contains("-480.0"),
            "{message}"
        );
        assert!(matches!(
            Lumen::from_seed(&volume, [99, 0, 0], -480.0, LumenSide::Below),
            Err(NavError::SeedOutside { .. })
        ));
        assert!(matches!(
            Lumen::from_seed(&volume, [16, 16, 16], f64::NAN, LumenSide::Below),
            Err(NavError::BadNumber { .. })
        ));
        // The tissue is the lumen when the lumen is bright.
        let tissue = Lumen::from_seed(&volume, [0, 0, 0], -480.0, LumenSide::Above).unwrap();
        assert_eq!(tissue.voxel_count(), 32 * 32 * 32 - lumen.voxel_count());
    }

    #[test]
    fn the_air_outside_the_body_leaks_and_the_inside_does_not() {
        let (volume, _) = phantom::sphere_shell(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        let inside = Lumen::from_seed(&volume, [16, 16, 16], -480.0, LumenSide::Below).unwrap();
        assert_eq!((inside.faces_touched(), inside.leak()), (0, None));
        let outside = Lumen::from_seed(&volume, [0, 0, 0], -480.0, LumenSide::Below).unwrap();
        assert_eq!(outside.faces_touched(), 6);
        let message = outside.leak().unwrap().to_string();
        assert!(
            message.contains("leaks out") && message.contains("6 of"),
            "{message}"
        );
        // A tube cut by the field of view touches its two end faces only.
        let (tube, _) = phantom::straight_tube(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        let lumen = Lumen::from_seed(&tube, [16, 16, 16], -480.0, LumenSide::Below).unwrap();
        assert_eq!((lumen.faces_touched(), lumen.leak()), (2, None));
    }

    #[test]
    fn the_largest_component_through_a_box_skips_those_touching_the_border() {
        let (volume, _) = phantom::sphere_shell(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        let through = |lo, hi| {
            Lumen::largest_through_box(&volume, -480.0, LumenSide::Below, (lo, hi)).unwrap()
        };
        let inner = through([14; 3], [18; 3]).unwrap();
        assert!(inner.contains([16, 16, 16]) && inner.faces_touched() == 0);
        // A box in the outside air only: that air touches the border.
        assert_eq!(through([0; 3], [2; 3]), None);
    }

    #[test]
    fn largest_prefers_the_inside_of_the_body() {
        let (volume, _) = phantom::sphere_shell(&PhantomOptions {
            size: 32,
            ..Default::default()
        });
        // Air inside and outside the shell: the outside is larger but touches the border.
        let inner = Lumen::largest(&volume, -480.0, LumenSide::Below, true)
            .unwrap()
            .unwrap();
        let outer = Lumen::largest(&volume, -480.0, LumenSide::Below, false)
            .unwrap()
            .unwrap();
        assert!(inner.contains([16, 16, 16]) && !outer.contains([16, 16, 16]));
        assert!(outer.voxel_count() > inner.voxel_count());
        assert!(outer.contains([0, 0, 0]));
        assert!(Lumen::largest(&volume, -5000.0, LumenSide::Below, true)
            .unwrap()
            .is_none());
    }
}
