//! The options that decide how a view looks (preset, mode, isovalues, transfer function,
//! sampling), where the camera is and what lens it has, and which lumen it navigates: the
//! CLI's `render` options, read from keywords, with the library's defaults.

use crate::errors::{error, to_py};
use crate::kwargs::Kwargs;
use endocast_core::camera::{default_up, Lens, Optics, Projection};
use endocast_core::pose::Pose;
use endocast_core::presets::{self, Preset};
use endocast_core::render::{Camera, Mode, RenderSettings, TransferFunction};
use endocast_core::study::{Study, StudyRequest};
use endocast_core::Volume;
use glam::DVec3;
use pyo3::prelude::*;

/// The look options as given (the keywords `render`, `fly` and `default_view` share), before
/// a volume resolves them ([`LookOptions::resolve`]).
pub struct LookOptions {
    preset: Option<&'static Preset>,
    mode: Option<Mode>,
    iso: Option<f64>,
    iso2: Option<f64>,
    iso_opacity: Option<f32>,
    tf: Option<TransferFunction>,
    step: Option<f64>,
    jitter: bool,
    skip_empty: bool,
    shade_dvr: Option<bool>,
    background: Option<[f32; 3]>,
    lumen_threshold: Option<f64>,
    bright_lumen: bool,
    threads: Option<usize>,
}

impl LookOptions {
    /// Takes `preset`, `mode`, `iso`, `iso2`, `iso_opacity`, `tf`, `step`, `jitter`,
    /// `skip_empty`, `shade_dvr`, `background`, `lumen_threshold`, `bright_lumen` and
    /// `threads`.
    pub fn take(kw: &Kwargs<'_>) -> PyResult<Self> {
        let mode = kw
            .take::<String>("mode")?
            .map(|mode| {
                Mode::from_name(&mode).ok_or_else(|| {
                    error(format!(
                        "unknown mode {mode:?}; choose iso, dvr, hybrid, two-iso, mip, minip or \
                         peel"
                    ))
                })
            })
            .transpose()?;
        let tf = kw
            .take::<String>("tf")?
            .map(|tf| endocast_io::transfer_json::transfer_function(&tf).map_err(to_py))
            .transpose()?;
        Ok(Self {
            preset: kw
                .take::<String>("preset")?
                .map(|name| find_preset(&name))
                .transpose()?,
            mode,
            iso: finite("iso", kw.take("iso")?)?,
            iso2: kw.take("iso2")?,
            iso_opacity: kw.take("iso_opacity")?,
            tf,
            step: kw.take("step")?,
            jitter: kw.take("jitter")?.unwrap_or(false),
            skip_empty: kw.take("skip_empty")?.unwrap_or(true),
            shade_dvr: kw.take("shade_dvr")?,
            background: kw.take("background")?,
            lumen_threshold: finite("lumen_threshold", kw.take("lumen_threshold")?)?,
            bright_lumen: kw.take("bright_lumen")?.unwrap_or(false),
            threads: kw.take("threads")?,
        })
    }

    /// The study of `volume` these options ask for (the same as `endocast render`'s: the preset
    /// in the scan's units, the lumen, the structure and the start, or `pose` when the caller
    /// placed the camera; resolved without the GIL), and the settings with every option on top.
    pub fn resolve(
        &self,
        py: Python<'_>,
        volume: &Volume,
        pose: Option<Pose>,
        fov_deg: Option<f64>,
    ) -> PyResult<Look> {
        let request = StudyRequest {
            preset: self.preset,
            iso: self.iso,
            lumen_threshold: self.lumen_threshold,
            bright_lumen: self.bright_lumen,
            fov_deg,
            pose,
        };
        let study = py.detach(|| Study::resolve(volume, &request));
        let settings = self.overridden(study.settings().clone())?;
        let pool = match self.threads {
            None => None,
            Some(0) => return Err(error("threads must be at least 1")),
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(to_py)?,
            ),
        };
        Ok(Look {
            study,
            settings,
            pool,
        })
    }

    fn overridden(&self, mut s: RenderSettings) -> PyResult<RenderSettings> {
        if let Some(mode) = self.mode {
            s.mode = mode;
        }
        if let Some(iso2) = self.iso2 {
            s.iso2_hu = iso2;
        }
        if let Some(alpha) = self.iso_opacity {
            s.iso_opacity = alpha;
        }
        if let Some(tf) = &self.tf {
            s.tf.clone_from(tf);
        }
        if let Some(step) = self.step {
            s.step_vox = step;
        }
        s.jitter = self.jitter;
        s.skip_empty = self.skip_empty;
        if let Some(shade) = self.shade_dvr {
            s.shade_dvr = shade;
        }
        if let Some(background) = self.background {
            s.background = background;
        }
        s.validate().map_err(to_py)?;
        Ok(s)
    }
}

