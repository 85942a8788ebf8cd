//! The colon prone: the [`colon`](super::colon) phantom of the same options (the same colon)
//! as a second scan of the patient lying on their front, for supine/prone correspondence.
//!
//! The supine centreline is moved by a smooth displacement field — the transverse colon sags
//! towards the patient's front and the sigmoid loop is stretched outwards from its centre by
//! about 15 % — then turned 180° about the patient's long axis (the grid's `k` axis through its
//! centre), as a patient turned over on the table is. The lumen's radius, folds and polyps are
//! laid out along the moved centreline as on the supine one. Vertex `n` of the prone
//! centreline is the image of vertex `n` of the supine one, so the correspondence along the
//! colon is known exactly ([`ColonPair::prone_arc_vox`]).

use super::centreline::Centreline;
use super::colon::{grid, raster, Colon};
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;

/// How far the transverse colon sags towards the front (−j), mm at paper size.
const SAG_MM: f64 = 20.0;
/// Where the sag is centred and how wide it is, fractions of the grid (i, j, k; the width is
/// the Gaussian's σ in each).
const SAG_CENTRE: [f64; 3] = [0.5, 0.3, 0.74];
const SAG_WIDTH: [f64; 3] = [0.2, 0.2, 0.1];
/// How much the sigmoid loop is stretched outwards from its centre, in the plane across the
/// body, and where (fractions of the grid): fully within `STRETCH_INNER` of the centre, fading
/// smoothly to nothing at `STRETCH_OUTER`.
const STRETCH: f64 = 0.25;
const STRETCH_CENTRE: [f64; 3] = [0.57, 0.5, 0.36];
const STRETCH_INNER: f64 = 0.08;
const STRETCH_OUTER: f64 = 0.22;

/// Truth of the supine/prone pair: the two colons and the map between them.
#[derive(Debug, Clone, PartialEq)]
pub struct ColonPair {
    /// The supine colon, as [`colon`](super::colon) gives it for the same options.
    pub supine: Colon,
    /// The prone colon: vertex `n` of its centreline is the image of the supine vertex `n`.
    pub prone: Colon,
    /// The grid's last voxel index on each axis.
    last: DVec3,
    /// Voxels per paper millimetre.
    scale: f64,
}

impl ColonPair {
    /// The layout on a `dims` grid at `scale` voxels per paper millimetre.
    fn new(dims: [usize; 3], scale: f64) -> Self {
        let last = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) - 1.0;
        let supine_points = Colon::axis_points(dims, scale);
        let mut pair = Self {
            supine: Colon::around(Centreline::new(supine_points.clone()), scale),
            prone: Colon::around(Centreline::new(supine_points.clone()), scale),
            last,
            scale,
        };
        let prone_points = supine_points.iter().map(|&p| pair.prone_point(p)).collect();
        pair.prone = Colon::around(Centreline::new(prone_points), scale);
        pair
    }

    /// The prone image of the supine point `p_vox` (voxel index): displaced, then turned 180°
    /// about the long axis through the grid's centre. Exact for the centreline's vertices.
    pub fn prone_point(&self, p_vox: DVec3) -> DVec3 {
        let moved = p_vox + self.displacement(p_vox);
        DVec3::new(self.last.x - moved.x, self.last.y - moved.y, moved.z)
    }

    /// The prone arc length (voxels) of the point at supine arc length `s_vox`: vertices map to
    /// vertices, linearly in between.
    pub fn prone_arc_vox(&self, s_vox: f64) -> f64 {
        let (from, to) = (
            self.supine.centreline.arc_vox(),
            self.prone.centreline.arc_vox(),
        );
        let s = s_vox.clamp(0.0, self.supine.centreline.length_vox());
        let upper = from.partition_point(|&a| a <= s).clamp(1, from.len() - 1);
        let span = from[upper] - from[upper - 1];
        let t = if span > 0.0 {
            (s - from[upper - 1]) / span
        } else {
            0.0
        };
        to[upper - 1] + t * (to[upper] - to[upper - 1])
    }

    /// The smooth displacement field (voxels) at the supine point `p_vox`: the transverse
    /// colon's sag plus the sigmoid's stretch.
    fn displacement(&self, p_vox: DVec3) -> DVec3 {
        let f = p_vox / self.last;
        let scale = self.scale;
        let sag = (f - DVec3::from(SAG_CENTRE)) / DVec3::from(SAG_WIDTH);
        let sag = DVec3::NEG_Y * (SAG_MM * scale * (-0.5 * sag.length_squared()).exp());
        let from_centre = (f - DVec3::from(STRETCH_CENTRE)) * self.last;
        let r = (f - DVec3::from(STRETCH_CENTRE)).length();
        let fade = smoothstep((STRETCH_OUTER - r) / (STRETCH_OUTER - STRETCH_INNER));
        let across = DVec3::new(from_centre.x, from_centre.y, 0.0);
        sag + across * (STRETCH * fade)
    }
}

