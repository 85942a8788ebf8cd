//! `endocast.path(..., target=...)`: the bronchoscope's route to a target, as `endocast path
//! --target` plans it (the same core [`Study::plan_to_target`]).

use crate::errors::error;
use crate::kwargs::Kwargs;
use endocast_core::navigate::DEFAULT_SCOPE_DIAMETER_MM;
use endocast_core::path::SmoothOptions;
use endocast_core::study::{Study, TargetPath};
use endocast_core::Volume;
use glam::DVec3;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The `target` and `scope_diameter` keywords.
pub struct TargetOptions {
    target_mm: DVec3,
    scope_diameter_mm: f64,
}

impl TargetOptions {
    /// Takes `target` and `scope_diameter` (which needs `target`); `None` without a target.
    pub fn take(kw: &Kwargs) -> PyResult<Option<Self>> {
        let target = kw.take::<[f64; 3]>("target")?;
        let scope = kw.take::<f64>("scope_diameter")?;
        match (target, scope) {
            (None, Some(_)) => Err(error("scope_diameter needs a target")),
            (None, None) => Ok(None),
            (Some(t), scope) => Ok(Some(Self {
                target_mm: DVec3::from(t),
                scope_diameter_mm: scope.unwrap_or(DEFAULT_SCOPE_DIAMETER_MM),
            })),
        }
    }

    /// The study's route to the target, smoothed with `options`.
    pub fn plan(
        &self,
        volume: &Volume,
        study: &Study,
        options: &SmoothOptions,
    ) -> PyResult<TargetPath> {
        study
            .plan_to_target(volume, self.target_mm, self.scope_diameter_mm, options)
            .map_err(|e| error(e.to_string()))
    }
}

/// What the route dict holds, gathered without the interpreter.
pub struct RouteSummary {
    target: [f64; 3],
    scope_diameter_mm: f64,
    end: [f64; 3],
    remaining_mm: f64,
    narrowest_diameter_mm: Option<f64>,
    branches: Vec<(String, u32)>,
    carina: Option<[f64; 3]>,
}

impl RouteSummary {
    /// The summary of a planned route.
    pub fn of(routed: &TargetPath) -> Self {
        let route = &routed.route;
        let all = routed.tree.branches();
        Self {
            target: route.target_mm.to_array(),
            scope_diameter_mm: route.scope_diameter_mm,
            end: route.end_mm().to_array(),
            remaining_mm: route.remaining_mm,
            narrowest_diameter_mm: Some(route.narrowest_mm).filter(|d| d.is_finite()),
            branches: route
                .branches
                .iter()
                .map(|&b| (all[b].name.clone(), all[b].generation))
                .collect(),
            carina: routed.tree.carina_mm().map(|c| c.to_array()),
        }
    }

    /// The dict `endocast.path` returns (the keys of `endocast path --target --json`).
    pub fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        dict.set_item("target", self.target)?;
        dict.set_item("scope_diameter_mm", self.scope_diameter_mm)?;
        dict.set_item("end", self.end)?;
        dict.set_item("remaining_mm", self.remaining_mm)?;
        dict.set_item("narrowest_diameter_mm", self.narrowest_diameter_mm)?;
        let branches = self
            .branches
            .iter()
            .map(|(name, generation)| {
                let b = PyDict::new(py);
                b.set_item("name", name)?;
                b.set_item("generation", generation)?;
                Ok(b)
            })
            .collect::<PyResult<Vec<_>>>()?;
        dict.set_item("branches", branches)?;
        dict.set_item("carina", self.carina)?;
        Ok(dict)
    }
}
