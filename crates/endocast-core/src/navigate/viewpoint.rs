//! Where to put the camera when the user gave none: at the most central point of the largest
//! relevant lumen, looking along it.

use super::aorta::{find_aorta, Aorta};
use super::central::{find_central, CENTRAL_ML};
use super::colon::find_colon;
use super::distance::DistanceField;
use super::faces::Faces;
use super::joint::{find_joint, Joint, JOINT_REACH_MM, MAX_JOINT_GAP_MM};
use super::lumen::{Lumen, LumenSide};
use super::nasal::{find_nasal_cavity, NasalCavity, MIN_ROUTE_MM, SCOPE_RADIUS_MM};
use super::preset::{Central, LumenChoice, LumenChoiceError};
use super::trachea::find_trachea;
use crate::camera::framing_pose;
use crate::pose::Pose;
use crate::presets::Structure;
use crate::Volume;
use glam::{DMat3, DVec3};

/// The neighbourhood whose shape gives the viewing direction, in multiples of the lumen's largest
/// distance to the wall: three radii each way is a tube segment three times longer than wide,
/// long enough to have a clear axis, short enough to follow a winding colon.
const AXIS_REACH: f64 = 3.0;
/// Power iterations for the principal axis (the ratio of the two largest eigenvalues of an
/// elongated neighbourhood is at least 2, so 64 steps converge far below a degree).
const POWER_STEPS: usize = 64;

/// A default camera for `volume`: the eye at the most central voxel (largest distance to the
/// wall; among voxels within half a voxel of it, the one nearest the lumen's centroid) of the
/// largest lumen component on `side` of `threshold_hu`, looking along the lumen's local long
/// axis (the principal axis of the lumen voxels within three wall distances of the eye), towards
/// the longer free run, with up as near the patient's anterior (−y, LPS) as the view allows.
///
/// For a dark lumen ([`LumenSide::Below`]: CT air, CSF on T1) components touching the volume's
/// border are passed over when another exists: the air around the patient touches it, the colon
/// and airways do not. For a bright lumen (contrast, CSF on T2) the largest is taken. `None`
/// when the threshold is not finite or no voxel lies on the lumen side.
pub fn default_viewpoint(volume: &Volume, threshold_hu: f64, side: LumenSide) -> Option<Pose> {
    let lumen = Lumen::largest(volume, threshold_hu, side, side == LumenSide::Below).ok()??;
    Some(viewpoint_in(volume, &lumen))
}

/// The camera inside `lumen` (a component of `volume`): at its most central voxel
/// [`FACE_MARGIN_MM`](super::FACE_MARGIN_MM) from the volume's faces (where the lumen reaches
/// that far in), looking along its local long axis towards the longer free run (see
/// [`default_viewpoint`]).
pub fn viewpoint_in(volume: &Volume, lumen: &Lumen) -> Pose {
    let field = DistanceField::new(lumen, volume.geometry());
    let eye_voxel = most_central(volume, lumen, &field);
    let eye_mm = field.world_of_voxel(eye_voxel);
    let reach_mm = AXIS_REACH * field.max_mm();
    let axis = principal_axis(lumen, &field, eye_mm, reach_mm);
    let forward = if free_run(&field, eye_mm, axis) >= free_run(&field, eye_mm, -axis) {
        axis
    } else {
        -axis
    };
    looking_along(eye_mm, forward, field.max_mm().max(1.0))
}

/// The camera at `eye_mm` looking along unit `forward` at a point `distance_mm` ahead, with up
/// as near the patient's anterior (−y, LPS) as the view allows (superior when looking nearly
/// along y).
pub(crate) fn looking_along(eye_mm: DVec3, forward: DVec3, distance_mm: f64) -> Pose {
    let anterior = DVec3::NEG_Y;
    let reference = if anterior.dot(forward).abs() < 0.9 {
        anterior
    } else {
        DVec3::Z
    };
    let up = (reference - forward * reference.dot(forward)).normalize();
    Pose {
        eye_mm,
        look_at_mm: eye_mm + forward * distance_mm,
        up,
    }
}

