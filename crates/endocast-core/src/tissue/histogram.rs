//! The histogram of a volume's stored values, Otsu's threshold and class medians on it.

use crate::Volume;

/// Counts of every stored `u16` value of a volume (or of a box of it).
#[derive(Debug, Clone)]
pub(crate) struct Histogram {
    counts: Vec<u64>,
    total: u64,
}

impl Histogram {
    /// The histogram of every voxel.
    pub(crate) fn of(volume: &Volume) -> Self {
        Self::from_values(volume.voxels().iter().copied())
    }

    /// The histogram of the voxels in the inclusive box `lo..=hi` (voxel indices).
    pub(crate) fn of_box(volume: &Volume, lo: [usize; 3], hi: [usize; 3]) -> Self {
        let dims = volume.dims();
        let voxels = volume.voxels();
        let values = (lo[2]..=hi[2]).flat_map(move |k| {
            (lo[1]..=hi[1]).flat_map(move |j| {
                let row = (k * dims[1] + j) * dims[0];
                voxels[row + lo[0]..=row + hi[0]].iter().copied()
            })
        });
        Self::from_values(values)
    }

    fn from_values(values: impl Iterator<Item = u16>) -> Self {
        let mut counts = vec![0u64; 1 << 16];
        for v in values {
            counts[usize::from(v)] += 1;
        }
        let total = counts.iter().sum();
        Self { counts, total }
    }

    /// Number of values counted.
    pub(crate) fn total(&self) -> u64 {
        self.total
    }

    /// Otsu's threshold: the stored value `t` such that splitting into `≤ t` and `> t`
    /// maximises the between-class variance; `None` with fewer than two distinct values.
    pub(crate) fn otsu(&self) -> Option<u16> {
        let (sum_all, total) = self
            .counts
            .iter()
            .enumerate()
            .fold((0.0, 0.0), |(s, n), (v, &c)| {
                (s + v as f64 * c as f64, n + c as f64)
            });
        let (mut w0, mut sum0) = (0.0, 0.0);
        let mut best: Option<(f64, u16)> = None;
        for (v, &c) in self.counts.iter().enumerate() {
            w0 += c as f64;
            sum0 += v as f64 * c as f64;
            let w1 = total - w0;
            if c == 0 || w0 == 0.0 || w1 == 0.0 {
                continue;
            }
            let (m0, m1) = (sum0 / w0, (sum_all - sum0) / w1);
            let between = w0 * w1 * (m0 - m1) * (m0 - m1);
            if best.is_none_or(|(b, _)| between > b) {
                best = Some((between, v as u16));
            }
        }
        best.map(|(_, t)| t)
    }

    /// Number of values in `lo..=hi`.
    pub(crate) fn count(&self, lo: u16, hi: u16) -> u64 {
        self.counts[usize::from(lo)..=usize::from(hi)].iter().sum()
    }

    /// The median of the values in `lo..=hi`; `None` when there are none.
    pub(crate) fn median(&self, lo: u16, hi: u16) -> Option<u16> {
        let n = self.count(lo, hi);
        if n == 0 {
            return None;
        }
        let mut seen = 0;
        for v in lo..=hi {
            seen += self.counts[usize::from(v)];
            if 2 * seen >= n {
                return Some(v);
            }
        }
        Some(hi)
    }

    /// The smallest and largest value counted; `None` when empty.
    pub(crate) fn range(&self) -> Option<(u16, u16)> {
        let lo = self.counts.iter().position(|&c| c > 0)?;
        let hi = self.counts.iter().rposition(|&c| c > 0)?;
        Some((lo as u16, hi as u16))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn otsu_splits_two_clusters_between_them_and_medians_find_each() {
        let values = (0..1000u16)
            .map(|n| 10 + n % 5)
            .chain((0..300u16).map(|n| 200 + n % 7));
        let h = Histogram::from_values(values);
        let t = h.otsu().unwrap();
        assert!((14..200).contains(&t), "{t}");
        assert_eq!(h.median(0, t), Some(12));
        assert_eq!(h.median(t + 1, u16::MAX), Some(203));
        assert_eq!(h.range(), Some((10, 206)));
        assert_eq!(h.total(), 1300);
        assert_eq!(Histogram::from_values([7u16; 9].into_iter()).otsu(), None);
        assert_eq!(h.median(300, 400), None);
    }
}
