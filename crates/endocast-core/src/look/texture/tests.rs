//! The textures: tiling, sampling, the default's contrast band, seamless tri-planar blending and
//! mip levels that band-limit what a pixel reads.

use super::*;

/// The luminance RMS contrast band of the default texture's detail on the tissue (std / mean of
/// `1 + strength (2 L − 1)` at the default strength): visible, but the shading stays the main
/// shape cue.
pub(in crate::look) const CONTRAST_BAND: std::ops::RangeInclusive<f32> = 0.05..=0.15;

/// The luminance of a colour.
fn luma(rgb: [f32; 3]) -> f32 {
    LUMA.iter().zip(rgb).map(|(w, c)| w * c).sum()
}

/// Mean and standard deviation.
fn mean_std(values: &[f32]) -> (f32, f32) {
    let n = values.len() as f64;
    let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let var = values
        .iter()
        .map(|&v| (f64::from(v) - mean).powi(2))
        .sum::<f64>()
        / n;
    (mean as f32, var.sqrt() as f32)
}

/// The texels of level `level` (their colours).
fn level_texels(t: &Texture, level: usize) -> Vec<[f32; 3]> {
    let l = t.pyramid.levels[level];
    let texels = &t.pyramid.texels[l.start..l.start + l.width * l.height];
    texels
        .iter()
        .map(|&p| std::array::from_fn(|c| pyramid::channel(p, c)))
        .collect()
}

/// The RMS contrast of `lumas` as detail on the tissue at the default strength.
fn detail_contrast(lumas: &[f32]) -> f32 {
    let strength = crate::look::Shading::default().texture_strength;
    let detail: Vec<f32> = lumas
        .iter()
        .map(|l| 1.0 + strength * (2.0 * l - 1.0))
        .collect();
    let (mean, std) = mean_std(&detail);
    std / mean
}

#[test]
fn built_in_textures_tile_and_the_mucosa_is_low_contrast_with_vessels() {
    let mucosa = Texture::built_in("Mucosa").unwrap();
    assert_eq!(mucosa.size(), [512, 512]);
    assert_eq!(mucosa.levels(), 10);
    assert!(mucosa.is_colour());
    let texels = level_texels(&mucosa, 0);
    let lumas: Vec<f32> = texels.iter().map(|&c| luma(c)).collect();
    let contrast = detail_contrast(&lumas);
    assert!(CONTRAST_BAND.contains(&contrast), "contrast {contrast}");
    // Vessels: sparse texels well below the base, redder than it (green falls more than red).
    let (mean, std) = mean_std(&lumas);
    let vessels: Vec<&[f32; 3]> = texels
        .iter()
        .zip(&lumas)
        .filter(|(_, &l)| l < mean - 2.5 * std)
        .map(|(c, _)| c)
        .collect();
    let share = vessels.len() as f32 / texels.len() as f32;
    assert!((0.003..0.06).contains(&share), "vessel share {share}");
    let red_over_green = vessels.iter().map(|c| c[0] - c[1]).sum::<f32>() / vessels.len() as f32;
    assert!(red_over_green > 0.05, "{red_over_green}");
    // Seamless: one tile over is the same colour, and the tile's edge is no edge.
    for level in [0, 3] {
        let a = mucosa.sample(0.3, 0.7, level);
        let b = mucosa.sample(1.3, -0.3, level);
        assert!(a.iter().zip(b).all(|(a, b)| (a - b).abs() < 1e-5));
    }
    let jump = |u: f32, v: f32| {
        (luma(mucosa.sample(u, v, 0)) - luma(mucosa.sample(u + 1.0 / 512.0, v, 0))).abs()
    };
    let across_edge: f32 = (0..512).map(|j| jump(-0.5 / 512.0, j as f32 / 512.0)).sum();
    let inside: f32 = (0..512)
        .map(|j| jump(0.5 - 0.5 / 512.0, j as f32 / 512.0))
        .sum();
    assert!(
        across_edge < 1.5 * inside,
        "{across_edge} at the edge, {inside} inside"
    );
    assert!(Texture::built_in("none").is_none());
    assert!(Texture::built_in("marble").is_none());
    let grid = Texture::built_in("grid").unwrap();
    assert!(!grid.is_colour());
    assert!(grid.sample(1.0 / 512.0, 0.5, 0)[0] < grid.sample(32.0 / 512.0, 32.0 / 512.0, 0)[0]);
}

#[test]
fn sampling_wraps() {
    let t = Texture::from_luma(3, 1, vec![0.0, 0.5, 1.0]).unwrap();
    let half = 128.0 / 255.0;
    // Between the last texel and the first (wrapped), and at a texel's centre.
    for u in [0.0, 3.0, -1.0] {
        assert!((t.sample(u, 0.0, 0)[0] - 0.5).abs() < 1e-5, "{u}");
    }
    assert_eq!(t.sample(0.5, 0.0, 0), [half; 3]);
    assert_eq!(t.sample(-4.5, 0.0, 0), [half; 3]);
    assert!((t.sample(1.0 / 3.0, 0.0, 0)[0] - 0.5 * half).abs() < 1e-5);
    // Past the last level, the last (one texel: the mean).
    assert!((t.sample(0.1, 0.0, 99)[0] - 0.5).abs() < 1.0 / 255.0);
}

