//! Tilted top grasps: when no straight-down pre-grasp of a block has a free configuration and a
//! free straight descent (the wrist or the forearm on a tall post beside the block), the pick's
//! approach `reach` tilts the tool about its closing axis by a few tens of degrees, so the wrist
//! leans away from what is in the way while the pads still close flat on the same two vertical
//! faces. The pre-grasp then stands `offset.z` metres back along the tilted tool axis, and the
//! pick's Cartesian `descend` keeps the tilted orientation ([`keeps_tilt`]), moving along the tool
//! axis into the grasp.
//!
//! A descent (straight or tilted) looked ahead from a pre-grasp counts real contact with anything
//! but the block, and the arm's links (not the fingers, which straddle the block between its
//! neighbours) closer than the checker's clearance margin: a descent that only grazes a post in
//! the kinematic check touches it in physics, where the arm lags its setpoint.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::cell::Cell;
use super::plan_help::PlanFor;
use super::planning::{look_ahead_clear, plan_motion};
use crate::failure::Failure;
use crate::kinds::PlanBudget;
use crate::motion::plan::{GoalSet, PlannedMotion};
use crate::motion::{CartesianMove, MotionLimits, down_pose, fk};

/// Tilts of the tool from the vertical tried, smallest first, radians (15°, 25°, 35°: at 0.26 m
/// above the pinch the wrist moves 7, 11 and 15 cm sideways).
pub(crate) const TILTS: [f64; 3] = [
    15.0 * std::f64::consts::PI / 180.0,
    25.0 * std::f64::consts::PI / 180.0,
    35.0 * std::f64::consts::PI / 180.0,
];

/// A tool counts as tilted (its descent keeps the orientation) when its axis is more than this
/// far from straight down, radians (2°; the tilts of [`TILTS`] are far above it, a straight-down
/// tool tracked by the controller far below it).
const TILTED: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// The pre-grasp poses of a top grasp of the block centred at `centre` (metres): for each grasp
/// yaw of `yaw` (its half turn, and its quarter turns when `quarter`), the tool tilted by `tilt`
/// radians either way about its closing axis (pinch y), the pinch `standoff` metres back along the
/// tilted tool axis from the centre.
pub(crate) fn pregrasp_poses(
    centre: &Vector3<f64>,
    yaw: f64,
    quarter: bool,
    tilt: f64,
    standoff: f64,
) -> Vec<Isometry3<f64>> {
    let (step, n) = if quarter {
        (std::f64::consts::FRAC_PI_2, 4)
    } else {
        (std::f64::consts::PI, 2)
    };
    let mut out = Vec::with_capacity(2 * n);
    for k in 0..n {
        let down = down_pose(centre, yaw + k as f64 * step).rotation;
        for sign in [1.0, -1.0] {
            let r = down * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), sign * tilt);
            let p = centre - standoff * (r * Vector3::z());
            out.push(Isometry3::from_parts(Translation3::from(p), r));
        }
    }
    out
}

/// The straight descent from configuration `q`: `standoff` metres along the tool axis, the
/// orientation kept; `None` when no straight line gets there.
pub(crate) fn descent(q: &[f64; 6], standoff: f64) -> Option<CartesianMove> {
    let top = fk(q);
    let end = Isometry3::from_parts(
        Translation3::from(top.translation.vector + standoff * (top.rotation * Vector3::z())),
        top.rotation,
    );
    CartesianMove::new(*q, end, &MotionLimits::default()).ok()
}

/// True when the straight descent from `q` (`standoff` metres along the tool axis) is clear
/// ([`look_ahead_clear`], `target` intended).
pub(crate) fn descent_clear(cell: &mut Cell, q: &[f64; 6], standoff: f64, target: &str) -> bool {
    match descent(q, standoff) {
        Some(mv) => look_ahead_clear(cell, &mv, &[target.to_string()]).is_none(),
        None => false,
    }
}

/// Plans from `from` to a tilted pre-grasp of the block `target` centred at `centre` whose
/// configuration and descent are free, the smallest tilt of [`TILTS`] first; `Ok(None)` when no
/// tilt has one. Each plan stays within the leaf's `budget`.
///
/// # Errors
/// The planner's failure for the last tilt that had free pre-grasps but no path to them.
pub(crate) fn plan(
    cell: &mut Cell,
    from: &[f64; 6],
    centre: &Vector3<f64>,
    (yaw, quarter): (f64, bool),
    standoff: f64,
    target: &str,
    budget: PlanBudget,
) -> Result<Option<PlannedMotion>, Failure> {
    let mut last = None;
    for tilt in TILTS {
        let poses = pregrasp_poses(centre, yaw, quarter, tilt, standoff);
        let goals = GoalSet::poses(&poses, from);
        let free: Vec<[f64; 6]> = goals
            .configs
            .iter()
            .filter(|q| descent_clear(cell, q, standoff, target))
            .copied()
            .collect();
        tracing::debug!(target: "macrotree::actions", "reach: tilted by {:.0}°: {} of {} pre-grasp configuration(s) of `{target}` have a clear descent", tilt.to_degrees(), free.len(), goals.len());
        if free.is_empty() {
            continue;
        }
        match plan_motion(cell, PlanFor::Reach, from, &GoalSet::configs(free), budget, None) {
            Ok(m) => return Ok(Some(m)),
            Err(e) => last = Some(e),
        }
    }
    last.map_or(Ok(None), Err)
}

/// The orientation a Cartesian top reach from configuration `from` keeps: the current one when
/// the tool is tilted from straight down by more than [`TILTED`] but still points down (a tilted
/// pick's descent); `None` for a straight-down tool (the reach aims at a down pose as always).
pub(crate) fn keeps_tilt(from: &[f64; 6]) -> Option<UnitQuaternion<f64>> {
    let r = fk(from).rotation;
    let axis = r * Vector3::z();
    (axis.z < super::side::POINTS_DOWN && axis.z > -TILTED.cos()).then_some(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tilted_pregrasp_stands_back_along_its_tool_axis_with_the_pads_still_horizontal() {
        let centre = Vector3::new(0.45, -0.1, 0.02);
        let poses = pregrasp_poses(&centre, 0.3, false, TILTS[1], 0.12);
        assert_eq!(poses.len(), 4);
        for p in &poses {
            let z = p.rotation * Vector3::z();
            let y = p.rotation * Vector3::y();
            assert!(
                (z.z + TILTS[1].cos()).abs() < 1e-12,
                "tool axis {z} tilted by 25°"
            );
            assert!(y.z.abs() < 1e-12, "closing axis {y} stays horizontal");
            let back = centre - p.translation.vector;
            assert!((back.normalize() - z).norm() < 1e-12 && (back.norm() - 0.12).abs() < 1e-12);
        }
    }

    #[test]
    fn only_a_tilted_tool_keeps_its_tilt() {
        let at = |pose: &Isometry3<f64>| crate::motion::ik(pose, &crate::motion::HOME_Q).expect("reachable");
        let centre = Vector3::new(0.45, 0.1, 0.02);
        let tilted = pregrasp_poses(&centre, 0.0, false, TILTS[0], 0.12)[0];
        assert!(keeps_tilt(&at(&tilted)).is_some());
        let straight = down_pose(&Vector3::new(0.45, 0.1, 0.14), 0.0);
        assert!(keeps_tilt(&at(&straight)).is_none());
    }
}
