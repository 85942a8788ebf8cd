//! Finding an OME-Zarr image and its `multiscales` metadata: v0.4 (Zarr v2, `.zattrs`) and
//! v0.5 (Zarr v3, `zarr.json` with `attributes.ome`), at the group's folder or at one of its
//! levels' array folders.

use super::json::read_object;
use crate::error::{ReadError, Result};
use serde::Deserialize;
use serde_json::{Map, Value};
use std::path::{Path, PathBuf};

/// The key of endocast's own attributes beside `ome` (see the module documentation of
/// [`crate::zarr`]).
pub(super) const ENDOCAST_KEY: &str = "endocast";

/// One OME-Zarr image: the first `multiscales` entry of a group.
#[derive(Debug)]
pub(super) struct Image {
    /// The group's folder.
    pub root: PathBuf,
    /// The file the metadata came from, named in errors.
    pub file: PathBuf,
    /// The OME-Zarr version the metadata states (`0.4` when it states none in v2).
    pub version: String,
    /// The multiscales entry.
    pub multiscale: Multiscale,
    /// endocast's own attributes, when the store was written by endocast.
    pub endocast: Option<Value>,
}

/// A `multiscales` entry.
#[derive(Debug, Deserialize)]
pub(super) struct Multiscale {
    /// The axes, slowest first.
    pub axes: Vec<Axis>,
    /// The levels, highest resolution first.
    pub datasets: Vec<Dataset>,
    /// Transformations applied after each level's own.
    #[serde(default, rename = "coordinateTransformations")]
    pub transforms: Vec<Transform>,
}

/// An axis: its name, type (`space`, `time`, `channel`) and unit.
#[derive(Debug, Deserialize)]
#[serde(from = "AxisJson")]
pub(super) struct Axis {
    pub name: String,
    pub kind: Option<String>,
    pub unit: Option<String>,
}

/// An axis as v0.4 and later write it, or as a bare name (v0.3).
#[derive(Deserialize)]
#[serde(untagged)]
enum AxisJson {
    Full {
        name: String,
        #[serde(rename = "type")]
        kind: Option<String>,
        unit: Option<String>,
    },
    Name(String),
}

impl From<AxisJson> for Axis {
    fn from(json: AxisJson) -> Self {
        match json {
            AxisJson::Full { name, kind, unit } => Self { name, kind, unit },
            AxisJson::Name(name) => Self {
                name,
                kind: None,
                unit: None,
            },
        }
    }
}

/// One resolution level: its array's path in the group and its transformations.
#[derive(Debug, Deserialize)]
pub(super) struct Dataset {
    pub path: String,
    #[serde(default, rename = "coordinateTransformations")]
    pub transforms: Vec<Transform>,
}

/// A coordinate transformation (a `path` to binary parameters is not read).
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub(super) enum Transform {
    Identity,
    Scale {
        scale: Vec<f64>,
    },
    Translation {
        translation: Vec<f64>,
    },
    /// OME-Zarr 0.6 (RFC 5): rows of an affine matrix over the axes.
    Affine {
        affine: Vec<Vec<f64>>,
    },
}

/// Whether `folder` is a Zarr node (group or array, v2 or v3) by its metadata files.
pub(crate) fn is_zarr(folder: &Path) -> bool {
    [".zattrs", ".zgroup", ".zarray", "zarr.json"]
        .iter()
        .any(|name| folder.join(name).is_file())
}

/// The OME-Zarr image at `folder` and the level asked for: the group itself (level 0, the
/// highest resolution), or one of its levels' array folders (that level).
pub(super) fn locate(folder: &Path) -> Result<(Image, usize)> {
    if let Some(image) = image_at(folder)? {
        return Ok((image, 0));
    }
    let not_ome = || {
        ReadError::unsupported(
            folder,
            "Zarr store: no OME-Zarr multiscales metadata (in zarr.json's attributes.ome or in \
             .zattrs), here or in the parent folder of a level",
        )
    };
    let (Some(parent), Some(name)) = (folder.parent(), folder.file_name()) else {
        return Err(not_ome());
    };
    let image = image_at(parent)?.ok_or_else(not_ome)?;
    let name = name.to_string_lossy();
    let level = image
        .multiscale
        .datasets
        .iter()
        .position(|d| d.path.trim_matches('/') == name)
        .ok_or_else(|| {
            ReadError::format(
                folder,
                format!("is not one of the levels {} lists", image.file.display()),
            )
        })?;
    Ok((image, level))
}

/// The image whose metadata is in `folder`'s `zarr.json` or `.zattrs`, if any.
fn image_at(folder: &Path) -> Result<Option<Image>> {
    for (name, version) in [("zarr.json", "0.5"), (".zattrs", "0.4")] {
        let file = folder.join(name);
        let Some(object) = read_object(&file)? else {
            continue;
        };
        let attributes = match name {
            "zarr.json" => match object.get("attributes") {
                Some(Value::Object(a)) => a.clone(),
                _ => continue,
            },
            _ => object,
        };
        return image_from(folder, &file, &attributes, version);
    }
    Ok(None)
}

/// The image the group attributes describe: `ome.multiscales` (v0.5) or `multiscales`
/// (v0.4); `None` when they hold neither.
fn image_from(
    folder: &Path,
    file: &Path,
    attributes: &Map<String, Value>,
    default_version: &str,
) -> Result<Option<Image>> {
    let ome = attributes.get("ome").and_then(Value::as_object);
    let holder = ome
        .filter(|o| o.contains_key("multiscales"))
        .unwrap_or(attributes);
    let Some(multiscales) = holder.get("multiscales") else {
        return Ok(None);
    };
    let first = match multiscales {
        Value::Array(entries) => entries.first(),
        _ => None,
    }
    .ok_or_else(|| ReadError::format(file, "multiscales is not a non-empty list"))?;
    let multiscale = Multiscale::deserialize(first)
        .map_err(|e| ReadError::format(file, format!("multiscales: {e}")))?;
    if multiscale.datasets.is_empty() {
        return Err(ReadError::format(file, "multiscales lists no datasets"));
    }
    let version = [holder.get("version"), first.get("version")]
        .into_iter()
        .flatten()
        .find_map(Value::as_str)
        .unwrap_or(default_version)
        .to_owned();
    Ok(Some(Image {
        root: folder.to_path_buf(),
        file: file.to_path_buf(),
        version,
        multiscale,
        endocast: attributes.get(ENDOCAST_KEY).cloned(),
    }))
}
