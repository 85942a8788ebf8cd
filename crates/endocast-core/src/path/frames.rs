//! Rotation-minimising frames along a sampled curve by the double reflection method (Wang,
//! Jüttler, Zheng & Liu, "Computation of rotation minimizing frames", ACM TOG 2008).
//!
//! A frame is carried from one sample to the next by two reflections: the first, in the plane
//! bisecting the chord between the samples, maps the position onto the next one; the second, in
//! the plane bisecting the reflected and the true next tangent, lines the tangents up. The result
//! has fourth-order accuracy, never twists about the tangent more than the curve demands (zero
//! on a plane curve or a straight line), and never flips, unlike the Frenet frame, which turns
//! over at every inflection and is undefined on straight pieces.

use glam::DVec3;

/// An up vector perpendicular to `tangent` (unit): `hint` made orthogonal when it is usable,
/// otherwise the world axis least aligned with the tangent, made orthogonal.
pub(crate) fn initial_up(tangent: DVec3, hint: Option<DVec3>) -> DVec3 {
    let orthogonal = |v: DVec3| (v - tangent * v.dot(tangent)).try_normalize();
    if let Some(up) = hint.and_then(orthogonal) {
        return up;
    }
    let axis = [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .min_by(|a, b| a.dot(tangent).abs().total_cmp(&b.dot(tangent).abs()))
        .unwrap_or(DVec3::Z);
    // The least aligned axis makes an angle of at least 54.7° with any unit tangent.
    orthogonal(axis).unwrap_or(DVec3::Z)
}

/// Up vectors (unit, perpendicular to the tangents) at each of `positions` with unit
/// `tangents`, starting from `first_up`.
pub(crate) fn rotation_minimising(
    positions: &[DVec3],
    tangents: &[DVec3],
    first_up: DVec3,
) -> Vec<DVec3> {
    let mut ups = Vec::with_capacity(positions.len());
    let mut up = first_up;
    for i in 0..positions.len() {
        if i > 0 {
            up = carry(
                positions[i - 1],
                tangents[i - 1],
                up,
                positions[i],
                tangents[i],
            );
        }
        ups.push(up);
    }
    ups
}

/// The double reflection step: `up` at `(x0, t0)` carried to `(x1, t1)`.
fn carry(x0: DVec3, t0: DVec3, up: DVec3, x1: DVec3, t1: DVec3) -> DVec3 {
    let reflect = |v: DVec3, n: DVec3, nn: f64| v - n * (2.0 * n.dot(v) / nn);
    let v1 = x1 - x0;
    let c1 = v1.length_squared();
    let (up_l, t_l) = if c1 > 0.0 {
        (reflect(up, v1, c1), reflect(t0, v1, c1))
    } else {
        (up, t0)
    };
    let v2 = t1 - t_l;
    let c2 = v2.length_squared();
    let carried = if c2 > 0.0 {
        reflect(up_l, v2, c2)
    } else {
        up_l
    };
    // Re-orthogonalise against rounding so thousands of steps keep an orthonormal frame.
    (carried - t1 * carried.dot(t1))
        .try_normalize()
        .unwrap_or_else(|| initial_up(t1, Some(up)))
}
