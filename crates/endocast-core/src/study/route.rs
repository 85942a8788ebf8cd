//! Paths planned in a study: from its start (or a point the user gave) through the structure
//! it found, or through the lumen grown from the point.

use super::Study;
use crate::navigate::{
    plan_in, plan_path, seed_voxel, DistanceField, Lumen, LumenChoiceError, NavError, PathEnd,
    PlannedPath,
};
use crate::path::SmoothOptions;
use crate::Volume;
use glam::DVec3;
use thiserror::Error;

/// A path planned in a study, with the lumen it was planned in.
#[derive(Debug)]
pub struct StudyPath {
    /// The lumen's voxel count.
    pub lumen_voxels: usize,
    /// The lumen's distance field.
    pub field: DistanceField,
    /// The path.
    pub planned: PlannedPath,
}

/// Why a study plans no path.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum StudyPathError {
    /// No start was given and no structure was found to start in.
    #[error("{0}")]
    NoStart(String),
    /// The study names no lumen threshold.
    #[error(transparent)]
    Lumen(#[from] LumenChoiceError),
    /// The lumen gives no path.
    #[error("no path in the lumen {what}: {error}")]
    Navigation {
        /// The lumen, in words.
        what: String,
        /// Why.
        error: NavError,
    },
}

impl Study {
    /// The centred path from `from` (else the study's start in its structure) to `to` (else the
    /// structure's known end, else the farthest point), smoothed with `options`: inside the
    /// structure the study found when it starts there (the path may not leave it for the rest
    /// of the lumen), else through the lumen grown from the start at the study's threshold.
    pub fn plan(
        &self,
        volume: &Volume,
        from: Option<DVec3>,
        to: Option<DVec3>,
        options: &SmoothOptions,
    ) -> Result<StudyPath, StudyPathError> {
        let (threshold, side) = self.lumen()?;
        let start = match from {
            Some(start) => start,
            None if self.found().is_some() => self.start_pose().eye_mm,
            None => return Err(StudyPathError::NoStart(self.no_start())),
        };
        let failed = |error| StudyPathError::Navigation {
            what: format!("{side} {}", crate::tissue::short(threshold)),
            error,
        };
        let within = self
            .structure()
            .filter(|lumen| seed_voxel(volume, start).is_ok_and(|v| lumen.contains(v)));
        let Some(lumen) = within else {
            let end = to.map_or(PathEnd::Farthest, PathEnd::Point);
            let (lumen, field, planned) =
                plan_path(volume, threshold, side, start, end, options).map_err(failed)?;
            return Ok(StudyPath {
                lumen_voxels: lumen.voxel_count(),
                field,
                planned,
            });
        };
        let end = to
            .or(self.end_mm())
            .map_or(PathEnd::Farthest, PathEnd::Point);
        let (field, planned) = plan_in(volume, lumen, start, end, options).map_err(failed)?;
        Ok(StudyPath {
            lumen_voxels: lumen.voxel_count(),
            field,
            planned,
        })
    }

    /// The lumen a route starting at `start_mm` flies through: the structure the study found
    /// (the aorta, not everything as bright as it) when the start is in it — then also its name
    /// — else the lumen grown from the start at the study's threshold.
    pub fn lumen_from(
        &self,
        volume: &Volume,
        start_mm: DVec3,
    ) -> Result<(Lumen, Option<&str>), StudyPathError> {
        let (threshold, side) = self.lumen()?;
        let failed = |error| StudyPathError::Navigation {
            what: format!("{side} {}", crate::tissue::short(threshold)),
            error,
        };
        let seed = seed_voxel(volume, start_mm).map_err(failed)?;
        if let Some(lumen) = self.structure().filter(|l| l.contains(seed)) {
            return Ok((lumen.clone(), self.structure_name()));
        }
        let lumen = Lumen::from_seed(volume, seed, threshold, side).map_err(failed)?;
        Ok((lumen, None))
    }

    /// Why there is no start, in words.
    fn no_start(&self) -> String {
        match (self.preset_name(), self.framing()) {
            (Some(name), Some(reason)) => {
                format!("found no {name} structure in the scan ({reason}); give a start")
            }
            (Some(name), None) => format!("the {name} preset names no lumen; give a start"),
            (None, _) => "give a start, or a preset to find one".to_owned(),
        }
    }
}
