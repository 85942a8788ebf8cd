//! `endocast annotate`: add, list and remove the annotations of a case file from scripts —
//! points with labels, strokes and measurements, given as world points or picked through a
//! pixel of a view of the case's scan.

use crate::look::{in_pool, LookArgs};
use crate::lumen::LumenArgs;
use crate::optics::LensArgs;
use crate::parse::{parse_size, parse_vec3};
use crate::pose_args::PoseArgs;
use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use endocast_core::annotate::{Annotation, Annotations, ScanIdentity, Shape, SurfaceView};
use endocast_core::camera::Camera;
use endocast_core::render::Renderer;
use endocast_core::Volume;
use endocast_io::case::{AnnotationRecord, Case, ScanSource};
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Arguments of `endocast annotate`.
#[derive(Args, Debug)]
pub struct AnnotateArgs {
    /// The case file (JSON; made when it does not exist, which needs --scan).
    case: PathBuf,
    /// The scan: for a new case, the one it is about; for an existing case, checked to be its
    /// scan (an error names what differs). Picking with --pixel reads the case's scan.
    #[arg(long, value_name = "PATH")]
    scan: Option<PathBuf>,
    /// DICOM: the SeriesInstanceUID of --scan, when not the largest series.
    #[arg(long, value_name = "UID", requires = "scan")]
    series: Option<String>,
    /// For a --scan that declares no patient orientation: where its index axes point (e.g.
    /// LPI), as `render --orientation`; the case keeps it.
    #[arg(long, value_name = "CODE", requires = "scan")]
    orientation: Option<String>,
    #[command(subcommand)]
    action: Action,
}

#[derive(Subcommand, Debug)]
enum Action {
    /// Add an annotation at world points (--at) or at the surface seen at pixels of a view
    /// (--pixel with --eye and --look-at).
    Add(Box<AddArgs>),
    /// List the annotations (id, kind, label, points; a measurement's length).
    List {
        /// As JSON, the case file's records.
        #[arg(long)]
        json: bool,
    },
    /// Remove annotations by id.
    Remove {
        /// Their ids, as `list` shows them.
        #[arg(required = true)]
        ids: Vec<u32>,
    },
}

/// The kinds of annotation.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// One point (a label is optional).
    Point,
    /// A text label at a point (--label required).
    Label,
    /// A line on the tissue through the points in order.
    Stroke,
    /// The distance between two points, mm.
    Measure,
}

#[derive(Args, Debug)]
struct AddArgs {
    /// What to add.
    #[arg(value_enum)]
    kind: Kind,
    /// A point, world mm (LPS). Repeat for strokes and measurements.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    at: Vec<[f64; 3]>,
    /// Picks the surface seen at this pixel (column, row from the top left; its centre, or
    /// with fractions a point between pixel centres) of the view given by --eye, --look-at and
    /// the look options. Repeatable.
    #[arg(long, value_name = "X,Y", value_parser = parse_image_point, conflicts_with = "at")]
    pixel: Vec<[f64; 2]>,
    /// The label drawn beside it.
    #[arg(long, default_value = "")]
    label: String,
    /// Its colour R,G,B (0–255; default by kind).
    #[arg(long, value_name = "R,G,B", value_parser = parse_rgb)]
    color: Option<[u8; 3]>,
    #[command(flatten)]
    view: PickView,
}

/// The view pixels are picked in.
#[derive(Args, Debug)]
struct PickView {
    #[command(flatten)]
    pose: PoseArgs,
    /// Field of view, degrees (default: the preset's, else 90).
    #[arg(long, value_name = "DEG")]
    fov: Option<f64>,
    /// Size of the view, pixels.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    size: [usize; 2],
    #[command(flatten)]
    lens: LensArgs,
    #[command(flatten)]
    look: LookArgs,
}

/// Runs `endocast annotate`.
pub fn run(args: &AnnotateArgs) -> Result<()> {
    let mut opened = Opened::new(args)?;
    match &args.action {
        Action::List { json } => list(&opened.case.annotations(&args.case)?, *json)?,
        Action::Remove { ids } => {
            let left = opened.save(&args.case, |marks| {
                for id in ids {
                    marks
                        .remove(*id)
                        .with_context(|| format!("{}: no annotation {id}", args.case.display()))?;
                }
                Ok(marks.len())
            })?;
            println!("removed {} annotation(s); {left} left", ids.len());
        }
        Action::Add(add) => {
            let points = if add.pixel.is_empty() {
                add.at.iter().map(|p| DVec3::from(*p)).collect()
            } else {
                pick(&add.pixel, &add.view, opened.volume(&args.case)?)?
            };
            let annotation = annotation(add, &points)?;
            let added = opened.save(&args.case, |marks| {
                let id = marks.add(annotation)?;
                marks.get(id).cloned().context("the annotation just added")
            })?;
            println!("added {}", line(&added));
        }
    }
    Ok(())
}

/// The case, its scan when read, and whether it is new.
struct Opened {
    case: Case,
    volume: Option<Volume>,
}

impl Opened {
    /// Reads the case (or makes it for --scan) and checks --scan against it.
    fn new(args: &AnnotateArgs) -> Result<Self> {
        let source = args.scan.as_ref().map(|path| ScanSource::File {
            path: path.clone(),
            series: args.series.clone(),
            orientation: args.orientation.clone(),
        });
        let volume = source.as_ref().map(load).transpose()?;
        let identity = volume.as_ref().map(ScanIdentity::of);
        if !args.case.exists() {
            let (Some(source), Some(identity)) = (source, identity) else {
                bail!(
                    "{} does not exist: give --scan to make a new case",
                    args.case.display()
                );
            };
            return Ok(Self {
                case: Case::new(source, Some(&identity)),
                volume,
            });
        }
        let case = Case::read(&args.case)?;
        if let Some(identity) = &identity {
            case.check_scan(identity, &args.case)?;
        }
        Ok(Self { case, volume })
    }

