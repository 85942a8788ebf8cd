//! One pixel traced sample by sample, for debugging a render (`render --debug-pixel`).

use super::integrate::Probe;
use super::traverse::VoxelRay;
use super::{vignette, Filter, Prepared};
use crate::camera::Camera;
use crate::render::RenderStats;

/// One sample of a traced pixel (see [`Prepared::trace_pixel`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceSample {
    /// Distance from the eye, mm.
    pub t_mm: f32,
    /// Interpolated physical value.
    pub value: f64,
    /// Opacity accumulated after this sample.
    pub alpha: f32,
}

/// Everything about one pixel's ray: set-up, every sample, and the result.
#[derive(Debug, Clone, PartialEq)]
pub struct PixelTrace {
    /// The ray in voxel space (mm parametrisation); `None` where the camera forms no ray.
    pub ray: Option<VoxelRay>,
    /// The ray's part inside the volume, mm from the eye; `None` when it misses.
    pub range_mm: Option<(f64, f64)>,
    /// Distance between samples, mm.
    pub step_mm: f64,
    /// Offset of the sample grid from the start, in steps (0.5 without jitter).
    pub offset: f32,
    /// Every sample the integrator looked at, in order.
    pub samples: Vec<TraceSample>,
    /// Final colour (over the background).
    pub rgb: [u8; 3],
    /// Final opacity.
    pub alpha: f32,
    /// Distance to the first isosurface hit, mm (NaN where none).
    pub depth_mm: f32,
}

impl Probe for Vec<TraceSample> {
    fn sample(&mut self, t: f32, value: f32, alpha: f32) {
        self.push(TraceSample {
            t_mm: t,
            value: f64::from(value),
            alpha,
        });
    }
}

impl Prepared {
    /// Traces pixel `(x, y)` of `camera` and returns every sample (the `--debug-pixel` aid).
    pub fn trace_pixel(&self, camera: &Camera, x: usize, y: usize) -> PixelTrace {
        let integrator = self.integrator(camera, Filter::Trilinear);
        let mut samples = Vec::new();
        let mut stats = RenderStats::default();
        let mut out = self.pixel(&integrator, camera, x, y, &mut stats, &mut samples);
        vignette(camera, x, y, &mut out);
        let ray = self.ray(camera, x, y);
        let range_mm = ray.and_then(|r| r.range);
        let map = self.renderer.volume.value_map();
        for s in &mut samples {
            s.value = s.value * map.scale() + map.offset();
        }
        PixelTrace {
            ray: ray.map(|r| r.voxel),
            range_mm,
            step_mm: self.step_mm,
            offset: self.offset(x, y),
            samples,
            rgb: self.display(&out.accum),
            alpha: out.accum.alpha(),
            depth_mm: out.depth_mm,
        }
    }
}
