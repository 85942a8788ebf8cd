//! The options that decide how a scan looks (preset, mode, isovalues, transfer function,
//! sampling) and how many threads render it; shared by `render` and `bench`.

use crate::lumen::LumenArgs;
use crate::peel::PeelArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::look::{Look, LookKind, PresetLook, SecretionMode, Texture, BUILT_IN_TEXTURES};
use endocast_core::pose::Pose;
use endocast_core::presets::{self, Preset};
use endocast_core::render::{Mode, RenderSettings, TransferFunction};
use endocast_core::study::{Study, StudyRequest};
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

    fn overridden(&self, mut s: RenderSettings) -> Result<RenderSettings> {
        if let Some(mode) = &self.mode {
            s.mode = Mode::from_name(mode).with_context(|| {
                format!(
                    "unknown mode {mode:?}; choose iso, dvr, hybrid, two-iso, mip, minip or peel"
                )
            })?;
        }
        if let Some(iso) = self.iso {
            s.iso_hu = finite("--iso", iso)?;
        }
        if let Some(iso2) = self.iso2 {
            s.iso2_hu = finite("--iso2", iso2)?;
        }
        if let Some(alpha) = self.iso_opacity {
            if !(0.0..=1.0).contains(&alpha) {
                bail!("--iso-opacity must be between 0 and 1, not {alpha}");
            }
            s.iso_opacity = alpha;
        }
        if let Some(tf) = &self.tf {
            s.tf = transfer_function(tf)?;
        }
        if let Some(step) = self.step {
            s.step_vox = finite("--step", step)?;
        }
        s.jitter = self.jitter;
        s.shade_dvr |= self.shade_dvr;
        s.skip_empty = self.skip_empty;
        self.peel.apply(&mut s)?;
        if let Some(spec) = self.peel.tf_after() {
            s.peel.tf_after = Some(transfer_function(spec)?);
        }
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
    /// Wetness, 0 (dry) to 1: darkening where the tissue turns away, sharp highlights.
    #[arg(long, value_name = "0..1", allow_negative_numbers = true)]
    wetness: Option<f32>,
    /// Detail texture: mucosa, grid, none, or a PNG file (its luminance).
    #[arg(long, value_name = "NAME|FILE.png")]
    texture: Option<String>,
    /// Edge of one texture tile on the tissue, mm.
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    texture_scale: Option<f32>,
    /// Distance at which the tip's light falls to half, mm (0: no fall-off).
    #[arg(long, value_name = "MM", allow_negative_numbers = true)]
    attenuation: Option<f32>,
}

impl RealismArgs {
    /// The options that only a clinical or realistic look uses, as given.
    fn given(&self) -> Vec<&'static str> {
        let flags = [
            ("--secretion", self.secretion.is_some()),
            ("--secretion-iso", self.secretion_iso.is_some()),
            ("--wetness", self.wetness.is_some()),
            ("--texture", self.texture.is_some()),
            ("--texture-scale", self.texture_scale.is_some()),
            ("--attenuation", self.attenuation.is_some()),
        ];
        flags
            .iter()
            .filter(|(_, on)| *on)
            .map(|(f, _)| *f)
            .collect()
    }

    /// The look asked for over `base` (a preset's look in the scan's units), `tissue_iso` the
    /// `--iso` given; `None` for plain.
    fn look(&self, base: &PresetLook, tissue_iso: Option<f64>) -> Result<Option<Look>> {
        let kind = match &self.look {
            Some(name) => LookKind::from_name(name).with_context(|| {
                format!("unknown look {name:?}; choose plain, clinical or realistic")
            })?,
            None => base.kind,
        };
        let Some(mut look) = Look::of_kind(kind, base) else {
            let given = self.given();
            if !given.is_empty() {
                bail!(
                    "{} only apply to --look clinical or realistic (the plain look has no deferred stage)",
                    given.join(", ")
                );
            }
            return Ok(None);
        };
        if let Some(iso) = tissue_iso {
            look.ray.tissue_hu = finite("--iso", iso)?;
        }
        if let Some(iso) = self.secretion_iso {
            look.ray.secretion_hu = finite("--secretion-iso", iso)?;
        }
        if let Some(mode) = &self.secretion {
            look.ray.secretion = SecretionMode::from_name(mode).with_context(|| {
                format!("unknown secretion mode {mode:?}; choose off, on or accumulate")
            })?;
        }
        if let Some(w) = self.wetness {
            if !(0.0..=1.0).contains(&w) {
                bail!("--wetness must be between 0 and 1, not {w}");
            }
            look.shading.wetness = w;
        }
        if let Some(spec) = &self.texture {
            look.shading.texture = texture(spec)?.map(std::sync::Arc::new);
        }
        if let Some(mm) = self.texture_scale {
            if !(mm.is_finite() && mm > 0.0) {
                bail!("--texture-scale must be a positive number of mm, not {mm}");
            }
            look.shading.texture_mm = mm;
        }
        if let Some(mm) = self.attenuation {
            if !(mm.is_finite() && mm >= 0.0) {
                bail!("--attenuation must be a distance in mm (0 for none), not {mm}");
            }
            look.shading.attenuation_mm = (mm > 0.0).then_some(mm);
        }
        look.ray.validate().context("invalid look")?;
        look.shading.validate().context("invalid look")?;
        Ok(Some(look))
    }
}

/// A detail texture by built-in name (`none`: no texture) or from a PNG file.
fn texture(spec: &str) -> Result<Option<Texture>> {
    let name = spec.trim();
    if BUILT_IN_TEXTURES.contains(&name.to_ascii_lowercase().as_str()) {
        return Ok(Texture::built_in(name));
    }
    let path = std::path::Path::new(spec);
    let is_png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png && !path.exists() {
        bail!(
            "unknown texture {spec:?}; choose {} or a .png file",
            BUILT_IN_TEXTURES.join(", ")
        );
    }
    let texture = endocast_io::texture::read_texture(path).context("cannot use the texture")?;
    Ok(Some(texture))
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
