//! The `data file` field: one detached file, a `LIST` of files, or a `%d` pattern of files.

use super::fields::DataFiles;
use crate::error::{ReadError, Result};
use crate::limits::Limits;
use std::path::Path;

/// The `data file` field in its three forms: one name, `LIST [subdim]` with the names on the
/// following lines, or `FORMAT first last step [subdim]` with a `%d` in FORMAT.
pub(super) fn parse_data_file(
    path: &Path,
    value: &str,
    list: &[String],
    dimension: usize,
    limits: &Limits,
) -> Result<DataFiles> {
    let words: Vec<&str> = value.split_whitespace().collect();
    let subdim = |word: Option<&&str>| -> Result<Option<usize>> {
        let Some(word) = word else { return Ok(None) };
        match word.parse::<usize>() {
            Ok(d) if (1..=dimension).contains(&d) => Ok(Some(d)),
            _ => Err(ReadError::format(
                path,
                format!("data file: the sub-dimension must be 1 … {dimension}, found {word:?}"),
            )),
        }
    };
    if words.first() == Some(&"LIST") {
        if words.len() > 2 {
            return Err(ReadError::format(
                path,
                format!("data file: expected \"LIST [subdim]\", found {value:?}"),
            ));
        }
        let names: Vec<String> = list.iter().filter(|n| !n.is_empty()).cloned().collect();
        if names.is_empty() {
            return Err(ReadError::format(
                path,
                "data file: LIST is followed by no file names",
            ));
        }
        return Ok(DataFiles::Many {
            names,
            subdim: subdim(words.get(1))?,
        });
    }
    let is_pattern = matches!(words.len(), 4 | 5) && words[0].contains('%');
    if !is_pattern {
        return Ok(DataFiles::Single(value.to_owned()));
    }
    let numbers: Option<Vec<i64>> = words[1..4].iter().map(|w| w.parse().ok()).collect();
    let Some(&[first, last, step]) = numbers.as_deref() else {
        return Err(ReadError::format(
            path,
            format!("data file: expected \"FORMAT first last step [subdim]\" with integers, found {value:?}"),
        ));
    };
    let names = expand_pattern(path, words[0], first, last, step, limits)?;
    Ok(DataFiles::Many {
        names,
        subdim: subdim(words.get(4))?,
    })
}

/// The file names of a `%d` pattern: `first`, `first + step`, … while not past `last`.
fn expand_pattern(
    path: &Path,
    format: &str,
    first: i64,
    last: i64,
    step: i64,
    limits: &Limits,
) -> Result<Vec<String>> {
    let bad = |why: &str| {
        ReadError::format(
            path,
            format!("data file pattern {format:?} {first} {last} {step}: {why}"),
        )
    };
    let (prefix, width, zero_pad, suffix) =
        split_pattern(format).ok_or_else(|| bad("expected one %d (or %0Nd) in the name"))?;
    if step == 0 {
        return Err(bad("the step must not be 0"));
    }
    let span = i128::from(last) - i128::from(first);
    if span != 0 && (span < 0) != (step < 0) {
        return Err(bad("the step goes away from the last index"));
    }
    let count = span / i128::from(step) + 1;
    // Checked before the names are built: the range may claim billions of files.
    limits.check_slices(path, u64::try_from(count).unwrap_or(u64::MAX))?;
    Ok((0..count)
        .map(|n| {
            let index = i128::from(first) + n * i128::from(step);
            let number = if zero_pad {
                format!("{index:0width$}")
            } else {
                format!("{index:width$}")
            };
            format!("{prefix}{number}{suffix}")
        })
        .collect())
}

/// Splits `name.%03d.raw` into (`name.`, 3, zero-padded, `.raw`).
fn split_pattern(format: &str) -> Option<(&str, usize, bool, &str)> {
    let percent = format.find('%')?;
    let rest = &format[percent + 1..];
    let d = rest.find('d')?;
    let spec = &rest[..d];
    if !spec.chars().all(|c| c.is_ascii_digit()) || spec.len() > 3 {
        return None;
    }
    let suffix = &rest[d + 1..];
    if suffix.contains('%') {
        return None;
    }
    let width = if spec.is_empty() {
        0
    } else {
        spec.parse().ok()?
    };
    Some((&format[..percent], width, spec.starts_with('0'), suffix))
}
