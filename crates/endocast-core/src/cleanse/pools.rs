//! Finding the pools: connected tagged voxels that lie under air with a flat level.

use super::{Gravity, AIR_HU, TAG_THRESHOLD_HU};
use crate::Volume;

/// Air above a pool is darker than this, HU.
const AIR_LIMIT_HU: f64 = -700.0;
/// How far above a pool's top voxel its level's air is looked for, voxels.
const LEVEL_SEARCH_VOX: usize = 4;
/// Fewest columns through a level for a component to count as a pool.
const MIN_LEVEL_COLUMNS: usize = 8;
/// Share of a pool's level crossings within a voxel of their median: the level is flat.
const FLAT_SHARE: f64 = 0.5;
/// Largest share of a pool's voxels more than a voxel above its level (fluid lies under it).
const ABOVE_LEVEL_SHARE: f64 = 0.05;
/// Largest number of a pool's bottom voxels with air under them, as a share of its level's
/// columns: fluid rests on the wall, a thin bony plate between two air spaces does not.
const AIR_BELOW_SHARE: f64 = 0.05;
/// Most voxels read to estimate a component's tag value.
const TAG_SAMPLES: usize = 100_000;
/// Steepest level, mm along gravity per mm across it (about 6°): a fluid's level is
/// perpendicular to gravity; the contrast-enhanced bowel wall under gas that the abdomen CT
/// showed (no oral contrast) rose 0.37 mm per mm.
const MAX_LEVEL_TILT: f64 = 0.1;

/// A pool of tagged fluid found in a scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaggedPool {
    /// Which way is down for this pool.
    pub gravity: Gravity,
    /// The air/fluid level, in the depth coordinate of [`Gravity::depth`] (voxels).
    pub level_depth: f64,
    /// The fluid's median value, HU.
    pub tag_hu: f64,
    /// Tagged voxels in the pool.
    pub voxels: usize,
}

/// A pool with its voxels (indices into the volume's buffer).
pub(crate) struct Found {
    pub pool: TaggedPool,
    pub voxels: Vec<usize>,
}

/// A CT's values in HU, addressed by buffer index.
pub(crate) struct HuScan<'a> {
    pub volume: &'a Volume,
    /// The stored physical value of 0 HU.
    pub offset: f64,
    pub dims: [usize; 3],
}

impl<'a> HuScan<'a> {
    pub fn new(volume: &'a Volume, offset: f64) -> Self {
        Self {
            volume,
            offset,
            dims: volume.dims(),
        }
    }

    /// The value of voxel `index`, HU.
    #[inline]
    pub fn hu(&self, index: usize) -> f64 {
        self.volume
            .value_map()
            .physical(self.volume.voxels()[index])
            - self.offset
    }

    #[inline]
    pub fn hu_at(&self, ijk: [usize; 3]) -> f64 {
        self.hu(self.index(ijk))
    }

    #[inline]
    pub fn is_tag(&self, index: usize) -> bool {
        self.hu(index) > TAG_THRESHOLD_HU
    }

    #[inline]
    pub fn index(&self, [i, j, k]: [usize; 3]) -> usize {
        (k * self.dims[1] + j) * self.dims[0] + i
    }

    #[inline]
    pub fn ijk(&self, index: usize) -> [usize; 3] {
        let [nx, ny, _] = self.dims;
        [index % nx, (index / nx) % ny, index / (nx * ny)]
    }

    /// The 6-connected neighbours of `ijk` inside the grid.
    pub fn neighbours(&self, ijk: [usize; 3]) -> impl Iterator<Item = [usize; 3]> + '_ {
        (0..3).flat_map(move |axis| {
            let below = ijk[axis].checked_sub(1);
            let above = (ijk[axis] + 1 < self.dims[axis]).then_some(ijk[axis] + 1);
            [below, above].into_iter().flatten().map(move |n| {
                let mut p = ijk;
                p[axis] = n;
                p
            })
        })
    }
}

/// A set of voxels of the scan, one bit each.
pub(crate) struct VoxelSet(Vec<u64>);

impl VoxelSet {
    pub fn new(len: usize) -> Self {
        Self(vec![0; len.div_ceil(64)])
    }

    /// Adds `index`; true if it was not there yet.
    #[inline]
    pub fn insert(&mut self, index: usize) -> bool {
        let (word, bit) = (index / 64, 1u64 << (index % 64));
        let fresh = self.0[word] & bit == 0;
        self.0[word] |= bit;
        fresh
    }

    #[inline]
    pub fn contains(&self, index: usize) -> bool {
        self.0[index / 64] & (1u64 << (index % 64)) != 0
    }
}

