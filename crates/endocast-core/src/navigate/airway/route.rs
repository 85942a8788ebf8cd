//! A bronchoscope's route to a target: from the trachea along the airway tree's centrelines,
//! through branches at least as wide as the scope, to the reachable centreline point nearest
//! the target.

use super::body::outside_body;
use super::AirwayTree;
use crate::navigate::error::check_finite;
use crate::navigate::NavError;
use crate::Volume;
use glam::DVec3;
use thiserror::Error;

/// The default scope's outer diameter, mm: 4.9 mm, the insertion tube of a standard adult
/// diagnostic bronchoscope (Olympus BF-Q190 class; thin scopes are about 4 mm, ultrathin about
/// 3 mm, therapeutic ones about 6 mm).
pub const DEFAULT_SCOPE_DIAMETER_MM: f64 = 4.9;

/// A route through the airway tree to a target.
#[derive(Debug, Clone, PartialEq)]
pub struct AirwayRoute {
    /// Centreline voxel centres from the trachea's top to the route's end, world mm (LPS).
    pub points_mm: Vec<DVec3>,
    /// The branches passed (indices into [`AirwayTree::branches`]), the trachea first.
    pub branches: Vec<usize>,
    /// The target, world mm.
    pub target_mm: DVec3,
    /// The scope's diameter, mm.
    pub scope_diameter_mm: f64,
    /// The straight-line distance from the route's end to the target, mm.
    pub remaining_mm: f64,
    /// The narrowest lumen diameter along the route, mm (infinite when only the scan's border
    /// limits it).
    pub narrowest_mm: f64,
}

impl AirwayRoute {
    /// The route's end, world mm.
    pub fn end_mm(&self) -> DVec3 {
        self.points_mm[self.points_mm.len() - 1]
    }
}

/// Why there is no route to a target.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum RouteError {
    /// A number is NaN or infinite, a point outside the scan.
    #[error(transparent)]
    Bad(#[from] NavError),
    /// The target lies in the air around the body.
    #[error("the target {point_mm:?} (mm) lies outside the body, in the air around it")]
    OutsideBody {
        /// The target, world mm.
        point_mm: [f64; 3],
    },
    /// The scope does not fit into the trachea.
    #[error(
        "a {scope_mm} mm scope does not fit the trachea ({trachea_mm:.1} mm wide at the top of the \
         scan): give a smaller scope diameter"
    )]
    TooWide {
        /// The scope's diameter, mm.
        scope_mm: f64,
        /// The lumen's diameter at the trachea's top, mm.
        trachea_mm: f64,
    },
}

impl AirwayTree {
    /// The route for a scope of `scope_diameter_mm` (finite, positive) to `target_mm` (world mm,
    /// inside the scan and the body): down the tree from the trachea's top as long as the lumen
    /// is at least as wide as the scope, ending at the centreline point so reached nearest the
    /// target. A thinner scope reaches every point a thicker one does, so its route ends as
    /// near or nearer.
    pub fn route(
        &self,
        volume: &Volume,
        target_mm: DVec3,
        scope_diameter_mm: f64,
    ) -> Result<AirwayRoute, RouteError> {
        let scope = check_finite("scope diameter (mm)", scope_diameter_mm, true)?;
        for c in target_mm.to_array() {
            check_finite("target coordinate (mm)", c, false)?;
        }
        let v = volume
            .geometry()
            .voxel_from_world()
            .transform_point3(target_mm);
        let dims = volume.dims();
        if (0..3).any(|a| !(-0.5..dims[a] as f64 - 0.5).contains(&v[a])) {
            return Err(NavError::PointOutside {
                point_mm: target_mm.to_array(),
            }
            .into());
        }
        if outside_body(volume, target_mm, self.threshold) {
            return Err(RouteError::OutsideBody {
                point_mm: target_mm.to_array(),
            });
        }
        let reach = self.reach(scope);
        let trachea = &self.branches[0].diameters_mm;
        // Stopped before the trachea's first point the wall (not the scan's top) limits.
        if reach[0] < trachea.len() && trachea[..reach[0]].iter().all(|d| d.is_infinite()) {
            return Err(RouteError::TooWide {
                scope_mm: scope,
                trachea_mm: trachea[reach[0]],
            });
        }
        let (b, i) = self.nearest_reached(&reach, target_mm);
        Ok(self.route_to(b, i, target_mm, scope))
    }

    /// How many leading points of each branch a scope of `scope_mm` reaches: all the points
    /// from the trachea's top on that are at least as wide, in a branch whose parent it passes
    /// through whole.
    fn reach(&self, scope_mm: f64) -> Vec<usize> {
        let mut reach = vec![0; self.branches.len()];
        for (b, branch) in self.branches.iter().enumerate() {
            let open = branch
                .parent
                .is_none_or(|p| reach[p] == self.branches[p].points_mm.len());
            if open {
                reach[b] = branch
                    .diameters_mm
                    .iter()
                    .take_while(|&&d| d >= scope_mm)
                    .count();
            }
        }
        reach
    }

    /// The reached point nearest `target_mm`: branch and index.
    fn nearest_reached(&self, reach: &[usize], target_mm: DVec3) -> (usize, usize) {
        let mut best = (f64::INFINITY, 0, 0);
        for (b, branch) in self.branches.iter().enumerate() {
            for (i, p) in branch.points_mm[..reach[b]].iter().enumerate() {
                let d = p.distance(target_mm);
                if d < best.0 {
                    best = (d, b, i);
                }
            }
        }
        (best.1, best.2)
    }

    /// The route down to point `i` of branch `b`.
    fn route_to(&self, b: usize, i: usize, target_mm: DVec3, scope: f64) -> AirwayRoute {
        let branches = self.lineage(b);
        let mut points_mm = Vec::new();
        let mut narrowest_mm = f64::INFINITY;
        for &a in &branches {
            let branch = &self.branches[a];
            let last = if a == b {
                i
            } else {
                branch.points_mm.len() - 1
            };
            // A branch's first point is the branch point its parent ends at.
            let first = usize::from(branch.parent.is_some());
            for n in first..=last {
                points_mm.push(branch.points_mm[n]);
                narrowest_mm = narrowest_mm.min(branch.diameters_mm[n]);
            }
        }
        if points_mm.is_empty() {
            points_mm.push(self.branches[b].points_mm[i]);
        }
        let end = points_mm[points_mm.len() - 1];
        AirwayRoute {
            remaining_mm: end.distance(target_mm),
            points_mm,
            branches,
            target_mm,
            scope_diameter_mm: scope,
            narrowest_mm,
        }
    }
}