/// `value` when it is finite (or absent), else an error naming the option.
fn finite(name: &str, value: Option<f64>) -> PyResult<Option<f64>> {
    match value {
        Some(v) if !v.is_finite() => Err(error(format!("{name} must be a finite number, not {v}"))),
        v => Ok(v),
    }
}

/// A scan understood for the options, and the render settings in force.
pub struct Look {
    /// The scan understood: its values, lumen, structure and start.
    pub study: Study,
    /// The settings in force.
    pub settings: RenderSettings,
    /// The workers of the `threads` option (`None`: rayon's global pool, all cores); made
    /// once, so that a flight's frames share it.
    pool: Option<rayon::ThreadPool>,
}

impl Look {
    /// Runs `work` on the `threads` workers (all cores without the option).
    pub fn in_pool<T: Send>(&self, work: impl FnOnce() -> T + Send) -> T {
        match &self.pool {
            None => work(),
            Some(pool) => pool.install(work),
        }
    }
}

/// The preset called `name`, or an error listing the known ones.
pub fn find_preset(name: &str) -> PyResult<&'static Preset> {
    Preset::find(name).ok_or_else(|| {
        error(format!(
            "unknown preset {name:?}; choose one of {}",
            presets::all_names()
        ))
    })
}

/// The optics the options `lens`, `distortion`, `vignetting` and `near` and the field `fov`
/// (the caller took it) describe under `preset`, with the library's defaults
/// ([`presets::lens_defaults`]).
pub fn optics(
    kw: &Kwargs<'_>,
    preset: Option<&Preset>,
    volume: &Volume,
    fov: Option<f64>,
) -> PyResult<Optics> {
    let projection = kw
        .take::<String>("lens")?
        .map(|name| {
            Projection::from_name(&name).ok_or_else(|| {
                error(format!(
                    "unknown lens {name:?}: use pinhole, equidistant, equisolid or orthographic"
                ))
            })
        })
        .transpose()?;
    let (lo, hi) = volume.geometry().world_bounds();
    let (projection, field) = presets::lens_defaults(preset, projection, fov, (hi - lo).length());
    Ok(Optics {
        projection,
        field,
        lens: Lens {
            distortion: kw.take("distortion")?.unwrap_or([0.0; 2]),
            vignetting: kw.take("vignetting")?.unwrap_or(0.0),
        },
        near_mm: kw.take("near")?.unwrap_or(0.0),
    })
}

/// Where the caller placed the camera, if they did: `eye`, `look_at` and `up` (LPS mm), the
/// field `fov` and the image `size` (width, height; default 512 × 512).
pub struct Placed {
    /// The camera placed, `None` for the study's start.
    pub pose: Option<Pose>,
    /// The field of view, degrees (mm for orthographic).
    pub fov: Option<f64>,
    /// Width and height, pixels.
    pub size: [usize; 2],
}

impl Placed {
    /// Takes `eye`, `look_at`, `up`, `fov` and `size`.
    pub fn take(kw: &Kwargs<'_>) -> PyResult<Self> {
        let fov = kw.take::<f64>("fov")?;
        let eye = kw.take::<[f64; 3]>("eye")?;
        let look_at = kw.take::<[f64; 3]>("look_at")?;
        let up = kw.take::<[f64; 3]>("up")?.map(DVec3::from);
        let size = kw.take::<[usize; 2]>("size")?.unwrap_or([512, 512]);
        let pose = match (eye, look_at) {
            (Some(eye), Some(look_at)) => {
                let (eye_mm, look_at_mm) = (DVec3::from(eye), DVec3::from(look_at));
                Some(Pose {
                    eye_mm,
                    look_at_mm,
                    up: up.unwrap_or_else(|| default_up(look_at_mm - eye_mm)),
                })
            }
            (None, None) => None,
            _ => return Err(error("eye and look_at go together")),
        };
        Ok(Self { pose, fov, size })
    }
}

/// The camera of `render`: the study's start (the pose placed, else inside the structure the
/// preset means looking along its path, else the whole object framed), with the lens options
/// and the placed field and size.
pub fn camera(kw: &Kwargs<'_>, look: &Look, volume: &Volume, placed: &Placed) -> PyResult<Camera> {
    let pose = look.study.start_pose();
    let optics = optics(kw, look.study.preset(), volume, placed.fov)?;
    optics
        .camera(pose.eye_mm, pose.look_at_mm, pose.up, placed.size)
        .map_err(to_py)
}

/// The names of the presets (`endocast presets` lists what each sets).
#[pyfunction(name = "presets")]
pub fn preset_names() -> Vec<&'static str> {
    presets::ALL.iter().map(|p| p.name).collect()
}
