//! The procedures endocast knows, in one table: per preset the render mode, the named transfer
//! function, the wall isosurface (and angioscopy's second one), the lumen a flight grows through,
//! the slice window and the lens. Every front end (the CLI's `render`, `path`, `fly`, `bench`
//! and `presets`) reads its defaults here, so a value lives in exactly one place.
//!
//! ```
//! use endocast_core::presets::Preset;
//! use endocast_core::render::Mode;
//!
//! let bronchoscopy = Preset::find("Bronchoscopy").expect("a known preset");
//! assert_eq!(bronchoscopy.settings().mode, Mode::Hybrid);
//! // Airways are grown below −900 HU: at the wall's −500 HU they would leak into the lung.
//! assert_eq!(bronchoscopy.lumen.map(|l| l.threshold), Some(-900.0));
//! assert!(endocast_core::presets::ALL.iter().any(|p| p.name == "ramp"));
//! ```
//!
//! Thresholds are the ones measured on the shared scans (`shared/data/README.md`): CT in
//! Hounsfield units, `ventricles` in the intensity units of a T1 MRI.

use crate::camera::Projection;
use crate::look::{PresetLook, SecretionMode};
use crate::navigate::LumenSide;
use crate::render::{Mode, PeelLayer, PeelSettings, RenderSettings, TransferFunction};
use crate::views::slices::Window;

/// Vertical field of view of a pinhole endoscope, degrees: the default of every preset and of
/// commands run without one.
pub const DEFAULT_FOV_DEG: f64 = 90.0;

/// The field of a fisheye lens when neither the caller nor the preset gives one, degrees: a
/// wide endoscope's.
pub const FISHEYE_DEFAULT_FOV_DEG: f64 = 170.0;

/// The projection and field of a view under `preset` (if any), for the `projection` and
/// `field` a caller asked for (if any): the projection defaults to the preset's, else a
/// pinhole; the field to the preset's field of view — a fisheye's
/// [`FISHEYE_DEFAULT_FOV_DEG`] when the preset's own lens is no fisheye — or, orthographic,
/// `default_height_mm`; the cube and the panorama take their own
/// ([`Projection::default_field`]). The field is not checked against the projection's range here (the
/// camera does that).
pub fn lens_defaults(
    preset: Option<&Preset>,
    projection: Option<Projection>,
    field: Option<f64>,
    default_height_mm: f64,
) -> (Projection, f64) {
    let projection = projection
        .or(preset.map(|p| p.projection))
        .unwrap_or(Projection::Pinhole);
    let field = field
        .or(projection.default_field())
        .unwrap_or(match projection {
            Projection::Orthographic => default_height_mm,
            p if p.is_fisheye() && preset.is_none_or(|p| !p.projection.is_fisheye()) => {
                FISHEYE_DEFAULT_FOV_DEG
            }
            _ => preset.map_or(DEFAULT_FOV_DEG, |p| p.fov_deg),
        });
    (projection, field)
}

/// A second isosurface ([`Mode::TwoIso`]'s upper one: stent, calcification).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// Isovalue, physical units.
    pub iso: f64,
    /// Opacity, 0–1.
    pub opacity: f32,
    /// Colour before shading, 0–1 (sRGB); `None` keeps [`RenderSettings`]' default.
    pub color: Option<[f32; 3]>,
}

/// The depth peeling of a [`Mode::Peel`] preset (see [`PeelSettings`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PresetPeel {
    /// Peel threshold, physical units.
    pub threshold: f64,
    /// Whether crossings into the darker material count (else into the brighter).
    pub falling: bool,
    /// The peel shown.
    pub layer: PeelLayer,
    /// Name of the transfer function behind the peel (see [`TransferFunction::preset`]).
    pub tf_after: &'static str,
}

