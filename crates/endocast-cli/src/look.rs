//! The options that decide how a scan looks (preset, mode, isovalues, transfer function,
//! sampling) and how many threads render it; shared by `render` and `bench`.

use crate::lumen::LumenArgs;
use crate::peel::PeelArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::look::{Look, PresetLook};
use endocast_core::pose::Pose;
use endocast_core::presets::{self, Preset};
use endocast_core::render::{RenderSettings, TransferFunction};
use endocast_core::study::{named, LookOptions, OptionError, Study, StudyRequest, ViewOptions};
use endocast_core::Volume;
use endocast_io::Limits;

/// How a scan is rendered.
#[derive(Args, Debug, Clone)]
pub struct LookArgs {
    /// Clinical defaults: colonoscopy, bronchoscopy, angioscopy, sinus, ventricles (also the
    /// benchmark TFs ramp, complex; `endocast presets` lists them). Options given explicitly
    /// override the preset.
    #[arg(long)]
    preset: Option<String>,
    /// iso, dvr, hybrid, two-iso, mip, minip or peel (default: the preset's, else hybrid).
    #[arg(long)]
    mode: Option<String>,
    /// Isovalue of the lumen wall, physical units (HU for CT).
    #[arg(long, value_name = "VALUE", allow_negative_numbers = true)]
    iso: Option<f64>,
    /// Upper isovalue for two-iso (stent, calcification), physical units.
    #[arg(long, value_name = "VALUE", allow_negative_numbers = true)]
    iso2: Option<f64>,
    /// Opacity of the isosurface, 0–1 (hybrid: 1 hides everything behind the wall).
    #[arg(long, value_name = "ALPHA")]
    iso_opacity: Option<f32>,
    /// Transfer function: a JSON file ({"opacity": [[v, a]..], "color": [[v, r, g, b]..]},
    /// opacity per mm) or a preset name.
    #[arg(long, value_name = "FILE|NAME")]
    tf: Option<String>,
    /// Sample step as a fraction of the smallest voxel spacing.
    #[arg(long, value_name = "VOXELS")]
    step: Option<f64>,
    /// Jitter each pixel's samples by a deterministic per-pixel offset.
    #[arg(long)]
    jitter: bool,
    /// Shade DVR samples with their gradient (Blinn-Phong; six extra samples per visible sample).
    /// The hybrid mode never shades behind its surface.
    #[arg(long)]
    shade_dvr: bool,
    /// Iso and hybrid: find the surface exactly, cell by cell (no thin feature missed at any
    /// step; about 1.4× the sampled search's work).
    #[arg(long)]
    exact: bool,
    /// DVR and the volume behind a surface: classify each segment between samples as a whole
    /// (pre-integrated, Engel et al. 2001) instead of each sample by its value (default: true
    /// when --dvr-stride is above 1, else the preset's).
    #[arg(long, action = clap::ArgAction::Set, value_name = "true|false")]
    preintegrate: Option<bool>,
    /// DVR and the volume behind a surface: composite every N-th sample of the step grid, each
    /// segment pre-integrated (1–16; the isosurface search keeps --step).
    #[arg(long, value_name = "N")]
    dvr_stride: Option<u32>,
    /// Skip empty bricks (the image is the same either way, only slower without).
    #[arg(long, default_value_t = true, action = clap::ArgAction::Set, value_name = "true|false")]
    skip_empty: bool,
    #[command(flatten)]
    peel: PeelArgs,
    #[command(flatten)]
    realism: RealismArgs,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

impl LookArgs {
    /// The preset named with `--preset`, if any; an error for an unknown name.
    pub fn preset(&self) -> Result<Option<&'static Preset>> {
        self.preset.as_deref().map(find_preset).transpose()
    }

    /// The study of `volume` these options ask for ([`Study::resolve`]: the preset carried to
    /// the scan's units, the lumen, the structure and the start, or `pose` when the user placed
    /// the camera), then every option given on top, which wins (`--iso` is in the scan's
    /// units and moves the lumen with it).
    pub fn on_scan(
        &self,
        volume: &Volume,
        lumen: &LumenArgs,
        pose: Option<Pose>,
        fov_deg: Option<f64>,
    ) -> Result<ScanLook> {
        let request = StudyRequest {
            preset: self.preset()?,
            iso: self.iso.map(|iso| finite("--iso", iso)).transpose()?,
            lumen_threshold: lumen
                .lumen_threshold
                .map(|t| finite("--lumen-threshold", t))
                .transpose()?,
            bright_lumen: lumen.bright_lumen,
            fov_deg,
            pose,
        };
        let study = Study::resolve(volume, &request);
        Ok(ScanLook {
            settings: self.overridden(study.settings().clone())?,
            look: self.realism.look(&study.look(), self.iso)?,
            study,
        })
    }