/// The camera a command uses when the user placed none, and why it was chosen.
#[derive(Debug, Clone, PartialEq)]
pub enum DefaultView {
    /// Inside the structure the lumen choice means (see [`default_view`]).
    InsideLumen {
        /// The camera.
        pose: Pose,
        /// The lumen's region-growing threshold, physical units.
        threshold: f64,
        /// The lumen's side of it.
        side: LumenSide,
        /// The structure's lumen: its mask, and what a path through it must stay in.
        lumen: Box<Lumen>,
        /// Where a path through it ends, world mm, for a tube whose far end is known (the
        /// aorta's lowest section, the nasopharynx behind the nasal passages); `None`: at the
        /// farthest point.
        end_mm: Option<DVec3>,
        /// What was found, in words (e.g. "aorta: 402 mm, radius 11.3 mm"); beginning with
        /// [`NOT_CONFIDENT`] where the finder is not sure (see [`DefaultView::confident`]).
        what: String,
    },
    /// The whole volume framed from the front (see [`crate::camera::framing_pose`]).
    Framing {
        /// The camera.
        pose: Pose,
        /// Why not from inside a lumen.
        reason: FramingReason,
    },
}

impl DefaultView {
    /// The camera, however it was chosen.
    pub fn pose(&self) -> Pose {
        match self {
            Self::InsideLumen { pose, .. } | Self::Framing { pose, .. } => *pose,
        }
    }

    /// Whether the view is inside the structure its finder was sure of: false for a `what`
    /// beginning with [`NOT_CONFIDENT`], and for a view framing the volume.
    pub fn confident(&self) -> bool {
        matches!(self, Self::InsideLumen { what, .. } if !what.starts_with(NOT_CONFIDENT))
    }
}

/// How a [`DefaultView::InsideLumen`]'s `what` begins when its finder is not sure it found the
/// structure the preset means; the rest of the line says what it found instead and what it
/// would need.
pub const NOT_CONFIDENT: &str = "not confident: ";

/// Why a [`DefaultView`] frames the volume from outside.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum FramingReason {
    /// No lumen was asked for (no preset, or one that is no procedure in a lumen).
    NoLumenAsked,
    /// The lumen choice gives no threshold.
    Choice(LumenChoiceError),
    /// No voxel of the volume lies on `side` of `threshold`.
    NoLumen {
        /// The region-growing threshold, physical units.
        threshold: f64,
        /// The lumen's side of it.
        side: LumenSide,
    },
}

/// A structure found: its lumen, the camera in it, the threshold it was grown at, the path's
/// end where known, and what it is in words.
struct Found {
    lumen: Lumen,
    pose: Pose,
    threshold: f64,
    end_mm: Option<DVec3>,
    what: String,
}

impl Found {
    /// The camera at `lumen`'s most central point ([`viewpoint_in`]), described as `name`
    /// with its volume.
    fn central(volume: &Volume, lumen: Lumen, threshold: f64, name: &str) -> Self {
        let s = volume.geometry().spacing_mm();
        let ml = lumen.voxel_count() as f64 * s.x * s.y * s.z / 1000.0;
        Self {
            pose: viewpoint_in(volume, &lumen),
            what: format!("{name}: {ml:.1} ml"),
            lumen,
            threshold,
            end_mm: None,
        }
    }

    /// The same, its `what` beginning with [`NOT_CONFIDENT`] and ending with `why` in
    /// brackets (what the finder missed or would need).
    fn doubted(self, why: &str) -> Self {
        Self {
            what: format!("{NOT_CONFIDENT}{} ({why})", self.what),
            ..self
        }
    }
}