/// The lumen a preset flies through: region growing keeps the voxels on `side` of `threshold`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PresetLumen {
    /// Region-growing threshold, physical units. It may differ from the wall isovalue: airways
    /// are grown below −900 HU although their wall is drawn at −500 HU.
    pub threshold: f64,
    /// Whether the lumen is darker (air, CSF on T1) or brighter (contrast) than the wall.
    pub side: LumenSide,
    /// What fills the lumen, in one word for messages ("air", "contrast", "CSF").
    pub tissue: &'static str,
    /// Which component of the lumen the procedure means.
    pub structure: Structure,
}

/// Which connected component of a lumen a procedure means, when no point is given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Structure {
    /// The largest; for a dark lumen, the largest that does not touch the volume's border (the
    /// air around the patient does).
    Largest,
    /// The largest that reaches into a box at the object's centre and does not touch the
    /// border: the lateral ventricles, not the CSF around the brain nor a lesion.
    Central,
    /// The airway tree grown from the trachea's round section in the top axial slices, its
    /// threshold lowered until it stops leaking into the lung.
    Trachea,
    /// The aorta: the longest chain of bright round sections of 7–16 mm radius in the axial
    /// slices, followed by its round core past the branches' origins to its division (see
    /// [`crate::navigate::find_aorta`]).
    Aorta,
    /// The colon: the largest gas component inside the body, not the lung (see
    /// [`crate::navigate::find_colon`]).
    Colon,
    /// The nasal cavity: the largest air hole of the head's axial slices that crosses its
    /// mid-sagittal plane, cut off from the outside air at the nostrils (see
    /// [`crate::navigate::find_nasal_cavity`]).
    NasalCavity,
    /// A joint space: the dark gap where the two largest bones' marrow comes closest (see
    /// [`crate::navigate::find_joint`]).
    Joint,
}

/// The scale a preset's values are written on; [`crate::tissue::resolve`] carries them to a
/// scan's own units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reference {
    /// Hounsfield units: air −1000, water 0; CT scans shift them by their offset.
    Hounsfield,
    /// The intensities of a T1 brain MRI (the shared `chris_t1`), anchored at its CSF and
    /// white-matter levels: a scan's own CSF and tissue levels stretch them (and reverse them
    /// where CSF is bright).
    T1Brain {
        /// Ventricular CSF on the reference scale.
        csf: f64,
        /// White matter on the reference scale.
        tissue: f64,
    },
    /// The intensities of the scan the preset was tuned on, used as they are (no tissue level
    /// anchors them yet).
    AsGiven,
}

/// One procedure's defaults. Built only in [`ALL`]; find one with [`Preset::find`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Preset {
    /// Lower-case name, as `--preset` takes it.
    pub name: &'static str,
    /// What it is for, in one line.
    pub description: &'static str,
    /// Render mode.
    pub mode: Mode,
    /// Name of the transfer function (see [`TransferFunction::preset`]).
    pub tf: &'static str,
    /// Wall isovalue, physical units (HU for CT).
    pub iso: f64,
    /// Opacity of the wall isosurface, 0–1.
    pub iso_opacity: f32,
    /// Colour of the wall before shading, 0–1 (sRGB); `None` keeps [`RenderSettings`]' default
    /// (a mucosa pink).
    pub iso_color: Option<[f32; 3]>,
    /// The second isosurface of [`Mode::TwoIso`], where the preset has one.
    pub iso2: Option<Surface>,
    /// The peel of [`Mode::Peel`], where the preset has one.
    pub peel: Option<PresetPeel>,
    /// The lumen a flight navigates; `None` for the benchmark presets, which are no procedure.
    pub lumen: Option<PresetLumen>,
    /// Window of the slice views, physical units.
    pub window: Window,
    /// The endoscope's lens.
    pub projection: Projection,
    /// The endoscope's field of view, degrees (vertical for a pinhole).
    pub fov_deg: f64,
    /// The scale the values above are written on.
    pub reference: Reference,
    /// The look shown by default, and the thresholds, colours and surface the clinical and
    /// realistic looks take (`--look`).
    pub look: PresetLook,
}

/// The window for CT with an air-filled lumen: air black, soft tissue light grey, bone white.
const AIR_TISSUE: Window = Window::AIR_TISSUE;

