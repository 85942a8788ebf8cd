//! What the viewer shows: a scan, where it came from, its renderer, its histogram and the lumen
//! the camera flies through (the distance field the collider reads).

use endocast_core::annotate::ScanIdentity;
use endocast_core::navigate::{seed_voxel, Collider, DistanceField, Lumen, LumenSide};
use endocast_core::render::Renderer;
use endocast_core::Volume;
use endocast_io::case::ScanFacts;
pub use endocast_io::case::ScanSource;
use endocast_io::SeriesSummary;
use glam::DVec3;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Bins of the value histogram under the isovalue slider.
pub const HISTOGRAM_BINS: usize = 128;

/// Numbers the lumens found, so views of one (the overview) know when it changed.
static LUMENS_FOUND: AtomicU64 = AtomicU64::new(0);

/// The lumen the camera is in: its voxels, its distance field and the camera's radius.
#[derive(Debug)]
pub struct Navigation {
    lumen: Arc<Lumen>,
    id: u64,
    field: DistanceField,
    radius_mm: f64,
}

impl Navigation {
    /// The lumen 6-connected to the voxel nearest `eye_mm` on `side` of `threshold`; `None`
    /// when the eye is outside the volume or in the wall. The camera's radius is two voxels (the
    /// collider's bound holds against the wall to within about a voxel), or half the lumen's
    /// widest radius in a lumen narrower than that.
    pub fn around(volume: &Volume, eye_mm: DVec3, threshold: f64, side: LumenSide) -> Option<Self> {
        let seed = seed_voxel(volume, eye_mm).ok()?;
        let lumen = Lumen::from_seed(volume, seed, threshold, side).ok()?;
        let field = DistanceField::new(&lumen, volume.geometry());
        let radius_mm = (2.0 * field.min_spacing_mm()).min(0.5 * field.max_mm());
        Some(Self {
            lumen: Arc::new(lumen),
            id: LUMENS_FOUND.fetch_add(1, Ordering::Relaxed),
            field,
            radius_mm,
        })
    }

    /// The lumen's voxels.
    pub fn lumen(&self) -> &Arc<Lumen> {
        &self.lumen
    }

    /// A number of this lumen, different for every lumen found in this process.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// The collider for a camera at `eye_mm`: the camera's radius, shrunk to fit where the eye
    /// already is nearer the wall than that (a jump, a reopened case), so it can always move
    /// on; `None` outside the lumen.
    pub fn collider_at(&self, eye_mm: DVec3) -> Option<Collider<'_>> {
        let room = 0.9 * self.field.distance_mm(eye_mm);
        Collider::new(&self.field, self.radius_mm.min(room)).ok()
    }

    /// The point of the cross-section through `eye_mm` (perpendicular to `forward`) farthest
    /// from the wall nearby: climbs the distance field within that plane in quarter-voxel
    /// steps until it no longer rises ("centre in lumen").
    pub fn centred(&self, eye_mm: DVec3, forward: DVec3) -> DVec3 {
        let step = 0.25 * self.field.min_spacing_mm();
        let limit = (4.0 * self.field.max_mm() / step).ceil() as usize + 1;
        let mut p = eye_mm;
        for _ in 0..limit {
            let g = self.field.gradient(p);
            let Some(uphill) = (g - forward * g.dot(forward)).try_normalize() else {
                break;
            };
            let next = p + uphill * step;
            if self.field.distance_mm(next) <= self.field.distance_mm(p) {
                break;
            }
            p = next;
        }
        p
    }

    /// Distance from `p_mm` to the wall, mm (0 outside the lumen).
    pub fn distance_mm(&self, p_mm: DVec3) -> f64 {
        self.field.distance_mm(p_mm)
    }

    /// The camera's radius, mm.
    pub fn radius_mm(&self) -> f64 {
        self.radius_mm
    }
}

/// A loaded scan ready to fly through.
#[derive(Debug)]
pub struct Scene {
    /// Where it came from.
    pub source: ScanSource,
    /// The renderer (the volume and its brick grid).
    pub renderer: Arc<Renderer>,
    /// Voxel counts of the physical values in [`HISTOGRAM_BINS`] equal bins over
    /// [`Scene::value_range`].
    pub histogram: Vec<u64>,
    /// Lowest and highest physical value.
    pub value_range: (f64, f64),
    /// The scan's fingerprint, which its cases record.
    pub identity: ScanIdentity,
    /// The series of the DICOM folder it was read from (empty for other sources).
    pub series_found: Vec<SeriesSummary>,
    /// Whether the file declared its orientation (else it was guessed or given: the panel
    /// offers to flip it).
    pub orientation_declared: bool,
    /// What the reader warned of, shown in the panel.
    pub warnings: Vec<String>,
}

impl Scene {
    /// The scene of `volume` read from `source`.
    pub fn new(source: ScanSource, volume: Volume) -> Self {
        let value_range = volume.physical_range();
        let histogram = histogram(&volume);
        let identity = ScanIdentity::of(&volume);
        Self {
            identity,
            source,
            renderer: Arc::new(Renderer::for_many_frames(volume)),
            histogram,
            value_range,
            series_found: Vec::new(),
            orientation_declared: true,
            warnings: Vec::new(),
        }
    }

    /// The scene, knowing what its reader found: the series its DICOM folder holds, whether
    /// the file declared its orientation, its warnings.
    pub fn with_facts(mut self, facts: ScanFacts) -> Self {
        self.series_found = facts.series_found;
        self.orientation_declared = facts.orientation_declared;
        self.warnings = facts.warnings;
        self
    }

    /// The volume.
    pub fn volume(&self) -> &Volume {
        self.renderer.volume()
    }
}

/// Voxel counts in [`HISTOGRAM_BINS`] bins of the stored range (a linear map of the physical).
fn histogram(volume: &Volume) -> Vec<u64> {
    let (lo, hi) = volume.stored_range();
    let span = f64::from(hi - lo).max(1.0);
    let mut counts = vec![0u64; HISTOGRAM_BINS];
    let last = HISTOGRAM_BINS - 1;
    for &v in volume.voxels() {
        let bin = (f64::from(v - lo) / span * last as f64).round() as usize;
        counts[bin.min(last)] += 1;
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn histogram_counts_every_voxel_and_bad_sources_say_why() {
        let source = ScanSource::Phantom {
            name: "straight-tube".into(),
            size: 16,
        };
        let scene = Scene::new(source.clone(), source.load().unwrap());
        let total: u64 = scene.histogram.iter().sum();
        assert_eq!(total as usize, scene.volume().voxels().len());
        let missing = ScanSource::File {
            path: "/nonexistent/scan.nii".into(),
            series: None,
            orientation: None,
        };
        let error = missing.load().unwrap_err();
        assert!(error.contains("/nonexistent/scan.nii"), "{error}");
        let unknown = ScanSource::Phantom {
            name: "teapot".into(),
            size: 16,
        };
        assert!(unknown.load().unwrap_err().contains("teapot"));
    }
}