/// The default camera for `volume`: with a `lumen` choice (an endoscopic preset), inside the
/// structure it means — the airway tree from the trachea, the aorta, the colon, the nasal
/// passages, the central CSF component, a joint space, else the largest lumen
/// ([`default_viewpoint`]) — looking along it, saying in its `what` when the finder is not
/// sure ([`NOT_CONFIDENT`]); without one, or when the choice gives no threshold or the scan no
/// such lumen, the whole volume framed from the front for the vertical field of view `fov_deg`
/// ([`framing_pose`]), with the reason.
pub fn default_view(volume: &Volume, lumen: Option<&LumenChoice<'_>>, fov_deg: f64) -> DefaultView {
    let framing = |reason| DefaultView::Framing {
        pose: framing_pose(volume.geometry(), fov_deg),
        reason,
    };
    let Some(choice) = lumen.filter(|c| c.preset.is_none_or(|p| p.lumen.is_some())) else {
        return framing(FramingReason::NoLumenAsked);
    };
    let (threshold, side) = match choice.resolve() {
        Ok(lumen) => lumen,
        Err(error) => return framing(FramingReason::Choice(error)),
    };
    let structure = choice.preset.and_then(|p| p.lumen).map(|l| l.structure);
    match find_structure(volume, threshold, side, choice.within, structure) {
        Some(found) => DefaultView::InsideLumen {
            pose: found.pose,
            threshold: found.threshold,
            side,
            lumen: Box::new(found.lumen),
            end_mm: found.end_mm,
            what: found.what,
        },
        None => framing(FramingReason::NoLumen { threshold, side }),
    }
}

/// The structure a preset means (see [`default_view`]); a specific finder that finds nothing
/// falls back to the largest lumen, not confident, saying what it missed.
fn find_structure(
    volume: &Volume,
    threshold: f64,
    side: LumenSide,
    within: Option<Central>,
    structure: Option<Structure>,
) -> Option<Found> {
    let largest = |missing: Option<&str>| {
        let lumen = Lumen::largest(volume, threshold, side, side == LumenSide::Below).ok()??;
        let found = Found::central(volume, lumen, threshold, "largest lumen");
        Some(match missing {
            Some(why) => found.doubted(why),
            None => found,
        })
    };
    match (within, structure, side) {
        (Some(central), _, _) => central_lumen(volume, threshold, side, &central),
        (None, Some(Structure::Trachea), LumenSide::Below) => find_trachea(volume, threshold)
            .map(|(tree, t)| Found::central(volume, tree, t, "airway tree from the trachea"))
            .or_else(|| {
                largest(Some(
                    "no trachea found: it needs a round air section in the top axial slices",
                ))
            }),
        (None, Some(Structure::Aorta), _) => find_aorta(volume, threshold, side)
            .map(|aorta| aorta_found(aorta, threshold))
            .or_else(|| {
                largest(Some(
                    "no aorta found: it needs a chain of round contrast sections of 7-16 mm radius \
                     in the axial slices",
                ))
            }),
        (None, Some(Structure::Colon), LumenSide::Below) => find_colon(volume, threshold)
            .map(|colon| {
                Found::central(
                    volume,
                    colon,
                    threshold,
                    "colon (largest gas inside the body)",
                )
            })
            .or_else(|| {
                largest(Some(
                    "no colon found: it needs gas inside the body, not lung",
                ))
            }),
        (None, Some(Structure::NasalCavity), LumenSide::Below) => {
            find_nasal_cavity(volume, threshold)
                .map(|nose| nasal_found(volume, nose, threshold))
                .or_else(|| {
                    largest(Some(
                        "no nasal cavity found: it needs air enclosed in the axial slices across \
                         the head's midline",
                    ))
                })
        }
        (None, Some(Structure::Joint), LumenSide::Below) => find_joint(volume, threshold)
            .map(|joint| joint_found(volume, joint, threshold))
            .or_else(|| {
                largest(Some(
                    "no joint space found: it needs two bones' marrow, thicker than the fat around \
                     them, with a dark gap between them",
                ))
            }),
        _ => largest(None),
    }
}