#[test]
fn triplanar_takes_the_plane_facing_the_normal() {
    let t = Texture::from_luma(2, 1, vec![0.0, 1.0]).unwrap();
    // Facing z: the (x, y) projection, which varies along x.
    let p = Vec3::new(0.75, 0.2, 0.25);
    assert_eq!(t.triplanar(p, Vec3::Z, 0.0), t.sample(0.75, 0.2, 0));
    // Facing x: the (y, z) projection.
    assert_eq!(t.triplanar(p, Vec3::X, 0.0), t.sample(0.2, 0.25, 0));
    // Halfway: both, their deviations from the mean (0.5) summed over √(Σ w²) = 1/√2.
    let mixed = t.triplanar(p, Vec3::new(1.0, 0.0, 1.0).normalize(), 0.0)[0];
    let deviations = t.sample(0.75, 0.2, 0)[0] + t.sample(0.2, 0.25, 0)[0] - 1.0;
    assert!(
        (mixed - (0.5 + deviations / 2f32.sqrt())).abs() < 1e-5,
        "{mixed}"
    );
    // A NaN normal reads the (x, y) projection; a footprint of a whole tile, the mean.
    assert_eq!(t.triplanar(p, Vec3::NAN, 0.0), t.sample(0.75, 0.2, 0));
    assert!((t.triplanar(p, Vec3::Z, 1.0)[0] - 0.5).abs() < 1.0 / 255.0);
}

#[test]
fn bad_textures_are_refused() {
    assert!(matches!(
        Texture::from_luma(0, 4, vec![]),
        Err(TextureError::BadSize { .. })
    ));
    assert!(matches!(
        Texture::from_luma(2, 2, vec![0.5; 3]),
        Err(TextureError::BadSize { .. })
    ));
    assert!(Texture::from_luma(1, 1, vec![f32::NAN]).is_err());
    assert!(Texture::from_rgb(1, 1, vec![[0.5, f32::INFINITY, 0.5]]).is_err());
    assert_eq!(
        Texture::from_luma(1, 2, vec![0.5, 1.5]).map(|_| ()),
        Err(TextureError::BadValue {
            index: 1,
            value: 1.5
        })
    );
}

/// The standard deviation of the tri-planar luminance over `count` points of the plane
/// through the origin with unit normal `n`, at the finest level.
fn contrast_on_plane(t: &Texture, n: Vec3, count: usize) -> f32 {
    let a = n.any_orthonormal_vector();
    let b = n.cross(a);
    let values: Vec<f32> = (0..count)
        .map(|i| {
            let (s, r) = ((i % 97) as f32 * 0.0731, (i / 97) as f32 * 0.0613);
            luma(t.triplanar(a * s + b * r, n, 0.0))
        })
        .collect();
    mean_std(&values).1
}

#[test]
fn the_blend_keeps_the_contrast_across_the_45_degree_lines() {
    // Normals turning from x to y: through the zone where the (y, z) and (x, z) projections
    // blend. A plain weighted average of two unrelated patterns would fall to 1/√2 of the
    // contrast at 45° (a grey band: the seam); the blend keeps it within 15 %.
    let mucosa = Texture::built_in("mucosa").unwrap();
    let facing = contrast_on_plane(&mucosa, Vec3::X, 4000);
    for degrees in [30.0f32, 38.0, 42.0, 45.0, 48.0, 55.0, 60.0] {
        let r = degrees.to_radians();
        let n = Vec3::new(r.cos(), r.sin(), 0.0);
        let ratio = contrast_on_plane(&mucosa, n, 4000) / facing;
        assert!((0.85..=1.15).contains(&ratio), "{degrees}°: {ratio}");
    }
    // The same points averaged plainly do show the seam.
    let n = Vec3::new(1.0, 1.0, 0.0).normalize();
    let (a, b) = (
        n.any_orthonormal_vector(),
        n.cross(n.any_orthonormal_vector()),
    );
    let plain: Vec<f32> = (0..4000)
        .map(|i| {
            let p = a * ((i % 97) as f32 * 0.0731) + b * ((i / 97) as f32 * 0.0613);
            let x = luma(mucosa.sample(p.y, p.z, 0));
            let y = luma(mucosa.sample(p.x, p.z, 0));
            0.5 * (x + y)
        })
        .collect();
    let ratio = mean_std(&plain).1 / facing;
    assert!(ratio < 0.8, "a plain average keeps {ratio} of the contrast");
}

/// `t` with its finest level only: what a lookup without mip mapping reads.
pub(in crate::look) fn without_mips(t: &Texture) -> Texture {
    let mut t = t.clone();
    t.pyramid.levels.truncate(1);
    t
}

/// The luminance variance of level `level`'s texels.
pub(in crate::look) fn level_variance(t: &Texture, level: usize) -> f32 {
    let lumas: Vec<f32> = level_texels(t, level).into_iter().map(luma).collect();
    mean_std(&lumas).1.powi(2)
}
