//! Grouping image files by SeriesInstanceUID and choosing the series to load.

use super::scan::{ImageFile, Scanned};
use crate::error::{ReadError, Result};
use crate::loaded::SeriesSummary;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// How many skipped file names a warning quotes.
const EXAMPLES: usize = 3;

/// The images among `scanned`, with one warning for the files that are not images.
///
/// `root` is the path the user gave. A single file that is not a readable image is an error
/// (its own error when it had one); in a directory such files are skipped and counted, and a
/// directory without any image is an error.
pub(super) fn images(
    root: &Path,
    files: &[PathBuf],
    scanned: Vec<Scanned>,
    warnings: &mut Vec<String>,
) -> Result<Vec<ImageFile>> {
    let single_file = !root.is_dir();
    let mut images = Vec::new();
    let mut skipped: Vec<(&Path, String)> = Vec::new();
    for (path, outcome) in files.iter().zip(scanned) {
        let reason = match outcome {
            Scanned::Image(image) => {
                images.push(image);
                continue;
            }
            Scanned::Unreadable(error) if single_file => return Err(error),
            Scanned::Unreadable(error) => error.to_string(),
            Scanned::NotDicom => "not DICOM".to_string(),
            Scanned::NoImage => "a DICOM object without pixel data".to_string(),
        };
        skipped.push((path, reason));
    }
    if images.is_empty() {
        let what = if single_file {
            "an image".to_string()
        } else {
            format!("a DICOM image among its {} files", files.len())
        };
        let found = skipped
            .first()
            .map_or("no file".to_string(), |(_, reason)| reason.clone());
        return Err(ReadError::format(
            root,
            format!("expected {what}, found {found}"),
        ));
    }
    if !skipped.is_empty() {
        let examples: Vec<String> = skipped
            .iter()
            .take(EXAMPLES)
            .map(|(path, reason)| {
                let name = path.strip_prefix(root).unwrap_or(path);
                format!("{} ({reason})", name.display())
            })
            .collect();
        warnings.push(format!(
            "{}: skipped {} {} not DICOM images, e.g. {}",
            root.display(),
            skipped.len(),
            if skipped.len() == 1 {
                "file that is"
            } else {
                "files that are"
            },
            examples.join(", ")
        ));
    }
    Ok(images)
}

/// Splits `images` by SeriesInstanceUID and returns the wanted series (the one with the most
/// frames when `wanted` is `None`) with a summary of every series, largest first.
pub(super) fn choose(
    root: &Path,
    images: Vec<ImageFile>,
    wanted: Option<&str>,
) -> Result<(Vec<ImageFile>, Vec<SeriesSummary>)> {
    let mut by_uid: BTreeMap<String, Vec<ImageFile>> = BTreeMap::new();
    for image in images {
        by_uid
            .entry(image.series_uid.clone())
            .or_default()
            .push(image);
    }
    let mut found: Vec<SeriesSummary> = by_uid
        .iter()
        .map(|(uid, files)| summary(uid, files))
        .collect();
    // Largest first; ties by UID so that the choice does not depend on the file system.
    found.sort_by(|a, b| b.images.cmp(&a.images).then_with(|| a.uid.cmp(&b.uid)));
    let uid = match wanted {
        Some(uid) if by_uid.contains_key(uid) => uid.to_string(),
        Some(uid) => {
            let listed: Vec<String> = found
                .iter()
                .map(|s| format!("{} ({} images)", s.uid, s.images))
                .collect();
            return Err(ReadError::format(
                root,
                format!(
                    "series {uid} not found; the series found are {}",
                    listed.join(", ")
                ),
            ));
        }
        None => found[0].uid.clone(),
    };
    let chosen = by_uid.remove(&uid).unwrap_or_default();
    Ok((chosen, found))
}

fn summary(uid: &str, files: &[ImageFile]) -> SeriesSummary {
    let first = &files[0];
    SeriesSummary {
        uid: uid.to_string(),
        description: first.description.clone(),
        modality: first.modality.clone(),
        images: files.iter().map(|f| f.frames.len()).sum(),
    }
}
