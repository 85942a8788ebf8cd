//! Cross-sections of a lumen in one axial slice: the 4-connected regions of a slice on the lumen
//! side of a threshold, with their size, centre and roundness. The trachea and the aorta are
//! found as round sections of the right size.

use super::lumen::LumenSide;
use crate::Volume;

/// One 4-connected region of an axial slice, on the lumen side of a threshold, that does not
/// touch the slice's border.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Section {
    /// The region's pixels, linear indices in the slice (`i + nx · j`).
    pub(crate) pixels: Vec<usize>,
    /// Lowest pixel `[i, j]` of its bounding box.
    pub(crate) lo: [usize; 2],
    /// Highest pixel `[i, j]` of its bounding box.
    pub(crate) hi: [usize; 2],
    /// Its centroid, pixel coordinates `[i, j]`.
    pub(crate) mean: [f64; 2],
    /// A pixel of the region nearest its centroid.
    pub(crate) centre: [usize; 2],
}

impl Section {
    /// The area, mm², for pixels of `pixel_mm` (`[x, y]` spacing).
    pub(crate) fn area_mm2(&self, pixel_mm: [f64; 2]) -> f64 {
        self.pixels.len() as f64 * pixel_mm[0] * pixel_mm[1]
    }

    /// The radius of the disc of the same area, mm.
    pub(crate) fn radius_mm(&self, pixel_mm: [f64; 2]) -> f64 {
        (self.area_mm2(pixel_mm) / std::f64::consts::PI).sqrt()
    }

    /// How round it is: its area over that of the disc around its centroid reaching its
    /// farthest pixel's outer edge; about 0.8–1 for a digitised disc, 0.5 for an ellipse twice
    /// as long as wide, less for a disc with something attached.
    pub(crate) fn roundness(&self, pixel_mm: [f64; 2], nx: usize) -> f64 {
        let half = 0.5 * pixel_mm[0].max(pixel_mm[1]);
        let reach = self
            .pixels
            .iter()
            .map(|&n| {
                let dx = ((n % nx) as f64 - self.mean[0]) * pixel_mm[0];
                let dy = ((n / nx) as f64 - self.mean[1]) * pixel_mm[1];
                dx.hypot(dy)
            })
            .fold(0.0, f64::max)
            + half;
        self.area_mm2(pixel_mm) / (std::f64::consts::PI * reach * reach)
    }

    /// The share of its bounding box it fills (a disc fills π/4).
    pub(crate) fn fill(&self) -> f64 {
        let box_pixels = (self.hi[0] - self.lo[0] + 1) * (self.hi[1] - self.lo[1] + 1);
        self.pixels.len() as f64 / box_pixels as f64
    }
}

/// The sections of axial slice `k` on `side` of `threshold` (physical units) that do not touch
/// the slice's border, keeping only those `keep` accepts (called with each section's pixel
/// count before the section is built, so large regions cost no more than their fill).
pub(crate) fn sections(
    volume: &Volume,
    k: usize,
    threshold: f64,
    side: LumenSide,
    keep: impl Fn(usize) -> bool,
) -> Vec<Section> {
    let [nx, ny, _] = volume.dims();
    let map = volume.value_map();
    let slice = &volume.voxels()[k * nx * ny..(k + 1) * nx * ny];
    let open: Vec<bool> = slice
        .iter()
        .map(|&s| side.holds(map.physical(s), threshold))
        .collect();
    let mut seen = vec![false; nx * ny];
    let mut found = Vec::new();
    let mut pixels = Vec::new();
    for start in 0..nx * ny {
        if !open[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        pixels.clear();
        let mut stack = vec![start];
        while let Some(n) = stack.pop() {
            pixels.push(n);
            let neighbours = neighbours4(n, nx, ny);
            for m in neighbours.into_iter().flatten() {
                if open[m] && !seen[m] {
                    seen[m] = true;
                    stack.push(m);
                }
            }
        }
        if keep(pixels.len()) {
            if let Some(section) = section_of(&pixels, nx, ny) {
                found.push(section);
            }
        }
    }
    found
}

/// The section of `pixels` (linear indices in an `nx` × `ny` slice), or `None` when it touches
/// the slice's border.
pub(crate) fn section_of(pixels: &[usize], nx: usize, ny: usize) -> Option<Section> {
    let ij = |n: usize| [n % nx, n / nx];
    let (mut lo, mut hi) = ([usize::MAX; 2], [0; 2]);
    let mut sum = [0.0; 2];
    for &n in pixels {
        let p = ij(n);
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
            sum[a] += p[a] as f64;
        }
    }
    if lo[0] == 0 || lo[1] == 0 || hi[0] + 1 == nx || hi[1] + 1 == ny {
        return None;
    }
    let mean = sum.map(|s| s / pixels.len() as f64);
    let centre = pixels.iter().map(|&n| ij(n)).min_by(|a, b| {
        let d = |p: &[usize; 2]| (p[0] as f64 - mean[0]).powi(2) + (p[1] as f64 - mean[1]).powi(2);
        d(a).total_cmp(&d(b))
    })?;
    Some(Section {
        pixels: pixels.to_vec(),
        lo,
        hi,
        mean,
        centre,
    })
}

/// Whether the volume's top (the patient's head end, largest world `z`) is its last slice.
pub(crate) fn top_is_last(volume: &Volume) -> bool {
    let g = volume.geometry();
    let last = volume.dims()[2].saturating_sub(1) as f64;
    g.world_of(glam::DVec3::new(0.0, 0.0, last)).z > g.world_of(glam::DVec3::ZERO).z
}

/// The 4-connected neighbours of pixel `n` in an `nx` × `ny` slice (`None` past its border).
pub(crate) fn neighbours4(n: usize, nx: usize, ny: usize) -> [Option<usize>; 4] {
    let (i, j) = (n % nx, n / nx);
    [
        (i > 0).then(|| n - 1),
        (i + 1 < nx).then_some(n + 1),
        (j > 0).then(|| n - nx),
        (j + 1 < ny).then_some(n + nx),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};

    #[test]
    fn a_tube_cut_across_is_one_round_section() {
        let (volume, tube) = phantom::straight_tube(&PhantomOptions {
            size: 48,
            ..Default::default()
        });
        let found = sections(&volume, 10, -480.0, LumenSide::Below, |_| true);
        assert_eq!(found.len(), 1);
        let s = &found[0];
        let r = s.radius_mm([1.0, 1.0]);
        assert!((r - tube.radius_vox).abs() < 0.5, "{r}");
        assert!(
            s.roundness([1.0, 1.0], 48) > 0.75,
            "{}",
            s.roundness([1.0, 1.0], 48)
        );
        assert!((s.fill() - std::f64::consts::FRAC_PI_4).abs() < 0.1);
        assert!(s.centre[0].abs_diff(24) <= 1 && s.centre[1].abs_diff(24) <= 1);
        // The tissue around it touches the slice's border: no section.
        assert!(sections(&volume, 10, -480.0, LumenSide::Above, |_| true).is_empty());
        assert!(sections(&volume, 10, -480.0, LumenSide::Below, |n| n > 10_000).is_empty());
    }
}
