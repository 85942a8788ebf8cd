//! From OME-Zarr axes and coordinate transformations to a grid in millimetres: the level's
//! own `scale`/`translation` (or 0.6 `affine`) first, then the multiscale's, composed as
//! affine maps over all axes, of which the three space axes `z, y, x` are kept.

use super::metadata::{Axis, Image, Transform};
use crate::error::{ReadError, Result};
use glam::{DAffine3, DMat3, DVec3};
use std::path::Path;

/// Millimetres per unit, for the UDUNITS-2 length names OME-Zarr allows that a scan may use.
const UNITS_MM: [(&str, f64); 8] = [
    ("nanometer", 1e-6),
    ("micrometer", 1e-3),
    ("millimeter", 1.0),
    ("centimeter", 10.0),
    ("decimeter", 100.0),
    ("meter", 1e3),
    ("inch", 25.4),
    ("foot", 304.8),
];

/// The space axes' names, slowest first: index `[z][y][x]`, `x` fastest, is the volume's
/// `(i, j, k) = (x, y, z)`.
const SPACE_AXES: [&str; 3] = ["z", "y", "x"];

/// An affine map over `n` axes: `p = m · q + t`, `m` as rows.
struct Affine {
    m: Vec<Vec<f64>>,
    t: Vec<f64>,
}

/// The world-from-voxel map (millimetres, axes `x, y, z` of the store's physical frame) of
/// level `level` of `image`, whose array has `shape` (slowest first). Checks the axes: three
/// space axes `z, y, x` last, before them only time or channel axes of size 1.
pub(super) fn physical_from_voxel(
    image: &Image,
    level: usize,
    shape: &[u64],
    warnings: &mut Vec<String>,
) -> Result<DAffine3> {
    let file = image.file.as_path();
    let axes = &image.multiscale.axes;
    check_axes(file, axes, shape)?;
    let mut map = Affine::identity(axes.len());
    let dataset = &image.multiscale.datasets[level];
    for transform in dataset
        .transforms
        .iter()
        .chain(&image.multiscale.transforms)
    {
        map.then(file, transform)?;
    }
    let n = axes.len();
    let mm = units_mm(file, &axes[n - 3..], warnings)?;
    // Row r and column c of the x, y, z block are axis 2 − r and 2 − c of the z, y, x one.
    let at = |r: usize, c: usize| map.m[n - 1 - r][n - 1 - c] * mm[2 - r];
    let column = |c: usize| DVec3::new(at(0, c), at(1, c), at(2, c));
    let translation = DVec3::new(
        map.t[n - 1] * mm[2],
        map.t[n - 2] * mm[1],
        map.t[n - 3] * mm[0],
    );
    Ok(DAffine3::from_mat3_translation(
        DMat3::from_cols(column(0), column(1), column(2)),
        translation,
    ))
}

/// Refuses axes other than `[t,] [c,] z, y, x` with `t` and `c` of size 1, or a shape of
/// another length.
fn check_axes(file: &Path, axes: &[Axis], shape: &[u64]) -> Result<()> {
    let names: Vec<&str> = axes.iter().map(|a| a.name.as_str()).collect();
    let refuse = |why: String| {
        ReadError::unsupported(
            file,
            format!("OME-Zarr axes {names:?} with shape {shape:?}: {why} (read: [t,] [c,] z, y, x with t and c of size 1)"),
        )
    };
    if axes.len() != shape.len() {
        return Err(refuse(format!("the array has {} axes", shape.len())));
    }
    if !(3..=5).contains(&axes.len()) {
        return Err(refuse("not 3 to 5 axes".into()));
    }
    let (leading, space) = axes.split_at(axes.len() - 3);
    for (axis, want) in space.iter().zip(SPACE_AXES) {
        let is_space = axis.kind.as_deref().is_none_or(|k| k == "space");
        if !is_space || !axis.name.eq_ignore_ascii_case(want) {
            return Err(refuse(
                "the last three axes must be space axes z, y, x".into(),
            ));
        }
    }
    for (axis, &size) in leading.iter().zip(shape) {
        let kind = axis.kind.as_deref().unwrap_or(axis.name.as_str());
        if !matches!(kind, "time" | "channel" | "t" | "c") || size != 1 {
            return Err(refuse(format!(
                "axis {:?} is not a time or channel axis of size 1",
                axis.name
            )));
        }
    }
    Ok(())
}