/// Every tagged component of `scan` that is a pool under air for gravity either way along the
/// anterior–posterior axis, largest first.
pub(crate) fn find(scan: &HuScan, gravity: &[Gravity; 2]) -> Vec<Found> {
    let len = scan.volume.voxels().len();
    let mut seen = VoxelSet::new(len);
    let mut found = Vec::new();
    let mut outside: Option<VoxelSet> = None;
    for start in 0..len {
        if seen.contains(start) || !scan.is_tag(start) {
            continue;
        }
        let voxels = component(scan, start, &mut seen);
        let outside = outside.get_or_insert_with(|| air_around_the_body(scan));
        if let Some(pool) = gravity
            .iter()
            .find_map(|g| as_pool(scan, &voxels, *g, outside))
        {
            found.push(Found { pool, voxels });
        }
    }
    found.sort_by_key(|f| std::cmp::Reverse(f.voxels.len()));
    found
}

/// The 6-connected tagged voxels joined to `start`, each marked in `seen`.
fn component(scan: &HuScan, start: usize, seen: &mut VoxelSet) -> Vec<usize> {
    seen.insert(start);
    let (mut voxels, mut stack) = (Vec::new(), vec![start]);
    while let Some(index) = stack.pop() {
        voxels.push(index);
        for n in scan.neighbours(scan.ijk(index)) {
            let n = scan.index(n);
            if scan.is_tag(n) && seen.insert(n) {
                stack.push(n);
            }
        }
    }
    voxels
}

/// `voxels` as a pool under `gravity`: its level measured where gas inside the body (not the
/// air `outside` it) lies above its top, flat and perpendicular to gravity, with (almost)
/// nothing of it above; `None` for anything else. (The CT table's bright top, read for prone
/// gravity, is flat and under air too, but that air is around the body.)
fn as_pool(
    scan: &HuScan,
    voxels: &[usize],
    gravity: Gravity,
    outside: &VoxelSet,
) -> Option<TaggedPool> {
    let tag_hu = median_hu(scan, voxels);
    let columns: Vec<(usize, f64)> = voxels
        .iter()
        .filter_map(|&v| level_crossing(scan, v, gravity, tag_hu).map(|c| (v, c)))
        .filter(|&(_, (_, air))| !outside.contains(air))
        .map(|(v, (depth, _))| (v, depth))
        .collect();
    if columns.len() < MIN_LEVEL_COLUMNS || tilt(scan, gravity, &columns)? > MAX_LEVEL_TILT {
        return None;
    }
    let crossings: Vec<f64> = columns.iter().map(|&(_, depth)| depth).collect();
    let mut sorted = crossings.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let flat: Vec<f64> = sorted
        .into_iter()
        .filter(|c| (c - median).abs() <= 1.0)
        .collect();
    let above = voxels
        .iter()
        .filter(|&&v| gravity.depth(scan.ijk(v)) < median - 1.0)
        .count();
    let floating = voxels
        .iter()
        .filter(|&&v| air_below(scan, v, gravity))
        .count();
    let is_pool = flat.len() as f64 >= FLAT_SHARE * crossings.len() as f64
        && above as f64 <= ABOVE_LEVEL_SHARE * voxels.len() as f64
        && floating as f64 <= AIR_BELOW_SHARE * crossings.len() as f64;
    is_pool.then(|| TaggedPool {
        gravity,
        level_depth: flat.iter().sum::<f64>() / flat.len() as f64,
        tag_hu,
        voxels: voxels.len(),
    })
}

/// Where the air/fluid level crosses the column above `index`, a top voxel of the component
/// (depth, voxels): the halfway value between air and `tag_hu`, linearly interpolated, and the
/// air voxel above it; `None` unless `index` is a top voxel with air within
/// [`LEVEL_SEARCH_VOX`] above it.
fn level_crossing(
    scan: &HuScan,
    index: usize,
    gravity: Gravity,
    tag_hu: f64,
) -> Option<(f64, usize)> {
    let top = scan.ijk(index);
    let mid = 0.5 * (AIR_HU + tag_hu);
    let (mut at, mut previous) = (top, scan.hu(index));
    let mut crossing = None;
    for step in 1..=LEVEL_SEARCH_VOX {
        at = gravity.up(at, scan.dims)?;
        let value = scan.hu_at(at);
        if step == 1 && value > TAG_THRESHOLD_HU {
            return None;
        }
        if crossing.is_none() && value < mid && previous >= mid {
            let fraction = (previous - mid) / (previous - value);
            crossing = Some(gravity.depth(top) - (step - 1) as f64 - fraction);
        }
        if value < AIR_LIMIT_HU {
            return crossing.map(|c| (c, scan.index(at)));
        }
        previous = value;
    }
    None
}

