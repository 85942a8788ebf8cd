//! The options that decide how a view looks (preset, mode, isovalues, transfer function,
//! sampling), where the camera is and what lens it has, and which lumen it navigates: the
//! CLI's `render` options, read from keywords, with the library's defaults.

use crate::errors::{error, to_py};
use crate::kwargs::Kwargs;
use endocast_core::camera::{default_up, Optics, Projection};
use endocast_core::pose::Pose;
use endocast_core::presets::{self, Preset};
use endocast_core::render::{Camera, PeelLayer, RenderSettings, TransferFunction};
use endocast_core::study::{
    self, named, LensOptions, OptionError, PeelOptions, Study, StudyRequest, ViewOptions,
};
use endocast_core::Volume;
use glam::DVec3;
use pyo3::prelude::*;
use std::sync::Arc;

/// The look options as given (the keywords `render`, `fly` and `default_view` share), before
/// a volume resolves them ([`LookOptions::resolve`]).
pub struct LookOptions {
    preset: Option<&'static Preset>,
    iso: Option<f64>,
    lumen_threshold: Option<f64>,
    bright_lumen: bool,
    threads: Option<usize>,
    view: ViewOptions,
    realism: study::LookOptions,
}

impl LookOptions {
    /// Takes `preset`, `iso`, `lumen_threshold`, `bright_lumen`, `threads`, the render
    /// options (`mode`, `iso2`, `iso_opacity`, `tf`, `step`, `jitter`, `skip_empty`,
    /// `shade_dvr`, `background`), the peel's (`peel`, `peel_threshold`, `peel_falling`,
    /// `peel_keep`, `unpeeled`, `tf_after`) and the look's (`look`, `secretion`,
    /// `secretion_iso`, `wetness`, `texture`, `texture_scale`, `specular_map`, `attenuation`,
    /// `lighting`).
    pub fn take(kw: &Kwargs<'_>) -> PyResult<Self> {
        let tf = |key| -> PyResult<Option<TransferFunction>> {
            kw.take::<String>(key)?
                .map(|tf| endocast_io::transfer_json::transfer_function(&tf).map_err(to_py))
                .transpose()
        };
        let view = ViewOptions {
            mode: named_option(kw, "mode", named::mode)?,
            iso2: kw.take("iso2")?,
            iso_opacity: kw.take("iso_opacity")?,
            tf: tf("tf")?,
            step: kw.take("step")?,
            jitter: kw.take("jitter")?,
            shade_dvr: kw.take("shade_dvr")?,
            skip_empty: kw.take("skip_empty")?,
            background: kw.take("background")?,
            peel: PeelOptions {
                layer: peel_layer(kw)?,
                threshold: kw.take("peel_threshold")?,
                falling: kw.take("peel_falling")?,
                keep: kw.take("peel_keep")?,
                unpeeled: named_option(kw, "unpeeled", named::unpeeled)?,
                tf_after: tf("tf_after")?,
            },
        };
        let realism = study::LookOptions {
            kind: named_option(kw, "look", named::look)?,
            secretion: named_option(kw, "secretion", named::secretion)?,
            secretion_iso: kw.take("secretion_iso")?,
            wetness: kw.take("wetness")?,
            texture: kw
                .take::<String>("texture")?
                .map(|spec| {
                    endocast_io::texture::named_or_file(&spec)
                        .map(|t| t.map(Arc::new))
                        .map_err(to_py)
                })
                .transpose()?,
            texture_scale: kw.take("texture_scale")?,
            specular_map: kw
                .take::<std::path::PathBuf>("specular_map")?
                .map(|path| {
                    endocast_io::texture::read_specular_map(&path)
                        .map(Arc::new)
                        .map_err(to_py)
                })
                .transpose()?,
            attenuation: kw.take("attenuation")?,
            lighting: kw
                .take::<String>("lighting")?
                .map(|spec| endocast_io::lit_sphere::named_or_file(&spec).map_err(to_py))
                .transpose()?,
        };
        Ok(Self {
            preset: kw
                .take::<String>("preset")?
                .map(|name| find_preset(&name))
                .transpose()?,
            iso: finite("iso", kw.take("iso")?)?,
            lumen_threshold: finite("lumen_threshold", kw.take("lumen_threshold")?)?,
            bright_lumen: kw.take("bright_lumen")?.unwrap_or(false),
            threads: kw.take("threads")?,
            view,
            realism,
        })
    }

    /// The study of `volume` these options ask for (the same as `endocast render`'s: the preset
    /// in the scan's units, the lumen, the structure and the start, or `pose` when the caller
    /// placed the camera; resolved without the GIL), and the settings and look with every
    /// option on top.
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
        let settings = self
            .view
            .apply(study.settings().clone())
            .map_err(option_error)?;
        settings.validate().map_err(to_py)?;
        let look = self
            .realism
            .resolve(&study.look(), self.iso)
            .map_err(option_error)?;
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
            look,
            pool,
        })
    }
}

/// The option `key`, a name parsed by `parse`, if given.
fn named_option<T>(
    kw: &Kwargs<'_>,
    key: &str,
    parse: fn(&str) -> Result<T, OptionError>,
) -> PyResult<Option<T>> {
    kw.take::<String>(key)?
        .map(|name| parse(&name).map_err(option_error))
        .transpose()
}

/// `peel`: a number (1, 2, 3 …) or "last".
fn peel_layer(kw: &Kwargs<'_>) -> PyResult<Option<PeelLayer>> {
    kw.take::<Bound<'_, PyAny>>("peel")?
        .map(|v| named::peel_layer(&v.str()?.to_string()).map_err(option_error))
        .transpose()
}

/// An option's error as Python's exception, the option named by its keyword.
fn option_error(e: OptionError) -> PyErr {
    error(e.message(str::to_owned))
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
    /// The clinical or realistic look's stages; `None` for the plain look.
    pub look: Option<endocast_core::look::Look>,
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
/// (the caller took it) describe under `preset` and `look` (its lens: the realistic look's
/// endoscope; `None`: the plain look), with the library's defaults
/// ([`presets::lens_defaults`], [`LensOptions::resolve`]).
pub fn optics(
    kw: &Kwargs<'_>,
    preset: Option<&Preset>,
    look: Option<&endocast_core::look::Look>,
    volume: &Volume,
    fov: Option<f64>,
) -> PyResult<Optics> {
    let projection = kw
        .take::<String>("lens")?
        .map(|name| {
            Projection::from_name(&name).ok_or_else(|| {
                error(format!(
                    "unknown lens {name:?}: use {}",
                    Projection::choices()
                ))
            })
        })
        .transpose()?;
    let (lo, hi) = volume.geometry().world_bounds();
    let (projection, field) = presets::lens_defaults(preset, projection, fov, (hi - lo).length());
    Ok(Optics {
        projection,
        field,
        lens: LensOptions {
            distortion: kw.take("distortion")?,
            vignetting: kw.take("vignetting")?,
        }
        .resolve(look, projection)
        .map_err(option_error)?,
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
    let optics = optics(
        kw,
        look.study.preset(),
        look.look.as_ref(),
        volume,
        placed.fov,
    )?;
    optics
        .camera(pose.eye_mm, pose.look_at_mm, pose.up, placed.size)
        .map_err(to_py)
}

/// The names of the presets (`endocast presets` lists what each sets).
#[pyfunction(name = "presets")]
pub fn preset_names() -> Vec<&'static str> {
    presets::ALL.iter().map(|p| p.name).collect()
}