    /// The case's scan, read once and checked against the case.
    fn volume(&mut self, path: &Path) -> Result<&Volume> {
        if self.volume.is_none() {
            let volume = load(&self.case.scan)?;
            self.case.check_scan(&ScanIdentity::of(&volume), path)?;
            self.volume = Some(volume);
        }
        self.volume.as_ref().context("the case's scan")
    }

    /// Makes `change` to the case's annotations and writes it, atomically. The case is read
    /// again under its lock first (see [`Case::update`]), so that what other programs saved
    /// since it was opened is kept; returns what `change` returns.
    fn save<T>(
        &self,
        path: &Path,
        change: impl FnOnce(&mut Annotations) -> Result<T>,
    ) -> Result<T> {
        Case::update(
            path,
            || Ok(self.case.clone()),
            |case| {
                if case.identity != self.case.identity {
                    bail!(
                        "{}: the case was changed to another scan meanwhile",
                        path.display()
                    );
                }
                let mut marks = case.annotations(path)?;
                let changed = change(&mut marks)?;
                case.set_annotations(&marks);
                Ok(changed)
            },
        )
    }
}

fn load(source: &ScanSource) -> Result<Volume> {
    source.load().map_err(anyhow::Error::msg)
}

/// The annotation `add` describes at `points`.
fn annotation(add: &AddArgs, points: &[DVec3]) -> Result<Annotation> {
    let kind = match add.kind {
        Kind::Label if add.label.trim().is_empty() => bail!("a label needs --label TEXT"),
        Kind::Point | Kind::Label => "point",
        Kind::Stroke => "stroke",
        Kind::Measure => "measure",
    };
    let shape = Shape::from_points(kind, points)
        .map_err(|e| anyhow::anyhow!("{e} (give them with --at or --pixel)"))?;
    let mut annotation = Annotation::new(shape).labelled(&add.label);
    if let Some(color) = add.color {
        annotation.color = color;
    }
    Ok(annotation)
}

/// The surface points seen at `pixels` of the view `view` describes.
fn pick(pixels: &[[f64; 2]], view: &PickView, volume: &Volume) -> Result<Vec<DVec3>> {
    let Some(pose) = view.pose.pose()? else {
        bail!("--pixel needs the view: --eye and --look-at");
    };
    let look = view
        .look
        .on_scan(volume, &LumenArgs::default(), Some(pose), view.fov)?;
    let (lo, hi) = volume.geometry().world_bounds();
    let optics = view.lens.optics(
        look.study.preset(),
        look.look.as_ref(),
        view.fov,
        0.0,
        (hi - lo).length(),
    )?;
    let camera: Camera = optics
        .camera(pose.eye_mm, pose.look_at_mm, pose.up, view.size)
        .context("invalid camera")?;
    let renderer = Arc::new(Renderer::new(volume.clone()));
    let prepared = renderer
        .prepare(&look.settings)
        .context("invalid render settings")?;
    let frame = in_pool(view.look.threads, || prepared.render(&camera))?;
    let spacing = volume.geometry().spacing_mm();
    let surface = SurfaceView::new(&camera, &frame.depth_mm, spacing);
    pixels
        .iter()
        .map(|&[x, y]| {
            surface.pick(x + 0.5, y + 0.5).with_context(|| {
                format!(
                    "pixel {x},{y} of the view shows no surface (wall at {:.1})",
                    look.settings.iso_hu
                )
            })
        })
        .collect()
}

/// Prints the annotations, one a line, or as JSON records.
fn list(marks: &Annotations, json: bool) -> Result<()> {
    if json {
        let records: Vec<AnnotationRecord> =
            marks.items().iter().map(AnnotationRecord::from).collect();
        println!("{}", serde_json::to_string_pretty(&records)?);
    } else {
        for a in marks.items() {
            println!("{}", line(a));
        }
    }
    Ok(())
}

/// One line about an annotation: `2 measure "septum" 12.3 mm: (x, y, z) (x, y, z)`.
fn line(a: &Annotation) -> String {
    let points: Vec<String> = a
        .shape
        .points()
        .iter()
        .map(|p| format!("({:.2}, {:.2}, {:.2})", p.x, p.y, p.z))
        .collect();
    let length = a
        .distance_mm()
        .map_or_else(String::new, |mm| format!(" {mm:.2} mm"));
    format!(
        "{} {} {:?}{length}: {}",
        a.id,
        a.shape.kind(),
        a.label,
        points.join(" ")
    )
}

/// An image position `X,Y` in pixels (fractions allowed).
fn parse_image_point(text: &str) -> Result<[f64; 2], String> {
    let (x, y) = text
        .split_once(',')
        .ok_or_else(|| format!("expected X,Y, found {text:?}"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v >= 0.0)
            .ok_or_else(|| format!("{s:?} is not a pixel position"))
    };
    Ok([parse(x)?, parse(y)?])
}

/// A colour `R,G,B`, each 0–255.
fn parse_rgb(text: &str) -> Result<[u8; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [r, g, b] = parts.as_slice() else {
        return Err(format!("expected R,G,B, found {text:?}"));
    };
    let parse = |s: &str| s.parse::<u8>().map_err(|_| format!("{s:?} is not 0–255"));
    Ok([parse(r)?, parse(g)?, parse(b)?])
}