    /// The name of the look asked for with `--look` (`plain` when none).
    pub fn look_name(&self) -> String {
        self.realism
            .look
            .as_deref()
            .map_or_else(|| "plain".to_owned(), |n| n.trim().to_ascii_lowercase())
    }

    fn overridden(&self, s: RenderSettings) -> Result<RenderSettings> {
        let options = ViewOptions {
            mode: parsed(self.mode.as_deref(), named::mode)?,
            iso2: self.iso2,
            iso_opacity: self.iso_opacity,
            tf: self.tf.as_deref().map(transfer_function).transpose()?,
            step: self.step,
            jitter: Some(self.jitter),
            shade_dvr: self.shade_dvr.then_some(true),
            skip_empty: Some(self.skip_empty),
            background: None,
            peel: self.peel.options()?,
        };
        let mut s = options.apply(s).map_err(flag_error)?;
        s.exact_hits |= self.exact;
        if let Some(stride) = self.dvr_stride {
            s.dvr_stride = stride;
            s.preintegrated |= stride > 1;
        }
        if let Some(preintegrate) = self.preintegrate {
            s.preintegrated = preintegrate;
            if !preintegrate && self.dvr_stride.is_none() {
                s.dvr_stride = 1;
            }
        }
        s.validate()?;
        Ok(s)
    }
}

/// The endoscopic look (Krüger et al.'s Sinus Endoscopy): secretion, wetness, texture, light.
#[derive(Args, Debug, Clone, Default)]
pub struct RealismArgs {
    /// plain (the mode's own image), clinical (the tissue lit from the tip, smoothed) or
    /// realistic (wet, textured mucosa, secretion); default: the preset's, else plain. With a
    /// look other than plain, --iso is the tissue threshold the rays stop at.
    #[arg(long, value_name = "LOOK")]
    look: Option<String>,
    /// Secretion: off, on (constant density between the first secretion and tissue hits) or
    /// accumulate (along the ray).
    #[arg(long, value_name = "MODE")]
    secretion: Option<String>,
    /// Secretion threshold, physical units (between the lumen's value and the tissue's).
    #[arg(long, value_name = "VALUE", allow_negative_numbers = true)]
    secretion_iso: Option<f64>,
    /// Wetness, 0 (dry: no highlight at all) to 1: darkening where the tissue turns away, wet
    /// highlights strongest on the texture's darker texels, glossy highlights on the mucus's
    /// own surface; secretion raises it (default: the preset's, 0.8 for CT).
    #[arg(long, value_name = "0..1", allow_negative_numbers = true)]
    wetness: Option<f32>,
    /// Detail texture: mucosa (default: a low-contrast mottled mucosa with fine vessels), grid
    /// (lines, the strongest shape cue), none, or a PNG file (its colour kept, mip-mapped).
    #[arg(long, value_name = "NAME|FILE.png")]
    texture: Option<String>,
    /// Specular map: a PNG file read as grey (its luminance), tiled as the texture; where it is
    /// bright the tissue is wetter and glossier, where black it has no highlights (default:
    /// derived from the texture, strongest on its darker texels).
    #[arg(long, value_name = "FILE.png")]
    specular_map: Option<std::path::PathBuf>,
    /// Edge of one texture tile on the tissue, mm.
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    texture_scale: Option<f32>,
    /// Distance at which the tip's light falls to half, mm (0: no fall-off).
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    attenuation: Option<f32>,
    /// Lighting: phong (the default); ibl, image-based (Krüger et al. §4.4): the diffuse light
    /// from a built-in lit sphere (the tip's light with a soft terminator and rim); or
    /// ibl:FILE.png, your lit sphere (a square image of a lit ball, its luminance; centre:
    /// facing the tip). The wet highlights stay the specular model's.
    #[arg(long, value_name = "phong|ibl|ibl:FILE.png")]
    lighting: Option<String>,
}

