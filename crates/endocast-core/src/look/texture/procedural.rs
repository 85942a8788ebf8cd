//! The built-in textures, computed: `mucosa` (a low-contrast mottled base at three scales under
//! sparse, thin, reddish-dark branching vessels at two) and `grid` (lines, the strongest shape
//! cue). Every pattern repeats with the tile (its noise lattices do), so tiles meet without a
//! seam.

/// Edge of the built-in textures, texels.
pub(super) const BUILT_IN_TEXELS: usize = 512;

/// The mottled base: (lattice cells across the tile, amplitude) of its gradient-noise octaves;
/// at the CT preset's 30 mm tile, patches of about 5, 2.5 and 1.2 mm.
const MOTTLING: [(usize, f32); 3] = [(6, 0.16), (12, 0.16), (24, 0.1)];

/// Vessels: (lattice cells across the tile, half-width in texels, strength, share shown) of the
/// larger and the finer ones; at 30 mm, about 10 and 4 mm apart, 0.15 and 0.08 mm wide.
const VESSELS: [(usize, f32, f32, f32); 2] = [(3, 1.3, 1.0, 0.6), (9, 0.8, 0.7, 0.5)];

/// How much a full-strength vessel lowers red, green and blue: darker, and redder than the
/// mucosa around it.
const VESSEL_TINT: [f32; 3] = [0.08, 0.22, 0.2];

/// The mucosa texture, `BUILT_IN_TEXELS²` colours (row 0 first).
pub(super) fn mucosa() -> Vec<[f32; 3]> {
    let n = BUILT_IN_TEXELS;
    let vessels: Vec<Vec<f32>> = VESSELS
        .iter()
        .enumerate()
        .map(|(i, &(cells, width, strength, shown))| {
            let seed = 10 * i as u32;
            let lines = lines(&warped_field(cells, seed), width);
            let mask =
                |x, y| smoothstep((value_noise(x, y, cells + 1, seed + 3) - 1.0 + shown) * 6.0);
            (0..n * n)
                .map(|t| strength * lines[t] * mask(t % n, t / n))
                .collect()
        })
        .collect();
    (0..n * n)
        .map(|t| {
            let (x, y) = (t % n, t / n);
            let mottle: f32 = MOTTLING
                .iter()
                .enumerate()
                .map(|(o, &(cells, amplitude))| {
                    let scale = cells as f32 / n as f32;
                    let (u, v) = ((x as f32 + 0.5) * scale, (y as f32 + 0.5) * scale);
                    amplitude * gradient_noise(u, v, cells, 20 + o as u32)
                })
                .sum();
            // A faint shift between pinker and yellower patches.
            let hue = 0.03 * (value_noise(x, y, 7, 30) - 0.5);
            let vessel = vessels.iter().map(|v| v[t]).sum::<f32>().min(1.0);
            let base = [0.5 + mottle + hue, 0.5 + mottle - hue, 0.5 + mottle - hue];
            std::array::from_fn(|c| (base[c] - VESSEL_TINT[c] * vessel).clamp(0.0, 1.0))
        })
        .collect()
}

/// The grid: dark lines four texels wide every 64 texels on a light ground.
pub(super) fn grid() -> Vec<[f32; 3]> {
    let n = BUILT_IN_TEXELS;
    (0..n * n)
        .map(|t| {
            let line = t % n % 64 < 4 || t / n % 64 < 4;
            [if line { 0.15 } else { 0.7 }; 3]
        })
        .collect()
}

/// A gradient noise over the tile, `cells` lattice cells across, its coordinates bent by a
/// noise twice as fine (meandering, not straight, zero lines).
fn warped_field(cells: usize, seed: u32) -> Vec<f32> {
    let n = BUILT_IN_TEXELS;
    let scale = cells as f32 / n as f32;
    (0..n * n)
        .map(|t| {
            let (x, y) = ((t % n) as f32 + 0.5, (t / n) as f32 + 0.5);
            let bend = |s| 0.35 * gradient_noise(x * scale * 2.0, y * scale * 2.0, 2 * cells, s);
            let (u, v) = (x * scale + bend(seed + 1), y * scale + bend(seed + 2));
            gradient_noise(u, v, cells, seed)
        })
        .collect()
}

/// Lines along the zeros of `field`, `half_width` texels either side: `exp(−(d / w)²)` of the
/// distance `d = |f| / |∇f|` to the zero (central differences, wrapping), so lines keep their
/// width where the field is steep or flat.
fn lines(field: &[f32], half_width: f32) -> Vec<f32> {
    let n = BUILT_IN_TEXELS;
    let at = |x: usize, y: usize| field[x % n + n * (y % n)];
    (0..n * n)
        .map(|t| {
            let (x, y) = (t % n + n, t / n + n);
            let dx = 0.5 * (at(x + 1, y) - at(x - 1, y));
            let dy = 0.5 * (at(x, y + 1) - at(x, y - 1));
            let d = field[t].abs() / dx.hypot(dy).max(1e-6);
            (-(d / half_width).powi(2)).exp()
        })
        .collect()
}

/// A hash of lattice point `(i, j)` (wrapped to `period`) in [0, 1).
fn lattice(i: i64, j: i64, period: usize, seed: u32) -> f32 {
    let p = period as i64;
    let (x, y) = (i.rem_euclid(p) as u32, j.rem_euclid(p) as u32);
    let mut h =
        x.wrapping_mul(0x8DA6_B343) ^ y.wrapping_mul(0xD816_3841) ^ seed.wrapping_mul(0x9E37_79B9);
    h ^= h >> 13;
    h = h.wrapping_mul(0x85EB_CA6B);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// `6t⁵ − 15t⁴ + 10t³`: a fade with no kink in slope or curvature at the lattice lines.
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// `3x² − 2x³` of `x` clamped to [0, 1].
fn smoothstep(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Smooth value noise in [0, 1] at texel `(x, y)` of the tile, `cells` lattice cells across.
fn value_noise(x: usize, y: usize, cells: usize, seed: u32) -> f32 {
    let scale = cells as f32 / BUILT_IN_TEXELS as f32;
    let (u, v) = ((x as f32 + 0.5) * scale, (y as f32 + 0.5) * scale);
    let (i, j) = (u.floor(), v.floor());
    let (fx, fy) = (fade(u - i), fade(v - j));
    let c = |di: i64, dj: i64| lattice(i as i64 + di, j as i64 + dj, cells, seed);
    let top = c(0, 0) + (c(1, 0) - c(0, 0)) * fx;
    let bottom = c(0, 1) + (c(1, 1) - c(0, 1)) * fx;
    top + (bottom - top) * fy
}

/// Gradient (Perlin) noise at `(u, v)` lattice cells, the lattice repeating every `period`.
fn gradient_noise(u: f32, v: f32, period: usize, seed: u32) -> f32 {
    let (i, j) = (u.floor(), v.floor());
    let (fx, fy) = (u - i, v - j);
    let dot = |di: f32, dj: f32| {
        let angle = std::f32::consts::TAU
            * lattice(i as i64 + di as i64, j as i64 + dj as i64, period, seed);
        angle.cos() * (fx - di) + angle.sin() * (fy - dj)
    };
    let (sx, sy) = (fade(fx), fade(fy));
    let top = dot(0.0, 0.0) + (dot(1.0, 0.0) - dot(0.0, 0.0)) * sx;
    let bottom = dot(0.0, 1.0) + (dot(1.0, 1.0) - dot(0.0, 1.0)) * sx;
    top + (bottom - top) * sy
}
