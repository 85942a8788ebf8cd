//! Deterministic Gaussian noise: a hash of (seed, voxel index), never a shared generator, so a
//! volume is the same on any number of threads and any voxel can be recomputed on its own.

/// SplitMix64's finaliser: a bijective mix of 64 bits with good avalanche.
#[inline]
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A standard normal sample for voxel `index` under `seed` (Box–Muller on two 32-bit uniforms
/// from one hash; 32 bits reach about 6.7 σ, plenty for image noise).
#[inline]
pub(crate) fn gaussian(seed: u64, index: u64) -> f64 {
    let h = splitmix64(splitmix64(seed) ^ index);
    let unit = |bits: u64| (bits as f64 + 0.5) / 4_294_967_296.0;
    let u1 = unit(h >> 32);
    let u2 = unit(h & 0xFFFF_FFFF);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_has_unit_moments_and_depends_on_seed_and_index() {
        let n = 200_000u64;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for i in 0..n {
            let g = gaussian(7, i);
            sum += g;
            sum2 += g * g;
        }
        let mean = sum / n as f64;
        let var = sum2 / n as f64 - mean * mean;
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.02, "variance {var}");
        assert_eq!(gaussian(7, 42), gaussian(7, 42));
        assert_ne!(gaussian(7, 42), gaussian(8, 42));
        assert_ne!(gaussian(7, 42), gaussian(7, 43));
    }
}