/// The camera in the joint space between the bones (at its darkest point where they come
/// closest) looking along it: along the principal axis of the joint space within
/// [`JOINT_REACH_MM`], less its part along the bones' axis, towards the longer free run. Not
/// confident where the dark gap there is wider than [`MAX_JOINT_GAP_MM`].
fn joint_found(volume: &Volume, joint: Joint, threshold: f64) -> Found {
    let field = DistanceField::new(&joint.space, volume.geometry());
    let eye = joint.gap_mm;
    let bones = (joint.cores_mm[1] - joint.cores_mm[0]).normalize_or_zero();
    let axis = principal_axis(&joint.space, &field, eye, JOINT_REACH_MM);
    let along = (axis - bones * axis.dot(bones))
        .try_normalize()
        .unwrap_or_else(|| bones.any_orthonormal_vector());
    let forward = if free_run(&field, eye, along) >= free_run(&field, eye, -along) {
        along
    } else {
        -along
    };
    let s = volume.geometry().spacing_mm();
    let what = format!(
        "joint space between the two largest bones: a gap of {:.1} mm, {:.1} ml around it",
        joint.width_mm,
        joint.space.voxel_count() as f64 * s.x * s.y * s.z / 1000.0
    );
    let found = Found {
        pose: looking_along(eye, forward, JOINT_REACH_MM),
        what,
        lumen: joint.space,
        threshold,
        end_mm: None,
    };
    if joint.width_mm <= MAX_JOINT_GAP_MM {
        found
    } else {
        found.doubted(&format!(
            "a joint space is at most {MAX_JOINT_GAP_MM} mm wide: it needs the bones nearer"
        ))
    }
}

/// The camera at the nasal cavity's start looking back (posterior, +y in LPS) along the
/// passages; the mask, the route an endoscope of [`SCOPE_RADIUS_MM`] takes from there, the
/// path's end at its back (the nasopharynx). Not confident where the start is too narrow for
/// the endoscope (the mask is then the passages) or the route shorter than [`MIN_ROUTE_MM`].
fn nasal_found(volume: &Volume, nose: NasalCavity, threshold: f64) -> Found {
    let s = volume.geometry().spacing_mm();
    let ml = |lumen: &Lumen| lumen.voxel_count() as f64 * s.x * s.y * s.z / 1000.0;
    let field = DistanceField::new(&nose.passages, volume.geometry());
    let radius = field.distance_mm(nose.start_mm).max(1.0);
    let what = format!(
        "nasal cavity: {:.1} ml with the sinuses and pharynx joined to it ({:.1} ml of \
         passages near the midline, {:.1} ml of them wide enough for an endoscope of \
         {SCOPE_RADIUS_MM} mm radius, {:.0} mm from front to back)",
        ml(&nose.lumen),
        ml(&nose.passages),
        nose.route.as_ref().map_or(0.0, ml),
        nose.end_mm.distance(nose.start_mm),
    );
    let doubt = match &nose.route {
        None => Some(format!(
            "the start is narrower than the endoscope: it needs passages of {SCOPE_RADIUS_MM} \
             mm radius"
        )),
        Some(_) if nose.end_mm.distance(nose.start_mm) < MIN_ROUTE_MM => Some(format!(
            "a route under {MIN_ROUTE_MM} mm: it needs the passages to the choanae in the \
             scan, wider than the endoscope"
        )),
        Some(_) => None,
    };
    let found = Found {
        pose: looking_along(nose.start_mm, DVec3::Y, radius),
        what,
        lumen: nose.route.unwrap_or(nose.passages),
        threshold,
        end_mm: Some(nose.end_mm),
    };
    match doubt {
        Some(why) => found.doubted(&why),
        None => found,
    }
}

/// Sections below the aorta's top where the camera starts: a little inside, so the whole
/// circle of the wall is in view.
const AORTA_START_SECTION: usize = 2;
/// How far ahead the camera looks along the aorta, in radii.
const AORTA_LOOK_RADII: f64 = 4.0;

/// The camera near the aorta's top looking down along it (with the flow), the path's end at
/// its lowest section.
fn aorta_found(aorta: Aorta, threshold: f64) -> Found {
    let centres = &aorta.centres_mm;
    let start = AORTA_START_SECTION.min(centres.len() - 1);
    let eye = centres[start];
    let ahead = centres[start..]
        .iter()
        .find(|c| c.distance(eye) >= AORTA_LOOK_RADII * aorta.radius_mm)
        .copied()
        .unwrap_or(aorta.bottom_mm);
    let forward = (ahead - eye).try_normalize().unwrap_or(DVec3::NEG_Z);
    Found {
        pose: looking_along(eye, forward, aorta.radius_mm),
        what: format!(
            "aorta: {:.0} mm along the slices, radius {:.1} mm (median), top at z {:.1} mm",
            aorta.length_mm, aorta.radius_mm, aorta.top_mm.z
        ),
        end_mm: Some(aorta.bottom_mm),
        lumen: aorta.lumen,
        threshold,
    }
}

