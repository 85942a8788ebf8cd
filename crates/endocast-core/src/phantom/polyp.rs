//! Polyp shapes on a wall: sessile (a hemispheroid), pedunculated (a ball on a stalk) and flat
//! (a low dome), each standing on a base point of the wall along the wall's normal.

use super::shape::segment_closest;
use glam::DVec3;

/// Height of a sessile polyp (a spheroid's half axis along the normal) over its base radius.
pub const SESSILE_HEIGHT: f64 = 0.8;
/// Height of a flat polyp over its base radius (a 6 mm flat polyp stands 1 mm high).
pub const FLAT_HEIGHT: f64 = 0.35;
/// Length of a pedunculated polyp's stalk (base to ball) over the ball's radius.
pub const STALK_LENGTH: f64 = 0.6;
/// Radius of the stalk over the ball's radius.
pub const STALK_RADIUS: f64 = 0.4;

/// What a polyp looks like.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PolypShape {
    /// Half a spheroid on the wall, [`SESSILE_HEIGHT`] × its radius high.
    Sessile,
    /// A ball on a stalk ([`STALK_LENGTH`], [`STALK_RADIUS`]).
    Pedunculated,
    /// A low dome, [`FLAT_HEIGHT`] × its radius high.
    Flat,
}

impl PolypShape {
    /// The shapes in the order placements cycle through them.
    pub const ALL: [PolypShape; 3] = [Self::Sessile, Self::Pedunculated, Self::Flat];

    /// How far the polyp stands into the lumen over its diameter.
    pub fn height_per_diameter(self) -> f64 {
        match self {
            Self::Sessile => SESSILE_HEIGHT / 2.0,
            Self::Pedunculated => 1.0 + STALK_LENGTH / 2.0,
            Self::Flat => FLAT_HEIGHT / 2.0,
        }
    }
}

/// A polyp: tissue standing on the wall at `base_vox` along `normal`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Polyp {
    /// Its shape.
    pub shape: PolypShape,
    /// Where it stands: a point of the wall's surface, voxel index.
    pub base_vox: DVec3,
    /// Unit normal of the wall there, into the lumen.
    pub normal: DVec3,
    /// Its size: the diameter of its base (of the ball for a pedunculated one), voxels.
    pub diameter_vox: f64,
    /// True when it stands on a fold's crest, false between folds.
    pub on_fold: bool,
}

impl Polyp {
    /// The point farthest into the lumen, voxel index.
    pub fn tip_vox(&self) -> DVec3 {
        self.base_vox + self.normal * self.diameter_vox * self.shape.height_per_diameter()
    }

    /// Signed distance (negative inside), voxels: exact for the ball and the stalk, to first
    /// order near the surface for the spheroids.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        let radius = self.diameter_vox / 2.0;
        match self.shape {
            PolypShape::Sessile => spheroid(p - self.base_vox, self.normal, radius, SESSILE_HEIGHT),
            PolypShape::Flat => spheroid(p - self.base_vox, self.normal, radius, FLAT_HEIGHT),
            PolypShape::Pedunculated => {
                let centre = self.base_vox + self.normal * radius * (1.0 + STALK_LENGTH);
                let ball = p.distance(centre) - radius;
                let foot = self.base_vox - self.normal * radius;
                let (_, d2) = segment_closest(foot, centre, p);
                ball.min(d2.sqrt() - STALK_RADIUS * radius)
            }
        }
    }

    /// The box holding the polyp grown by `margin`, voxel index.
    pub(crate) fn bounds(&self, margin: f64) -> (DVec3, DVec3) {
        let reach = DVec3::splat(self.diameter_vox * (1.0 + STALK_LENGTH) + margin);
        (self.base_vox - reach, self.base_vox + reach)
    }
}

/// Signed distance to the spheroid of radius `radius` across `axis` and `height · radius`
/// along it, centred at the origin (`q` relative to the centre): the first-order estimate
/// k0 (k0 − 1) / k1 of the scaled distances k0 = |q / r|, k1 = |q / r²|.
fn spheroid(q: DVec3, axis: DVec3, radius: f64, height: f64) -> f64 {
    let along = q.dot(axis);
    let across = (q - axis * along).length();
    let (a, c) = (radius, radius * height);
    let k0 = (across / a).hypot(along / c);
    let k1 = (across / (a * a)).hypot(along / (c * c));
    if k1 > 0.0 {
        k0 * (k0 - 1.0) / k1
    } else {
        -c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_shape_reaches_its_tip_and_covers_its_base() {
        for shape in PolypShape::ALL {
            let polyp = Polyp {
                shape,
                base_vox: DVec3::new(10.0, 20.0, 30.0),
                normal: DVec3::Y,
                diameter_vox: 8.0,
                on_fold: false,
            };
            let tip = polyp.tip_vox();
            assert!(polyp.signed_distance(tip).abs() < 1e-9, "{shape:?}");
            assert!(polyp.signed_distance(tip + DVec3::Y).abs() > 0.99);
            assert!(polyp.signed_distance(polyp.base_vox) < 0.0);
            // The base is as wide as the diameter says (the ball's middle for the stalked one).
            let side = match shape {
                PolypShape::Pedunculated => polyp.base_vox + DVec3::Y * 4.0 * (1.0 + STALK_LENGTH),
                _ => polyp.base_vox,
            } + DVec3::X * 4.0;
            assert!(polyp.signed_distance(side).abs() < 1e-9, "{shape:?}");
        }
    }
}
