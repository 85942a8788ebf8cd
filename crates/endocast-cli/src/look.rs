//! The options that decide how a scan looks (preset, mode, isovalues, transfer function,
//! sampling) and how many threads render it; shared by `render` and `bench`.

use crate::peel::PeelArgs;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::presets::{self, Preset};
use endocast_core::render::{Mode, RenderSettings, TransferFunction};
use endocast_core::tissue::{self, ScanValues};
use endocast_core::Volume;

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
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

impl LookArgs {
    /// The preset named with `--preset`, if any; an error for an unknown name.
    pub fn preset(&self) -> Result<Option<&'static Preset>> {
        self.preset.as_deref().map(find_preset).transpose()
    }

    /// The preset (or defaults), overridden by every option given; values as the table gives
    /// them (HU), whatever the scan (see [`LookArgs::on_scan`]).
    pub fn settings(&self) -> Result<RenderSettings> {
        let base = match self.preset()? {
            Some(preset) => preset.settings(),
            None => RenderSettings::default(),
        };
        self.overridden(base)
    }

    /// The look on `volume`: the preset (or the default view) carried to the scan's own units
    /// ([`tissue::resolve`], [`tissue::default_settings`]), then every option given, which
    /// wins (`--iso` is in the scan's units). Also says in one line what was resolved.
    pub fn on_scan(&self, volume: &Volume) -> Result<ScanLook> {
        let scan = ScanValues::measure(volume);
        let (base, preset, summary) = match self.preset()? {
            Some(preset) => {
                let resolved = tissue::resolve(preset, volume, &scan);
                (resolved.settings(), Some(resolved.preset), resolved.summary)
            }
            None => {
                let s = tissue::default_settings(&scan);
                let summary = format!("wall at {:.1} ({scan})", s.iso_hu);
                (s, None, summary)
            }
        };
        Ok(ScanLook {
            settings: self.overridden(base)?,
            preset,
            summary,
            scan,
        })
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

/// How a scan looks, its values understood.
#[derive(Debug, Clone)]
pub struct ScanLook {
    /// The settings, options applied.
    pub settings: RenderSettings,
    /// The preset in the scan's units, if one was named.
    pub preset: Option<Preset>,
    /// What was resolved, in one line.
    pub summary: String,
    /// What the histogram says.
    pub scan: ScanValues,
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
    match threads {
        None => Ok(work()),
        Some(0) => bail!("--threads must be at least 1"),
        Some(n) => Ok(rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .context("cannot start the worker threads")?
            .install(work)),
    }
}

/// Makes every later parallel render use `threads` workers (all cores when `None`), for
/// commands whose work loop cannot move into a pool.
pub fn set_threads(threads: Option<usize>) -> Result<()> {
    match threads {
        None => Ok(()),
        Some(0) => bail!("--threads must be at least 1"),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("cannot start the worker threads"),
    }
}
