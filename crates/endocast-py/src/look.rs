//! The options that decide how a view looks (preset, mode, isovalues, transfer function,
//! sampling), where the camera is and what lens it has, and which lumen it navigates: the
//! CLI's `render` options, read from keywords, with the library's defaults.

use crate::errors::{error, to_py};
use crate::kwargs::Kwargs;
use endocast_core::camera::{default_up, Lens, Optics, Projection};
use endocast_core::navigate::{default_view, LumenChoice};
use endocast_core::pose::Pose;
use endocast_core::presets::{self, Preset, DEFAULT_FOV_DEG};
use endocast_core::render::{Camera, Mode, RenderSettings};
use endocast_core::Volume;
use glam::DVec3;
use pyo3::prelude::*;

/// A preset and the render settings: the preset's (or the defaults), overridden by the options.
pub struct Look {
    /// The preset named, if any.
    pub preset: Option<&'static Preset>,
    /// The settings in force.
    pub settings: RenderSettings,
    /// The workers of the `threads` option (`None`: rayon's global pool, all cores); made
    /// once, so that a flight's frames share it.
    pool: Option<rayon::ThreadPool>,
}

impl Look {
    /// Takes `preset`, `mode`, `iso`, `iso2`, `iso_opacity`, `tf`, `step`, `jitter`,
    /// `skip_empty`, `shade_dvr`, `background` and `threads`.
    pub fn take(kw: &Kwargs<'_>) -> PyResult<Self> {
        let preset = kw
            .take::<String>("preset")?
            .map(|name| find_preset(&name))
            .transpose()?;
        let mut s = preset.map_or_else(RenderSettings::default, Preset::settings);
        if let Some(mode) = kw.take::<String>("mode")? {
            s.mode = Mode::from_name(&mode).ok_or_else(|| {
                error(format!(
                    "unknown mode {mode:?}; choose iso, dvr, hybrid, two-iso, mip or minip"
                ))
            })?;
        }
        if let Some(iso) = kw.take("iso")? {
            s.iso_hu = iso;
        }
        if let Some(iso2) = kw.take("iso2")? {
            s.iso2_hu = iso2;
        }
        if let Some(alpha) = kw.take("iso_opacity")? {
            s.iso_opacity = alpha;
        }
        if let Some(tf) = kw.take::<String>("tf")? {
            s.tf = endocast_io::transfer_json::transfer_function(&tf).map_err(to_py)?;
        }
        if let Some(step) = kw.take("step")? {
            s.step_vox = step;
        }
        s.jitter = kw.take("jitter")?.unwrap_or(false);
        s.skip_empty = kw.take("skip_empty")?.unwrap_or(true);
        if let Some(shade) = kw.take("shade_dvr")? {
            s.shade_dvr = shade;
        }
        if let Some(background) = kw.take("background")? {
            s.background = background;
        }
        s.validate().map_err(to_py)?;
        let pool = match kw.take::<usize>("threads")? {
            None => None,
            Some(0) => return Err(error("threads must be at least 1")),
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(to_py)?,
            ),
        };
        Ok(Self {
            preset,
            settings: s,
            pool,
        })
    }

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

/// The lumen options `lumen_threshold` and `bright_lumen`, with the wall isovalue `iso` (the
/// preset's when `None`).
pub fn lumen_choice<'a>(
    kw: &Kwargs<'_>,
    preset: Option<&'a Preset>,
    iso: Option<f64>,
) -> PyResult<LumenChoice<'a>> {
    Ok(LumenChoice {
        preset,
        iso,
        threshold: kw.take("lumen_threshold")?,
        bright_lumen: kw.take("bright_lumen")?.unwrap_or(false),
        within: None,
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

/// The camera of `render`: `eye`, `look_at` and `up` (LPS mm) when given, else the library's
/// default view (inside the largest lumen for an endoscopic preset, else framing the volume);
/// with the optics and the image `size` (width, height; default 512 × 512).
pub fn camera(kw: &Kwargs<'_>, look: &Look, volume: &Volume) -> PyResult<Camera> {
    let fov = kw.take::<f64>("fov")?;
    let eye = kw.take::<[f64; 3]>("eye")?;
    let look_at = kw.take::<[f64; 3]>("look_at")?;
    let up = kw.take::<[f64; 3]>("up")?;
    let size = kw.take::<[usize; 2]>("size")?.unwrap_or([512, 512]);
    let lumen = lumen_choice(kw, look.preset, Some(look.settings.iso_hu))?;
    let (eye, look_at, chosen_up) = match (eye, look_at) {
        (Some(eye), Some(look_at)) => (DVec3::from(eye), DVec3::from(look_at), None),
        (None, None) => {
            let pose = default_pose(volume, look, &lumen, fov);
            (pose.eye_mm, pose.look_at_mm, Some(pose.up))
        }
        _ => return Err(error("eye and look_at go together")),
    };
    let up = up
        .map(DVec3::from)
        .or(chosen_up)
        .unwrap_or_else(|| default_up(look_at - eye));
    let optics = optics(kw, look.preset, volume, fov)?;
    optics.camera(eye, look_at, up, size).map_err(to_py)
}

/// The library's default view ([`default_view`]) for the preset and lumen options.
pub fn default_pose(
    volume: &Volume,
    look: &Look,
    lumen: &LumenChoice<'_>,
    fov: Option<f64>,
) -> Pose {
    let fov_deg = fov.unwrap_or_else(|| look.preset.map_or(DEFAULT_FOV_DEG, |p| p.fov_deg));
    let choice = look.preset.map(|_| lumen);
    default_view(volume, choice, fov_deg).pose()
}

/// The names of the presets (`endocast presets` lists what each sets).
#[pyfunction(name = "presets")]
pub fn preset_names() -> Vec<&'static str> {
    presets::ALL.iter().map(|p| p.name).collect()
}