/// Every preset: the five procedures, then the benchmark's two transfer functions.
pub const ALL: &[Preset] = &[
    Preset {
        name: "colonoscopy",
        description: "CT colonography: the gas-filled colon's wall at -500 HU, 60 % opaque",
        mode: Mode::Hybrid,
        tf: "colonoscopy",
        iso: -500.0,
        iso_opacity: 0.6,
        iso_color: None,
        iso2: None,
        peel: None,
        lumen: Some(PresetLumen {
            threshold: -500.0,
            side: LumenSide::Below,
            tissue: "gas",
            structure: Structure::Colon,
        }),
        window: AIR_TISSUE,
        projection: Projection::Pinhole,
        fov_deg: DEFAULT_FOV_DEG,
        reference: Reference::Hounsfield,
        look: PresetLook {
            secretion_mode: SecretionMode::Off,
            texture_mm: 36.0,
            attenuation_mm: 60.0,
            tissue_color: [0.95, 0.6, 0.5],
            ..PresetLook::CT
        },
    },
    Preset {
        name: "bronchoscopy",
        description: "chest CT: trachea and bronchi, wall at -500 HU, lumen grown below -900 HU",
        mode: Mode::Hybrid,
        tf: "bronchoscopy",
        iso: -500.0,
        iso_opacity: 0.6,
        iso_color: None,
        iso2: None,
        peel: None,
        // −900, not −500: at −500 the thin bronchial wall leaks into the lung (−820…−950 HU).
        lumen: Some(PresetLumen {
            threshold: -900.0,
            side: LumenSide::Below,
            tissue: "air",
            structure: Structure::Trachea,
        }),
        // The lung window.
        window: Window {
            level_hu: -600.0,
            width_hu: 1500.0,
        },
        projection: Projection::Pinhole,
        fov_deg: DEFAULT_FOV_DEG,
        reference: Reference::Hounsfield,
        look: PresetLook {
            // Thin bronchial walls reach only about −500 HU: a higher tissue threshold would
            // open holes in them; the secretion threshold stays above the lung (−820 HU).
            tissue: -450.0,
            secretion: -780.0,
            attenuation_mm: 50.0,
            tissue_color: [0.95, 0.68, 0.62],
            ..PresetLook::CT
        },
    },
    Preset {
        name: "angioscopy",
        description: "CT angiography: vessel wall at 130 HU and calcium or stent at 700 HU",
        mode: Mode::TwoIso,
        tf: "angioscopy",
        // Contrast ≈ 190–300 HU, wall ≈ 40 HU.
        iso: 130.0,
        iso_opacity: 0.7,
        iso_color: Some([0.85, 0.35, 0.3]),
        iso2: Some(Surface {
            iso: 700.0,
            opacity: 1.0,
            color: None,
        }),
        peel: None,
        lumen: Some(PresetLumen {
            threshold: 130.0,
            side: LumenSide::Above,
            tissue: "contrast",
            structure: Structure::Aorta,
        }),
        // A vessel window: contrast light grey, calcium and metal white, fat dark.
        window: Window {
            level_hu: 100.0,
            width_hu: 700.0,
        },
        projection: Projection::Pinhole,
        fov_deg: DEFAULT_FOV_DEG,
        reference: Reference::Hounsfield,
        look: PresetLook {
            // The lumen is bright: the "secretion" threshold lies between contrast and wall.
            tissue: 130.0,
            secretion: 220.0,
            secretion_mode: SecretionMode::Off,
            wetness: 0.4,
            texture: "none",
            attenuation_mm: 30.0,
            tissue_color: [0.85, 0.35, 0.3],
            secretion_color: [0.8, 0.1, 0.1],
            ..PresetLook::CT
        },
    },
    Preset {
        name: "sinus",
        description: "head CT: nasal cavity and sinuses, wall at -500 HU, bone seen through it",
        mode: Mode::Hybrid,
        tf: "sinus",
        iso: -500.0,
        iso_opacity: 0.6,
        iso_color: None,
        iso2: None,
        peel: None,
        lumen: Some(PresetLumen {
            threshold: -500.0,
            side: LumenSide::Below,
            tissue: "air",
            structure: Structure::NasalCavity,
        }),
        // The bone window: air black, thin sinus walls distinct from soft tissue.
        window: Window {
            level_hu: 400.0,
            width_hu: 2000.0,
        },
        projection: Projection::Pinhole,
        fov_deg: DEFAULT_FOV_DEG,
        reference: Reference::Hounsfield,
        look: PresetLook::CT,
    },
    Preset {
        name: "ventricles",
        description: "T1 MRI: the lateral ventricles, CSF (25-40) darker than white matter at 75",
        mode: Mode::Hybrid,
        tf: "ventricles",
        iso: 75.0,
        iso_opacity: 0.6,
        iso_color: None,
        iso2: None,
        peel: None,
        lumen: Some(PresetLumen {
            threshold: 75.0,
            side: LumenSide::Below,
            tissue: "CSF",
            structure: Structure::Central,
        }),
        // T1 intensity units (chris_t1: CSF 25–40, white matter 106–130): 0 black, 160 white.
        window: Window {
            level_hu: 80.0,
            width_hu: 160.0,
        },
        projection: Projection::Pinhole,
        fov_deg: DEFAULT_FOV_DEG,
        // The CSF and tissue class medians `tissue::measure_csf` finds on chris_t1 (partial
        // volume lifts CSF from its 25–40 core): that scan keeps the table's values.
        reference: Reference::T1Brain {
            csf: 43.0,
            tissue: 119.0,
        },
        look: PresetLook {
            // Ependyma: between CSF (43) and the wall at 75, and the secretion threshold just
            // above CSF (none by default: CSF is clear).
            tissue: 80.0,
            secretion: 60.0,
            secretion_mode: SecretionMode::Off,
            wetness: 0.5,
            texture_mm: 48.0,
            attenuation_mm: 30.0,
            tissue_color: [0.92, 0.84, 0.76],
            secretion_color: [0.85, 0.85, 0.9],
            ..PresetLook::CT
        },
    },
    Preset {
        name: "arthroscopy",
        description:
            "T1 MRI joint: from the joint space, the surfaces of the bones around it (peel \
                      back into tissue above 30)",
        mode: Mode::Peel,
        tf: "arthroscopy",
        // The peel draws the bones' surface as an opaque one.
        iso: 30.0,
        iso_opacity: 1.0,
        iso_color: Some([0.93, 0.88, 0.78]),
        iso2: None,
        // Measured on shared/data/knee-mri (T1, no contrast). Around the femorotibial joint
        // two-class Otsu splits the dark joint space, cortex and menisci (mean 24) from marrow
        // (48) at 36, but 36 lies inside the femoral marrow's texture (median 41, quartile 34),
        // which would peel; 30 lies midway between the dark class and the tibial marrow's 10th
        // percentile (35). From the joint space the first crossing above it is a bone's surface.
        peel: Some(PresetPeel {
            threshold: 30.0,
            falling: false,
            layer: PeelLayer::Nth(1),
            tf_after: "arthroscopy",
        }),
        // The dark joint space between the bones is the lumen the eye starts in: from there
        // the peel's first rise above 30 is the bones' surface.
        lumen: Some(PresetLumen {
            threshold: 30.0,
            side: LumenSide::Below,
            tissue: "joint space",
            structure: Structure::Joint,
        }),
        // T1 intensity units: joint space black, marrow light grey.
        window: Window {
            level_hu: 50.0,
            width_hu: 100.0,
        },
        projection: Projection::Pinhole,
        fov_deg: DEFAULT_FOV_DEG,
        reference: Reference::AsGiven,
        look: PresetLook {
            // The joint space is the lumen (below the threshold): fluid in it (the secretion,
            // off) lies below too.
            tissue: 30.0,
            secretion: 20.0,
            secretion_mode: SecretionMode::Off,
            wetness: 0.3,
            texture: "none",
            attenuation_mm: 30.0,
            tissue_color: [0.93, 0.88, 0.78],
            ..PresetLook::CT
        },
    },
    Preset {
        name: "ramp",
        description: "benchmark: the paper's Table 1 alpha ramp (-700 to -300 HU), wall 50 %",
        mode: Mode::Hybrid,
        tf: "ramp",
        iso: -500.0,
        iso_opacity: 0.5,
        iso_color: None,
        iso2: None,
        peel: None,
        lumen: None,
        window: AIR_TISSUE,
        projection: Projection::Pinhole,
        fov_deg: DEFAULT_FOV_DEG,
        reference: Reference::Hounsfield,
        look: PresetLook::CT,
    },
    Preset {
        name: "complex",
        description: "benchmark: the paper's Table 2 kind of TF, faint peaks, wall 50 %",
        mode: Mode::Hybrid,
        tf: "complex",
        iso: -500.0,
        iso_opacity: 0.5,
        iso_color: None,
        iso2: None,
        peel: None,
        lumen: None,
        window: AIR_TISSUE,
        projection: Projection::Pinhole,
        fov_deg: DEFAULT_FOV_DEG,
        reference: Reference::Hounsfield,
        look: PresetLook::CT,
    },
];