/// The slope of the plane fitted (least squares) to a level's `columns` (top voxel, crossing
/// depth), mm along gravity per mm across it; `None` when the columns lie on one line.
fn tilt(scan: &HuScan, gravity: Gravity, columns: &[(usize, f64)]) -> Option<f64> {
    let spacing = scan.volume.geometry().spacing_mm().to_array();
    let across: Vec<usize> = (0..3).filter(|&a| a != gravity.axis).collect();
    let points: Vec<[f64; 3]> = columns
        .iter()
        .map(|&(v, depth)| {
            let ijk = scan.ijk(v);
            let at = |a: usize| ijk[a] as f64 * spacing[a];
            [at(across[0]), at(across[1]), depth * spacing[gravity.axis]]
        })
        .collect();
    let n = points.len() as f64;
    let mean = [0, 1, 2].map(|c| points.iter().map(|p| p[c]).sum::<f64>() / n);
    let moment = |a: usize, b: usize| {
        points
            .iter()
            .map(|p| (p[a] - mean[a]) * (p[b] - mean[b]))
            .sum::<f64>()
    };
    let (uu, uv, vv, ud, vd) = (
        moment(0, 0),
        moment(0, 1),
        moment(1, 1),
        moment(0, 2),
        moment(1, 2),
    );
    let det = uu * vv - uv * uv;
    if det <= 1e-9 * (uu * vv).max(f64::MIN_POSITIVE) {
        return None;
    }
    let slope_u = (ud * vv - vd * uv) / det;
    let slope_v = (vd * uu - ud * uv) / det;
    Some(slope_u.hypot(slope_v))
}

/// The air around the body: voxels darker than [`AIR_LIMIT_HU`] joined (6-connected) to the
/// scan's side faces (those along the body's long axis, the index axis nearest the world's
/// superior axis) through such voxels. Gas inside the body, a bowel's included, does not reach
/// them, even where the first or last slice cuts it; the air under the CT table does.
fn air_around_the_body(scan: &HuScan) -> VoxelSet {
    let dims = scan.dims;
    let mut outside = VoxelSet::new(dims.iter().product());
    let air = |index: usize| scan.hu(index) < AIR_LIMIT_HU;
    let direction = scan.volume.geometry().direction();
    let long = (0..3)
        .max_by(|&a, &b| {
            direction
                .col(a)
                .z
                .abs()
                .total_cmp(&direction.col(b).z.abs())
        })
        .unwrap_or(2);
    let on_face =
        |ijk: [usize; 3]| (0..3).any(|a| a != long && (ijk[a] == 0 || ijk[a] + 1 == dims[a]));
    let mut stack: Vec<usize> = (0..dims.iter().product())
        .filter(|&v| on_face(scan.ijk(v)) && air(v))
        .collect();
    for &v in &stack {
        outside.insert(v);
    }
    while let Some(v) = stack.pop() {
        for n in scan.neighbours(scan.ijk(v)) {
            let n = scan.index(n);
            if air(n) && outside.insert(n) {
                stack.push(n);
            }
        }
    }
    outside
}

/// Whether `index` is a bottom voxel of its component with air within [`LEVEL_SEARCH_VOX`]
/// under it.
fn air_below(scan: &HuScan, index: usize, gravity: Gravity) -> bool {
    let mut at = scan.ijk(index);
    for step in 1..=LEVEL_SEARCH_VOX {
        let Some(below) = gravity.down(at, scan.dims) else {
            return false;
        };
        at = below;
        let value = scan.hu_at(at);
        if step == 1 && value > TAG_THRESHOLD_HU {
            return false;
        }
        if value < AIR_LIMIT_HU {
            return true;
        }
    }
    false
}

/// The median value of (a regular sample of) the interior of `voxels` (those whose six
/// neighbours are tagged too, clear of the partial volumes at its boundary), or of all of them
/// when it has no interior, HU.
fn median_hu(scan: &HuScan, voxels: &[usize]) -> f64 {
    let step = voxels.len().div_ceil(TAG_SAMPLES).max(1);
    let sample = || voxels.iter().step_by(step).copied();
    let interior = |&v: &usize| {
        let ijk = scan.ijk(v);
        scan.neighbours(ijk).count() == 6
            && scan.neighbours(ijk).all(|n| scan.is_tag(scan.index(n)))
    };
    let mut values: Vec<f64> = sample().filter(interior).map(|v| scan.hu(v)).collect();
    if values.is_empty() {
        values = sample().map(|v| scan.hu(v)).collect();
    }
    let middle = values.len() / 2;
    *values.select_nth_unstable_by(middle, f64::total_cmp).1
}