impl RealismArgs {
    /// The look asked for over `base` (a preset's look in the scan's units), `tissue_iso` the
    /// `--iso` given; `None` for plain.
    fn look(&self, base: &PresetLook, tissue_iso: Option<f64>) -> Result<Option<Look>> {
        let options = LookOptions {
            kind: parsed(self.look.as_deref(), named::look)?,
            secretion: parsed(self.secretion.as_deref(), named::secretion)?,
            secretion_iso: self.secretion_iso,
            wetness: self.wetness,
            texture: self
                .texture
                .as_deref()
                .map(|spec| {
                    endocast_io::texture::named_or_file(spec)
                        .map(|t| t.map(std::sync::Arc::new))
                        .context("cannot use the texture")
                })
                .transpose()?,
            texture_scale: self.texture_scale,
            specular_map: self
                .specular_map
                .as_deref()
                .map(|path| {
                    endocast_io::texture::read_specular_map(path)
                        .map(std::sync::Arc::new)
                        .context("cannot use the specular map")
                })
                .transpose()?,
            attenuation: self.attenuation,
            lighting: self
                .lighting
                .as_deref()
                .map(|spec| {
                    endocast_io::lit_sphere::named_or_file(spec).context("cannot use the lighting")
                })
                .transpose()?,
        };
        options.resolve(base, tissue_iso).map_err(flag_error)
    }
}

/// `name` parsed by `parse`, if given.
fn parsed<T>(name: Option<&str>, parse: fn(&str) -> Result<T, OptionError>) -> Result<Option<T>> {
    name.map(parse).transpose().map_err(flag_error)
}

/// An option's error with the option spelled as its flag (`--iso-opacity`).
pub fn flag_error(e: OptionError) -> anyhow::Error {
    anyhow::anyhow!(e.message(|key| format!("--{}", key.replace('_', "-"))))
}

/// How a scan looks, its values understood.
#[derive(Debug)]
pub struct ScanLook {
    /// The settings, options applied.
    pub settings: RenderSettings,
    /// The scan understood for the procedure: its values, lumen, structure and start.
    pub study: Study,
    /// The clinical or realistic look's stages; `None` for the plain look.
    pub look: Option<Look>,
}

/// The preset called `name`, or an error listing the known ones.
pub fn find_preset(name: &str) -> Result<&'static Preset> {
    Preset::find(name).with_context(|| {
        format!(
            "unknown preset {name:?}; choose one of {}",
            presets::all_names()
        )
    })
}

fn finite(name: &str, value: f64) -> Result<f64> {
    if !value.is_finite() {
        bail!("{name} must be a finite number, not {value}");
    }
    Ok(value)
}

/// A transfer function from a JSON file, or a preset by name.
pub fn transfer_function(spec: &str) -> Result<TransferFunction> {
    endocast_io::transfer_json::transfer_function(spec).context("cannot use the transfer function")
}

/// Runs `work` on a pool of `threads` workers (all cores when `None`).
pub fn in_pool<T: Send>(threads: Option<usize>, work: impl FnOnce() -> T + Send) -> Result<T> {
    match pool(threads)? {
        None => Ok(work()),
        Some(pool) => Ok(pool
            .build()
            .context("cannot start the worker threads")?
            .install(work)),
    }
}

/// Makes every later parallel render use `threads` workers (all cores when `None`), for
/// commands whose work loop cannot move into a pool.
pub fn set_threads(threads: Option<usize>) -> Result<()> {
    match pool(threads)? {
        None => Ok(()),
        Some(pool) => pool
            .build_global()
            .context("cannot start the worker threads"),
    }
}

/// A pool of `--threads` workers (`None`: the default pool, all cores), after checking the
/// count: at least one, at most the limit ([`Limits::check_threads`]).
fn pool(threads: Option<usize>) -> Result<Option<rayon::ThreadPoolBuilder>> {
    let Some(n) = threads else {
        return Ok(None);
    };
    if n == 0 {
        bail!("--threads must be at least 1");
    }
    Limits::default().check_threads("--threads", n)?;
    Ok(Some(rayon::ThreadPoolBuilder::new().num_threads(n)))
}
