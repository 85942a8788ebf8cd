//! `endocast path --target`: the bronchoscope's route from the trachea to a target through
//! airways at least as wide as the scope, with the labels of the branches it passes and the
//! distance left from its end to the target.

use anyhow::Result;
use endocast_core::navigate::{AirwayBranch, AirwayTree};
use endocast_core::path::SmoothOptions;
use endocast_core::study::{Study, TargetPath};
use endocast_core::Volume;
use glam::DVec3;
use serde_json::{json, Value};

/// The study's route to `target` for a scope of `scope_mm` ([`Study::plan_to_target`]).
pub(crate) fn plan(
    volume: &Volume,
    study: &Study,
    target: [f64; 3],
    scope_mm: f64,
    options: &SmoothOptions,
) -> Result<TargetPath> {
    Ok(study.plan_to_target(volume, DVec3::from(target), scope_mm, options)?)
}

/// The route's part of `path --json`: target, scope, end, remaining distance, the branches
/// passed, the carina and the whole labelled tree.
pub(crate) fn to_json(target: &TargetPath) -> Value {
    let route = &target.route;
    let tree = &target.tree;
    let passed: Vec<Value> = route
        .branches
        .iter()
        .map(|&b| branch_label(&tree.branches()[b]))
        .collect();
    json!({
        "target": route.target_mm.to_array(),
        "scope_diameter_mm": route.scope_diameter_mm,
        "end": route.end_mm().to_array(),
        "remaining_mm": route.remaining_mm,
        "narrowest_diameter_mm": finite(route.narrowest_mm),
        "branches": passed,
        "carina": tree.carina_mm().map(|c| c.to_array()),
        "airway_tree": tree_json(tree),
    })
}

/// One line for the terminal.
pub(crate) fn say(target: &TargetPath) -> String {
    let route = &target.route;
    let names: Vec<&str> = route
        .branches
        .iter()
        .map(|&b| target.tree.branches()[b].name.as_str())
        .collect();
    format!(
        "route for a {} mm scope: {}; ends {:.1} mm from the target",
        route.scope_diameter_mm,
        names.join(" > "),
        route.remaining_mm
    )
}

/// A branch's name and generation.
fn branch_label(branch: &AirwayBranch) -> Value {
    json!({"name": branch.name, "generation": branch.generation})
}

/// Every branch of the tree: name, generation, parent, ends, length, narrowest diameter and
/// where its fork splits (`null` for a tip).
fn tree_json(tree: &AirwayTree) -> Vec<Value> {
    tree.branches()
        .iter()
        .map(|b| {
            let narrowest = b.diameters_mm.iter().copied().fold(f64::INFINITY, f64::min);
            json!({
                "name": b.name,
                "generation": b.generation,
                "parent": b.parent,
                "start": b.points_mm[0].to_array(),
                "end": b.points_mm[b.points_mm.len() - 1].to_array(),
                "length_mm": b.length_mm(),
                "min_diameter_mm": finite(narrowest),
                "split": b.split_mm.map(|s| s.to_array()),
            })
        })
        .collect()
}

/// `null` for a diameter only the scan's border limits.
fn finite(mm: f64) -> Value {
    if mm.is_finite() {
        json!(mm)
    } else {
        Value::Null
    }
}
