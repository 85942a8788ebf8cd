//! Bronchoscopy routes in a study: the airway tree of the structure the bronchoscopy preset
//! found, and the route through it to a target, smoothed into a flight path like any other.

use super::{Study, StudyPath, StudyPathError};
use crate::navigate::{
    smooth_raw, AirwayRoute, AirwayTree, CentrelinePath, DistanceField, RouteError,
};
use crate::path::SmoothOptions;
use crate::presets::Structure;
use crate::Volume;
use glam::DVec3;
use thiserror::Error;

/// A route to a target planned in a study.
#[derive(Debug)]
pub struct TargetPath {
    /// The labelled airway tree.
    pub tree: AirwayTree,
    /// The route through it.
    pub route: AirwayRoute,
    /// The route smoothed into a flight path, with the lumen's distance field.
    pub path: StudyPath,
}

/// Why a study plans no route to a target.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum TargetPathError {
    /// The study found no airway tree from the trachea.
    #[error("{0}")]
    NoTree(String),
    /// The target or scope is refused.
    #[error(transparent)]
    Route(#[from] RouteError),
    /// The route gives no path.
    #[error(transparent)]
    Path(#[from] StudyPathError),
}

impl Study {
    /// The airway tree of the structure the study found, with its distance field, when that is
    /// the tree grown from the trachea (the bronchoscopy preset, found with confidence).
    pub fn airway_tree(
        &self,
        volume: &Volume,
    ) -> Result<(AirwayTree, DistanceField), TargetPathError> {
        let trachea = self
            .preset()
            .is_some_and(|p| p.lumen.is_some_and(|l| l.structure == Structure::Trachea));
        let lumen = self.structure().filter(|_| trachea && self.confident());
        let Some(lumen) = lumen else {
            return Err(TargetPathError::NoTree(format!(
                "a target needs the airway tree from the trachea (the bronchoscopy preset); {}",
                self.structure_name().unwrap_or("none was found")
            )));
        };
        let field = DistanceField::new(lumen, volume.geometry());
        Ok((AirwayTree::new(volume, lumen, &field), field))
    }

    /// The route from the trachea to `target_mm` for a scope of `scope_diameter_mm` (see
    /// [`AirwayTree::route`]), smoothed with `options` into a path that stays in the airways.
    pub fn plan_to_target(
        &self,
        volume: &Volume,
        target_mm: DVec3,
        scope_diameter_mm: f64,
        options: &SmoothOptions,
    ) -> Result<TargetPath, TargetPathError> {
        let (tree, field) = self.airway_tree(volume)?;
        let route = tree.route(volume, target_mm, scope_diameter_mm)?;
        let lumen_voxels = self.structure().map_or(0, |l| l.voxel_count());
        let planned = smooth_raw(
            &field,
            CentrelinePath::through(&field, route.points_mm.clone()),
            options,
        )
        .map_err(|error| StudyPathError::Navigation {
            what: "airway tree".to_owned(),
            error,
        })?;
        Ok(TargetPath {
            tree,
            route,
            path: StudyPath {
                lumen_voxels,
                field,
                planned,
            },
        })
    }
}