/// Millimetres per unit of the space axes `z, y, x`; an axis without a unit is taken to be
/// in millimetres, with a warning.
fn units_mm(file: &Path, space: &[Axis], warnings: &mut Vec<String>) -> Result<[f64; 3]> {
    let mut mm = [1.0; 3];
    for (factor, axis) in mm.iter_mut().zip(space) {
        let Some(unit) = axis.unit.as_deref() else {
            warnings.push(format!(
                "{}: axis {} has no unit: millimetres assumed",
                file.display(),
                axis.name
            ));
            continue;
        };
        *factor = UNITS_MM
            .iter()
            .find(|(name, _)| *name == unit)
            .map(|&(_, f)| f)
            .ok_or_else(|| {
                ReadError::unsupported(
                    file,
                    format!(
                        "unit {unit:?} of axis {} (read: nanometer to meter, inch, foot)",
                        axis.name
                    ),
                )
            })?;
    }
    Ok(mm)
}

impl Affine {
    fn identity(n: usize) -> Self {
        let m = (0..n)
            .map(|r| (0..n).map(|c| f64::from(u8::from(r == c))).collect())
            .collect();
        Self { m, t: vec![0.0; n] }
    }

    /// Applies `transform` after this map.
    fn then(&mut self, file: &Path, transform: &Transform) -> Result<()> {
        let n = self.t.len();
        match transform {
            Transform::Identity => {}
            Transform::Scale { scale } => {
                let scale = checked(file, "scale", scale, n)?;
                if let Some(axis) = scale.iter().position(|&s| s == 0.0) {
                    return Err(ReadError::format(
                        file,
                        format!("scale of axis {axis} is 0"),
                    ));
                }
                let rows = self.m.iter_mut().zip(self.t.iter_mut());
                for ((row, t), s) in rows.zip(scale) {
                    row.iter_mut().for_each(|v| *v *= s);
                    *t *= s;
                }
            }
            Transform::Translation { translation } => {
                let shift = checked(file, "translation", translation, n)?;
                self.t.iter_mut().zip(shift).for_each(|(t, s)| *t += s);
            }
            Transform::Affine { affine } => self.then_affine(file, affine)?,
        }
        Ok(())
    }

    /// Applies an affine given as `n` or `n + 1` rows of `n + 1` numbers (the last one the
    /// translation) after this map.
    fn then_affine(&mut self, file: &Path, rows: &[Vec<f64>]) -> Result<()> {
        let n = self.t.len();
        let well_formed =
            (rows.len() == n || rows.len() == n + 1) && rows.iter().all(|r| r.len() == n + 1);
        if !well_formed {
            return Err(ReadError::format(
                file,
                format!(
                    "affine: expected {n} or {} rows of {} numbers",
                    n + 1,
                    n + 1
                ),
            ));
        }
        for row in rows {
            checked(file, "affine", row, n + 1)?;
        }
        let apply = |row: &[f64], column: &dyn Fn(usize) -> f64| {
            (0..n).map(|k| row[k] * column(k)).sum::<f64>()
        };
        let m = (0..n)
            .map(|r| (0..n).map(|c| apply(&rows[r], &|k| self.m[k][c])).collect())
            .collect();
        let t = (0..n)
            .map(|r| apply(&rows[r], &|k| self.t[k]) + rows[r][n])
            .collect();
        *self = Self { m, t };
        Ok(())
    }
}

/// `values` when they are `n` finite numbers; an error naming `what` otherwise.
fn checked<'a>(file: &Path, what: &str, values: &'a [f64], n: usize) -> Result<&'a [f64]> {
    if values.len() != n {
        return Err(ReadError::format(
            file,
            format!("{what} has {} values for {n} axes", values.len()),
        ));
    }
    if let Some(bad) = values.iter().find(|v| !v.is_finite()) {
        return Err(ReadError::format(
            file,
            format!("{what} holds {bad}, not a finite number"),
        ));
    }
    Ok(values)
}