/// Every preset, in the table's order.
pub fn iter() -> impl Iterator<Item = &'static Preset> {
    ALL.iter()
}

/// The names of the presets that navigate a lumen, comma-separated (for messages).
pub fn lumen_names() -> String {
    names(iter().filter(|p| p.lumen.is_some()))
}

/// The names of every preset, comma-separated (for messages).
pub fn all_names() -> String {
    names(iter())
}

fn names<'a>(presets: impl Iterator<Item = &'a Preset>) -> String {
    presets.map(|p| p.name).collect::<Vec<_>>().join(", ")
}

impl Preset {
    /// The preset called `name` (surrounding space and ASCII case ignored).
    pub fn find(name: &str) -> Option<&'static Preset> {
        let name = name.trim();
        iter().find(|p| p.name.eq_ignore_ascii_case(name))
    }

    /// The transfer function the preset names.
    pub fn transfer_function(&self) -> TransferFunction {
        TransferFunction::preset(self.tf).expect("every preset names a known transfer function")
    }

    /// The render settings of this preset: its mode, transfer function and surfaces, every
    /// other field at [`RenderSettings`]' default.
    pub fn settings(&self) -> RenderSettings {
        let mut s = RenderSettings {
            mode: self.mode,
            iso_hu: self.iso,
            iso_opacity: self.iso_opacity,
            tf: self.transfer_function(),
            ..RenderSettings::default()
        };
        if let Some(color) = self.iso_color {
            s.iso_color = color;
        }
        if let Some(peel) = self.peel {
            s.peel = PeelSettings {
                threshold_hu: Some(peel.threshold),
                falling: peel.falling,
                layer: peel.layer,
                tf_after: TransferFunction::preset(peel.tf_after),
                ..PeelSettings::default()
            };
        }
        if let Some(upper) = self.iso2 {
            s.iso2_hu = upper.iso;
            s.iso2_opacity = upper.opacity;
            if let Some(color) = upper.color {
                s.iso2_color = color;
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::look::LookKind;

    #[test]
    fn names_are_unique_lower_case_and_found_in_any_case() {
        for (n, preset) in ALL.iter().enumerate() {
            assert_eq!(preset.name, preset.name.to_ascii_lowercase());
            assert!(ALL[..n].iter().all(|p| p.name != preset.name), "{preset:?}");
            let shouted = format!(" {} ", preset.name.to_ascii_uppercase());
            assert_eq!(Preset::find(&shouted), Some(preset));
            assert!(!preset.description.is_empty() && !preset.description.contains('\n'));
        }
        assert_eq!(Preset::find("gastroscopy"), None);
        assert_eq!(iter().count(), 8);
        assert_eq!(
            lumen_names(),
            "colonoscopy, bronchoscopy, angioscopy, sinus, ventricles, arthroscopy"
        );
    }

    #[test]
    fn every_preset_gives_valid_settings_with_its_named_transfer_function() {
        for preset in ALL {
            let s = preset.settings();
            assert_eq!(s.validate(), Ok(()), "{}", preset.name);
            assert_eq!(s.tf, TransferFunction::preset(preset.tf).unwrap());
            assert!(preset.window.width_hu > 0.0);
            assert_eq!(preset.iso2.is_some(), preset.mode == Mode::TwoIso);
            assert_eq!(preset.peel.is_some(), preset.mode == Mode::Peel);
            if let Some(peel) = preset.peel {
                assert!(TransferFunction::preset(peel.tf_after).is_some());
                assert_eq!(s.peel_threshold_hu(), peel.threshold);
            }
            assert!((10.0..=170.0).contains(&preset.fov_deg));
        }
    }

    /// The values the presets had before they moved into this table: images must not change.
    #[test]
    fn settings_are_those_of_before_the_table() {
        let base = RenderSettings::default();
        let hybrid = |tf: &str, iso_hu: f64, iso_opacity: f32| RenderSettings {
            tf: TransferFunction::preset(tf).unwrap(),
            iso_hu,
            iso_opacity,
            ..base.clone()
        };
        let expected = [
            ("colonoscopy", hybrid("colonoscopy", -500.0, 0.6)),
            ("bronchoscopy", hybrid("bronchoscopy", -500.0, 0.6)),
            ("sinus", hybrid("sinus", -500.0, 0.6)),
            ("ventricles", hybrid("ventricles", 75.0, 0.6)),
            ("ramp", hybrid("ramp", -500.0, 0.5)),
            ("complex", hybrid("complex", -500.0, 0.5)),
            (
                "angioscopy",
                RenderSettings {
                    mode: Mode::TwoIso,
                    iso_hu: 130.0,
                    iso_opacity: 0.7,
                    iso_color: [0.85, 0.35, 0.3],
                    iso2_hu: 700.0,
                    ..hybrid("angioscopy", 0.0, 0.0)
                },
            ),
        ];
        for (name, settings) in expected {
            assert_eq!(Preset::find(name).unwrap().settings(), settings, "{name}");
        }
        assert_eq!(Mode::Hybrid, base.mode);
    }

    #[test]
    fn every_look_puts_the_secretion_on_the_lumen_side_of_the_tissue() {
        for preset in ALL {
            let look = preset.look;
            assert_eq!(look.kind, LookKind::Plain, "{}", preset.name);
            let lumen_below = preset.lumen.is_none_or(|l| l.side == LumenSide::Below);
            assert_eq!(look.secretion < look.tissue, lumen_below, "{}", preset.name);
            for kind in [LookKind::Clinical, LookKind::Realistic] {
                let l = crate::look::Look::of_kind(kind, &look).unwrap();
                assert_eq!(l.ray.validate(), Ok(()), "{}", preset.name);
                assert_eq!(l.shading.validate(), Ok(()), "{}", preset.name);
            }
        }
        let sinus = Preset::find("sinus").unwrap().look;
        assert_eq!(
            (sinus.tissue, sinus.secretion_mode),
            (-230.0, SecretionMode::On)
        );
    }

    #[test]
    fn windows_suit_each_procedure() {
        let window = |name| Preset::find(name).unwrap().window;
        // Lung parenchyma (−820 HU) is visible in the lung window, not black.
        assert!(window("bronchoscopy").grey(-820.0) > 20);
        // Enhanced blood (≈ 190 HU) and fat (≈ −100 HU) are told apart in the vessel window.
        let vessel = window("angioscopy");
        assert!(vessel.grey(190.0) > vessel.grey(-100.0) + 60);
        // T1: CSF (30) darker than white matter (120).
        let t1 = window("ventricles");
        assert!(t1.grey(120.0) > t1.grey(30.0) + 100);
        assert_eq!(window("colonoscopy"), Window::AIR_TISSUE);
    }
}
