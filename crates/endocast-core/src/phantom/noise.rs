//! Deterministic Gaussian noise: a hash of (seed, voxel index), never a shared generator, so a
//! volume is the same on any number of threads and any voxel can be recomputed on its own.
//!
//! Voxels `2m` and `2m + 1` share one draw of the polar Box–Muller method (Marsaglia's), seeded
//! by the hash of (seed, m): one logarithm and one square root per two voxels and no
//! trigonometry, which keeps noise cheap next to the phantoms themselves.

/// SplitMix64's finaliser: a bijective mix of 64 bits with good avalanche.
#[inline]
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Two independent standard normal samples for the voxel pair `pair` under `seed`.
#[inline]
fn gaussian_pair(seed: u64, pair: u64) -> (f64, f64) {
    // Uniform in (−1, 1) from 32 bits (enough for image noise: the tails reach about 6.6 σ).
    let signed_unit = |bits: u64| (bits as f64 + 0.5) / 2_147_483_648.0 - 1.0;
    let mut h = splitmix64(splitmix64(seed) ^ pair);
    loop {
        let u = signed_unit(h >> 32);
        let v = signed_unit(h & 0xFFFF_FFFF);
        let s = u * u + v * v;
        // Points outside the unit disc (21 %) are rejected; the next hash in the chain is as
        // deterministic as the first.
        if s < 1.0 && s > 0.0 {
            let factor = (-2.0 * s.ln() / s).sqrt();
            return (u * factor, v * factor);
        }
        h = splitmix64(h);
    }
}

/// A uniform sample in [0, 1) for draw `index` under `seed` (53 bits of the hash), for
/// placements drawn with a seed.
pub(crate) fn uniform(seed: u64, index: u64) -> f64 {
    (splitmix64(splitmix64(seed ^ 0x0005_EED0_FA11_D4A3) ^ index) >> 11) as f64
        / (1u64 << 53) as f64
}

/// The standard normal sample of voxel `index` under `seed`.
#[cfg(test)]
pub(crate) fn gaussian(seed: u64, index: u64) -> f64 {
    let (even, odd) = gaussian_pair(seed, index / 2);
    if index.is_multiple_of(2) {
        even
    } else {
        odd
    }
}

/// Fills `out` with the samples of voxels `first..first + out.len()` (same values as asking
/// for each voxel alone).
pub(crate) fn fill(seed: u64, first: u64, out: &mut [f64]) {
    let mut n = 0;
    while n < out.len() {
        let index = first + n as u64;
        let (even, odd) = gaussian_pair(seed, index / 2);
        if index % 2 == 1 {
            out[n] = odd;
            n += 1;
        } else {
            out[n] = even;
            if let Some(next) = out.get_mut(n + 1) {
                *next = odd;
            }
            n += 2;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_have_unit_moments_and_depend_on_seed_and_index() {
        let n = 200_000u64;
        let mut all = vec![0.0; n as usize];
        fill(7, 0, &mut all);
        let mean = all.iter().sum::<f64>() / n as f64;
        let var = all.iter().map(|g| g * g).sum::<f64>() / n as f64 - mean * mean;
        let kurtosis = all.iter().map(|g| g.powi(4)).sum::<f64>() / n as f64;
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.02, "variance {var}");
        assert!((kurtosis - 3.0).abs() < 0.1, "fourth moment {kurtosis}");
        // Neighbours sharing a draw are uncorrelated.
        let pairs = all.chunks_exact(2).map(|p| p[0] * p[1]).sum::<f64>() / (n / 2) as f64;
        assert!(pairs.abs() < 0.02, "pair correlation {pairs}");
        assert_eq!(gaussian(7, 42), all[42]);
        assert_ne!(gaussian(7, 42), gaussian(8, 42));
        assert_ne!(gaussian(7, 42), gaussian(7, 43));
    }

    #[test]
    fn filling_any_range_gives_each_voxel_its_own_sample() {
        for (first, len) in [(0, 5), (3, 4), (7, 1), (10, 0), (11, 6)] {
            let mut out = vec![0.0; len];
            fill(5, first, &mut out);
            for (n, &g) in out.iter().enumerate() {
                assert_eq!(g, gaussian(5, first + n as u64));
            }
        }
    }
}