/// The camera in the [`Central`] structure (see [`find_central`]); not confident where its
/// size is not a pair of lateral ventricles' ([`CENTRAL_ML`]).
fn central_lumen(
    volume: &Volume,
    threshold: f64,
    side: LumenSide,
    central: &Central,
) -> Option<Found> {
    let (lumen, t, sized) = find_central(volume, threshold, side, central)?;
    let found = Found::central(volume, lumen, t, "central CSF component");
    Some(if sized {
        found
    } else {
        found.doubted(&format!(
            "the lateral ventricles, together or one, hold {}-{} ml: it needs a CSF/tissue \
             contrast at which they part from the CSF around the brain",
            CENTRAL_ML.start(),
            CENTRAL_ML.end()
        ))
    })
}

/// The voxel nearest the lumen's centroid among those within half a voxel of the largest
/// distance to the wall (ties on a lattice are common: a straight tube's whole axis), both
/// among the voxels [`FACE_MARGIN_MM`](super::FACE_MARGIN_MM) from the volume's faces where
/// the lumen has any.
fn most_central(volume: &Volume, lumen: &Lumen, field: &DistanceField) -> [usize; 3] {
    let faces = Faces::of(volume);
    let any_clear = lumen.voxels().any(|v| faces.clear(v));
    let eligible = |v: &[usize; 3]| !any_clear || faces.clear(*v);
    let mut sum = DVec3::ZERO;
    for v in lumen.voxels() {
        sum += field.world_of_voxel(v);
    }
    let centroid = sum / lumen.voxel_count() as f64;
    let widest = lumen
        .voxels()
        .filter(eligible)
        .map(|v| field.distance_at_voxel(v))
        .fold(0.0, f64::max);
    let floor = widest - 0.5 * field.min_spacing_mm();
    let mut best = (f64::INFINITY, field.max_voxel());
    for v in lumen.voxels().filter(eligible) {
        if field.distance_at_voxel(v) >= floor {
            let d = field.world_of_voxel(v).distance_squared(centroid);
            if d < best.0 {
                best = (d, v);
            }
        }
    }
    best.1
}

/// The unit principal axis (largest variance) of the lumen voxels within `reach_mm` of
/// `centre_mm`, by power iteration on their covariance.
fn principal_axis(lumen: &Lumen, field: &DistanceField, centre_mm: DVec3, reach_mm: f64) -> DVec3 {
    let near: Vec<DVec3> = lumen
        .voxels()
        .map(|v| field.world_of_voxel(v) - centre_mm)
        .filter(|p| p.length() <= reach_mm)
        .collect();
    let n = near.len().max(1) as f64;
    let mean = near.iter().copied().sum::<DVec3>() / n;
    let mut cov = DMat3::ZERO;
    for &p in &near {
        let q = p - mean;
        cov += DMat3::from_cols(q * q.x, q * q.y, q * q.z);
    }
    let mut axis = DVec3::new(0.6, 0.5, 0.62).normalize();
    for _ in 0..POWER_STEPS {
        match (cov * axis).try_normalize() {
            Some(next) => axis = next,
            None => break,
        }
    }
    axis
}