/// 0 below 0, 1 above 1, C¹-smooth in between.
fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The prone colon on the supine colon's grid (`size × size × (size · 478 / 512)`), and the pair's
/// truth.
pub fn colon_prone(options: &PhantomOptions) -> (Volume, ColonPair) {
    let (dims, scale) = grid(options);
    let truth = ColonPair::new(dims, scale);
    (raster(&truth.prone, dims, options), truth)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pair at paper size, without generating a volume.
    fn paper() -> ColonPair {
        ColonPair::new([512, 512, 478], 1.0)
    }

    #[test]
    fn prone_colon_stays_inside_the_grid_and_apart_from_itself() {
        let pair = paper();
        let line = &pair.prone.centreline;
        for (&p, &s) in line.points().iter().zip(line.arc_vox()) {
            let margin = p.min(pair.last - p).min_element();
            assert!(margin > pair.prone.radius_vox_at(s) + 5.0, "s = {s}");
        }
        let wall = 2.0 * pair.prone.max_radius_vox() + 10.0;
        for (a, &sa) in line.points().iter().zip(line.arc_vox()) {
            for (b, &sb) in line.points().iter().zip(line.arc_vox()) {
                if sb - sa > 2.0 * wall {
                    assert!(a.distance(*b) > wall, "s = {sa} and {sb}");
                }
            }
        }
        let step = line.arc_vox()[1];
        for w in line.points().windows(3) {
            let turn = (w[1] - w[0]).angle_between(w[2] - w[1]);
            assert!(step / turn.max(1e-9) > 1.5 * pair.prone.max_radius_vox());
        }
    }

    #[test]
    fn prone_is_the_supine_colon_turned_over_sagged_and_stretched() {
        let pair = paper();
        let (supine, prone) = (&pair.supine.centreline, &pair.prone.centreline);
        assert_eq!(supine.points().len(), prone.points().len());
        // Far from the sag and the stretch (the rectum, the caecum) the colon is only turned
        // over: left and right, front and back swap.
        for n in [0, supine.points().len() - 1] {
            let (a, b) = (supine.points()[n], prone.points()[n]);
            let turned = DVec3::new(pair.last.x - a.x, pair.last.y - a.y, a.z);
            assert!(b.distance(turned) < 0.01, "{a} → {b}");
        }
        // The sigmoid (the first quarter) is 10–20 % longer.
        let (from, to) = (0.1 * supine.length_vox(), 0.25 * supine.length_vox());
        let stretch = (pair.prone_arc_vox(to) - pair.prone_arc_vox(from)) / (to - from);
        assert!(
            (1.10..=1.20).contains(&stretch),
            "sigmoid stretched {stretch}"
        );
        // The transverse colon sags by up to 20 mm.
        let transverse = supine.points().iter().filter(|p| p.z > 0.6 * pair.last.z);
        let sag = |p: &DVec3| -pair.displacement(*p).y;
        let most = transverse.map(sag).fold(0.0, f64::max);
        assert!((15.0..=25.0).contains(&most), "sagged at most {most} mm");
        // The arc map is monotone and ends at the ends.
        assert_eq!(pair.prone_arc_vox(0.0), 0.0);
        assert!((pair.prone_arc_vox(supine.length_vox()) - prone.length_vox()).abs() < 1e-9);
    }
}