/// How far (mm) the eye can look from `from_mm` along unit `dir` before the distance to the wall
/// drops below a voxel.
fn free_run(field: &DistanceField, from_mm: DVec3, dir: DVec3) -> f64 {
    let step = field.min_spacing_mm();
    let limit = field.diagonal_mm();
    let mut t = 0.0;
    while t < limit && field.distance_mm(from_mm + dir * (t + step)) >= step {
        t += step;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};

    fn options(size: usize) -> PhantomOptions {
        PhantomOptions {
            size,
            ..Default::default()
        }
    }

    fn forward(pose: &Pose) -> DVec3 {
        (pose.look_at_mm - pose.eye_mm).normalize()
    }

    #[test]
    fn straight_tube_view_is_down_the_middle() {
        let (volume, tube) = phantom::straight_tube(&options(64));
        let pose = default_viewpoint(&volume, -480.0, LumenSide::Below).unwrap();
        // World (0, 0, 0) is the grid's centre, on the axis.
        assert!(pose.eye_mm.truncate().length() <= 1.0, "{}", pose.eye_mm);
        assert!(pose.eye_mm.z.abs() < 0.25 * tube.centreline.length_vox());
        assert!(
            forward(&pose).z.abs() > 15f64.to_radians().cos(),
            "{pose:?}"
        );
        assert!(pose.up.dot(forward(&pose)).abs() < 1e-9);
        assert!((pose.up.length() - 1.0).abs() < 1e-9);
        assert!(default_viewpoint(&volume, f64::NAN, LumenSide::Below).is_none());
        assert!(default_viewpoint(&volume, -5000.0, LumenSide::Below).is_none());
    }

    #[test]
    fn colon_view_is_well_inside_and_along_the_lumen() {
        let (volume, colon) = phantom::colon(&options(128));
        let pose = default_viewpoint(&volume, -480.0, LumenSide::Below).unwrap();
        let to_vox = volume.geometry().voxel_from_world();
        let (s, off) = colon
            .centreline
            .closest(to_vox.transform_point3(pose.eye_mm));
        assert!(
            off < 0.25 * colon.radius_vox_at(s),
            "{off} voxel off the axis"
        );
        let tangent = colon.centreline.tangent_at(s);
        let cos = forward(&pose).dot(tangent).abs();
        assert!(
            cos > 15f64.to_radians().cos(),
            "{}°",
            cos.acos().to_degrees()
        );
    }

    #[test]
    fn default_view_is_inside_an_endoscopic_presets_lumen_else_framing() {
        use crate::presets::Preset;
        let (volume, _) = phantom::straight_tube(&options(32));
        let colonoscopy = LumenChoice {
            preset: Preset::find("colonoscopy"),
            ..LumenChoice::default()
        };
        let view = default_view(&volume, Some(&colonoscopy), 90.0);
        assert!(
            matches!(view, DefaultView::InsideLumen { threshold, side: LumenSide::Below, .. } if threshold == -500.0),
            "{view:?}"
        );
        assert_eq!(
            view.pose(),
            default_viewpoint(&volume, -500.0, LumenSide::Below).unwrap()
        );
        let framed = framing_pose(volume.geometry(), 90.0);
        let ramp = LumenChoice {
            preset: Preset::find("ramp"),
            ..LumenChoice::default()
        };
        for (choice, reason) in [
            (None, FramingReason::NoLumenAsked),
            (Some(ramp), FramingReason::NoLumenAsked),
            (
                Some(LumenChoice::default()),
                FramingReason::Choice(LumenChoiceError::Underdetermined),
            ),
            (
                Some(LumenChoice {
                    threshold: Some(-5000.0),
                    ..colonoscopy
                }),
                FramingReason::NoLumen {
                    threshold: -5000.0,
                    side: LumenSide::Below,
                },
            ),
        ] {
            assert_eq!(
                default_view(&volume, choice.as_ref(), 90.0),
                DefaultView::Framing {
                    pose: framed,
                    reason
                }
            );
        }
    }

    #[test]
    fn a_finder_that_finds_nothing_says_so_in_one_line_and_still_gives_a_view_inside() {
        use crate::presets::Preset;
        let (volume, _) = phantom::straight_tube(&options(32));
        let arthroscopy = LumenChoice {
            preset: Preset::find("arthroscopy"),
            ..LumenChoice::default()
        };
        // A tube has no bones: the largest lumen, said to be a guess, with what was missing.
        let view = default_view(&volume, Some(&arthroscopy), 90.0);
        let DefaultView::InsideLumen { what, .. } = &view else {
            panic!("{view:?}");
        };
        assert!(
            what.starts_with("not confident: largest lumen")
                && what.contains("no joint space found: it needs")
                && !what.contains('\n'),
            "{what}"
        );
        assert!(!view.confident());
        assert!(!default_view(&volume, None, 90.0).confident());
    }
}
