//! Side grasps for `reach` (`approach: side | auto`): the tool horizontal, approaching a block
//! along the normal of one of its four vertical faces, the pinch at the block's centre height and
//! the fingers closing across the two faces beside it.
//!
//! The faces are tried in a fixed order (the one facing the robot's base most first; ties by
//! face index), and the first whose pre-grasp configurations and straight approach are free
//! (the cell's collision checker: the pre-grasp with the planner's margin, the approach keeping
//! [`APPROACH_CLEARANCE`], the block itself intended) is taken; the arm then moves there directly
//! when that joint move is free, else by the planner to those pre-grasp configurations.
//!
//! `offset` is read in the approach frame of the face: z is the stand-off back out along the
//! face's normal, y is up (world z), x = y × z runs along the face. A Cartesian side reach (the
//! final approach, or pulling a held block out) keeps to the face the tool points at now.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::cell::Cell;
use super::plan_help::PlanFor;
use super::planning::{check_motion, check_straight, look_ahead_clear, plan_motion};
use crate::failure::{Failure, FailureKind};
use crate::kinds::PlanBudget;
use crate::motion::plan::GoalSet;
use crate::motion::{CartesianMove, JointMove, MotionLimits, Trajectory, fk};
use crate::world::World;

/// A tool axis counts as pointing down when its world z component is below this (about 45°).
pub(crate) const POINTS_DOWN: f64 = -0.7;

/// A failure of kind `unreachable`.
fn unreachable(message: String) -> Failure {
    Failure::new(FailureKind::Unreachable, message)
}

/// Outward unit normals of block `b`'s four vertical faces (world frame, horizontal): the face
/// turned most toward the robot's base (the world origin) first, ties by face index (the
/// block's yaw, then quarter turns counter-clockwise).
pub(crate) fn faces(w: &World, b: usize) -> Vec<Vector3<f64>> {
    let yaw = w.yaw(b);
    let p = w.objects[b].pos;
    let to_base = Vector3::new(-p.x, -p.y, 0.0);
    let to_base = if to_base.norm() > 1e-9 {
        to_base.normalize()
    } else {
        Vector3::x()
    };
    let mut normals: Vec<(f64, usize, Vector3<f64>)> = (0..4)
        .map(|k| {
            let a = yaw + k as f64 * std::f64::consts::FRAC_PI_2;
            let n = Vector3::new(a.cos(), a.sin(), 0.0);
            (n.dot(&to_base), k, n)
        })
        .collect();
    normals.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    normals.into_iter().map(|(_, _, n)| n).collect()
}

/// The approach frame of a face with outward normal `n` (columns: x along the face, y up, z out
/// along `n`).
pub(crate) fn approach_frame(n: &Vector3<f64>) -> Matrix3<f64> {
    let up = Vector3::z();
    Matrix3::from_columns(&[up.cross(n), up, *n])
}

/// The two tool orientations of a side grasp through the face with outward normal `n`: the
/// tool axis (pinch z) along −`n`, the fingers' closing axis (pinch y) horizontal along the face;
/// the second is the first turned half a turn about the tool axis (the two-finger gripper looks
/// the same).
pub(crate) fn rotations(n: &Vector3<f64>) -> [UnitQuaternion<f64>; 2] {
    let z = -n;
    let y = Vector3::new(-n.y, n.x, 0.0);
    let x = y.cross(&z);
    let r =
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
            x, y, z,
        ])));
    let half = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI);
    [r, r * half]
}

/// Where the pinch goes for a side reach at block `b` through the face with outward normal `n`,
/// `offset` in the approach frame ([`approach_frame`]), metres.
pub(crate) fn pinch_at(w: &World, b: usize, n: &Vector3<f64>, offset: &Vector3<f64>) -> Vector3<f64> {
    w.objects[b].pos + approach_frame(n) * offset
}

/// The block `b` as the intended contact of a side reach.
fn intended(w: &World, b: usize) -> Vec<String> {
    vec![w.name(b).to_string()]
}

/// Each of `configs` with the pairs that count there by the planner's margin (those touching at
/// `start` and contact with the `intended` objects allowed); none when the cell has no checker.
/// The checks are counted in the tally.
fn blocking(
    cell: &mut Cell,
    start: &[f64; 6],
    intended: &[String],
    configs: Vec<[f64; 6]>,
) -> Vec<([f64; 6], Vec<crate::motion::plan::Collision>)> {
    let Some(checker) = cell.checker() else {
        return configs.into_iter().map(|q| (q, Vec::new())).collect();
    };
    let mut allow = super::planning::Allowing::new(checker, start, intended, false);
    let out = configs
        .into_iter()
        .map(|q| {
            let pairs = allow.blocking(&q);
            (q, pairs)
        })
        .collect();
    let checks = allow.checks;
    cell.planning_mut().collision_checks += checks;
    out
}

/// The pre-grasp configurations (pinch at `pre`, tool along −`n`) whose configuration is free
/// (the planner's margin, the block intended) and whose straight approach to the grasp (pinch
/// at `grasp`) keeps [`APPROACH_CLEARANCE`] from everything but the block; nearest to `from`
/// first. With none, why (the counts, and the pairs of the pre-grasp nearest to free).
fn free_pregrasps(
    cell: &mut Cell,
    b: usize,
    n: &Vector3<f64>,
    pre: &Vector3<f64>,
    grasp: &Vector3<f64>,
    from: &[f64; 6],
) -> (Vec<[f64; 6]>, String) {
    let poses: Vec<Isometry3<f64>> = rotations(n)
        .iter()
        .map(|r| Isometry3::from_parts(Translation3::from(*pre), *r))
        .collect();
    let goals = GoalSet::poses(&poses, from);
    if goals.is_empty() {
        return (
            Vec::new(),
            goals.ik_failure.unwrap_or_else(|| "no IK solution".into()),
        );
    }
    let w = cell.world();
    let intended = intended(w, b);
    let start = cell.arm_setpoint();
    let limits = MotionLimits::default();
    let total = goals.configs.len();
    let mut free = Vec::new();
    // The pre-grasp that comes nearest to being free (its deepest pair the shallowest), and the
    // count of those whose straight approach is blocked.
    let mut nearest: Option<(f64, String)> = None;
    let mut approach_blocked = 0;
    for (q, blocked) in blocking(cell, &start, &intended, goals.configs) {
        if !blocked.is_empty() {
            let deepest = blocked.iter().map(|c| c.distance).fold(f64::INFINITY, f64::min);
            if nearest.as_ref().is_none_or(|(d, _)| deepest > *d) {
                nearest = Some((deepest, super::planning::describe(&blocked)));
            }
            continue;
        }
        let to = Isometry3::from_parts(Translation3::from(*grasp), fk(&q).rotation);
        let clear = match CartesianMove::new(q, to, &limits) {
            Ok(mv) => approach_is_clear(cell, &mv, &intended),
            Err(_) => false,
        };
        if !clear {
            approach_blocked += 1;
            continue;
        }
        free.push(q);
    }
    let mut why = Vec::new();
    if let Some((_, pairs)) = nearest {
        why.push(format!(
            "{} of {total} pre-grasp configurations touch something (the nearest to free: {pairs})",
            total - approach_blocked - free.len()
        ));
    }
    if approach_blocked > 0 {
        why.push(format!("{approach_blocked} of {total} have a straight approach that comes within {APPROACH_CLEARANCE} m of something"));
    }
    let why = why.join("; ");
    (free, why)
}

/// The top-down pre-grasp configurations of block `b` (the pinch `standoff` metres above its
/// centre, the tool yaw `reach` would take for it and the turns its symmetry allows, every IK
/// branch) that are free (the planner's margin, the block intended) and whose straight descent to
/// the centre passes the pick's look-ahead (`look_ahead_clear`: nothing but the block touched,
/// the arm's links kept the margin from everything); nearest to `from` first. Empty: the block
/// cannot be grasped from above.
pub(crate) fn top_free_goals(cell: &mut Cell, b: usize, standoff: f64, from: &[f64; 6]) -> Vec<[f64; 6]> {
    let w = cell.world();
    let centre = w.objects[b].pos;
    let pre = centre + Vector3::new(0.0, 0.0, standoff);
    let (yaw, quarter) = super::grasp_yaw::block_grasp_yaw(w, b);
    let goals = GoalSet::down(&pre, yaw, quarter, from);
    let intended = intended(w, b);
    let start = cell.arm_setpoint();
    let limits = MotionLimits::default();
    let mut out = Vec::new();
    for (q, blocked) in blocking(cell, &start, &intended, goals.configs) {
        if !blocked.is_empty() {
            continue;
        }
        if standoff > 1e-6 {
            let to = Isometry3::from_parts(Translation3::from(centre), fk(&q).rotation);
            match CartesianMove::new(q, to, &limits) {
                Ok(mv) if look_ahead_clear(cell, &mv, &intended).is_none() => {}
                _ => continue,
            }
        }
        out.push(q);
    }
    out
}

/// A side reach by a joint-space move (or a planned one) to the pre-grasp of the first face
/// whose pre-grasp and approach are free; the pre-grasp is `offset` (approach frame) from the
/// block's centre. Starts the motion on the cell and returns its end configuration.
///
/// # Errors
/// `unreachable` when no face has a free pre-grasp and approach (the message gives each face's
/// reason); the planner's failure when the move there must be planned and cannot be.
pub(crate) fn start_joint(
    cell: &mut Cell,
    b: usize,
    offset: &Vector3<f64>,
    limits: &MotionLimits,
    budget: PlanBudget,
) -> Result<[f64; 6], Failure> {
    let from = cell.arm_setpoint();
    let w = cell.world();
    let name = w.name(b).to_string();
    let normals = faces(w, b);
    let mut reasons = Vec::new();
    for n in normals {
        let w = cell.world();
        let pre = pinch_at(w, b, &n, offset);
        let grasp = pinch_at(w, b, &n, &Vector3::new(offset.x, offset.y, 0.0));
        let (free, why) = free_pregrasps(cell, b, &n, &pre, &grasp, &from);
        if free.is_empty() {
            reasons.push(format!("face ({:+.2}, {:+.2}): {why}", n.x, n.y));
            continue;
        }
        tracing::debug!(target: "macrotree::actions", "reach: side approach to {name} through the face ({:+.2}, {:+.2}); {} free pre-grasp configuration(s)", n.x, n.y, free.len());
        return go_to(cell, &from, free, limits, budget);
    }
    Err(unreachable(format!(
        "unreachable: no face of {name} can be approached from the side: {}",
        reasons.join("; ")
    )))
}

/// A side reach in a straight line: through the face the tool points at now (the one whose
/// approach is nearest the tool axis), the tool turned to the nearer of that face's two grasp
/// orientations, the pinch `offset` (approach frame) from the block's centre. Starts the motion
/// and returns its end configuration.
///
/// # Errors
/// `unreachable` when the straight line has no IK solution along it.
pub(crate) fn start_cartesian(
    cell: &mut Cell,
    b: usize,
    offset: &Vector3<f64>,
    limits: &MotionLimits,
) -> Result<[f64; 6], Failure> {
    let from = cell.arm_setpoint();
    let w = cell.world();
    let now = UnitQuaternion::from_matrix(&w.pinch_rot);
    let axis = now * Vector3::z();
    let n = faces(w, b)
        .into_iter()
        .enumerate()
        .max_by(|(i, a), (j, c)| (-a.dot(&axis)).total_cmp(&-c.dot(&axis)).then(j.cmp(i)))
        .map(|(_, n)| n)
        .expect("four faces");
    let rotation = rotations(&n)
        .into_iter()
        .min_by(|a, c| a.angle_to(&now).total_cmp(&c.angle_to(&now)))
        .expect("two rotations");
    let pose = Isometry3::from_parts(Translation3::from(pinch_at(w, b, &n, offset)), rotation);
    let mv = CartesianMove::new(from, pose, limits)
        .map_err(|e| unreachable(format!("unreachable side approach path: {e}")))?;
    let intended = intended(w, b);
    check_straight(cell, "side approach", &mv, &intended);
    let end = mv.end();
    cell.track(Box::new(mv));
    Ok(end)
}

/// Least gap the hand keeps from everything but the block along a side approach, metres: the
/// approach runs level just above a shelf board (the pads 9 mm, the spring links 0.5 mm above it
/// for a 4 cm block), so contact alone is too little to ask (the arm tracks its path within a
/// millimetre or two) and the planner's margin too much.
pub const APPROACH_CLEARANCE: f64 = 0.002;

/// Pinch travel between two configurations checked along a side approach, metres.
const APPROACH_STEP: f64 = 0.005;

/// True when nothing but the `intended` objects comes closer than [`APPROACH_CLEARANCE`] to
/// the arm, the hand or a held block along the straight move `mv` (pairs already that close at
/// its start excepted); the checks are counted in the tally.
fn approach_is_clear(cell: &mut Cell, mv: &CartesianMove, intended: &[String]) -> bool {
    let start = mv.sample(0.0).0;
    let length = (mv.end_pose().translation.vector - mv.start_pose().translation.vector).norm();
    let n = ((length / APPROACH_STEP).ceil() as usize).clamp(1, 400);
    let d = mv.duration();
    let Some(checker) = cell.checker() else {
        return true;
    };
    let mut allow = super::planning::Allowing::new(checker, &start, intended, false);
    let mut clear = true;
    for k in 1..=n {
        let q = if k == n {
            mv.end()
        } else {
            mv.sample(d * k as f64 / n as f64).0
        };
        if allow.blocking(&q).iter().any(|c| c.distance < APPROACH_CLEARANCE) {
            clear = false;
            break;
        }
    }
    let checks = allow.checks;
    cell.planning_mut().collision_checks += checks;
    clear
}

/// True when the tool axis of the current pose points down (a top grasp), so a Cartesian
/// `approach: auto` reach continues from above.
pub(crate) fn tool_points_down(w: &World) -> bool {
    (w.pinch_rot * Vector3::z()).z < POINTS_DOWN
}

/// Where a `reach` with `approach: side | auto` goes, when it is not the plain top-down reach.
enum Route {
    /// The plain top-down reach (`approach: top`, or a Cartesian `auto` reach whose tool points
    /// down).
    Top,
    /// From above, to these pre-grasp configurations (an `auto` reach: the top-down ones whose
    /// configuration and descent are free).
    Above(Vec<[f64; 6]>),
    /// From the side of this block.
    Side(usize),
}

/// Decides the [`Route`] of `spec` (see [`Route`]).
///
/// # Errors
/// `other` when `side` or `auto` names something that is not a block (a container, an obstacle).
fn route(cell: &mut Cell, spec: &crate::kinds::Reach) -> Result<Route, Failure> {
    use crate::kinds::{Approach, PathKind};
    if spec.approach == Approach::Top {
        return Ok(Route::Top);
    }
    let w = cell.world();
    let Some(b) = super::targets::target_block(&spec.target, w) else {
        let what = super::targets::target_object(&spec.target, w)
            .map_or_else(|| "its target".to_string(), |i| format!("`{}`", w.name(i)));
        return Err(Failure::other(format!(
            "`approach: {}` needs a block to approach, and {what} is not a block",
            spec.approach.name()
        )));
    };
    if spec.approach == Approach::Side {
        return Ok(Route::Side(b));
    }
    let name = w.name(b).to_string();
    match spec.path {
        PathKind::Cartesian if tool_points_down(w) => Ok(Route::Top),
        PathKind::Cartesian => Ok(Route::Side(b)),
        PathKind::Joint => {
            let from = cell.arm_setpoint();
            let free = top_free_goals(cell, b, spec.offset[2], &from);
            if free.is_empty() {
                tracing::debug!(target: "macrotree::actions", "reach: approach auto: no free top-down pre-grasp and descent for {name}: from the side");
                Ok(Route::Side(b))
            } else {
                tracing::debug!(target: "macrotree::actions", "reach: approach auto: {name} from above ({} free pre-grasp configuration(s))", free.len());
                Ok(Route::Above(free))
            }
        }
    }
}

/// Starts a `reach` with `approach: side | auto` on the cell and returns the configuration it
/// goes to; `None` for a plain top-down reach (`approach: top`, or a Cartesian `auto` reach
/// whose tool points down), which the caller runs as before.
///
/// # Errors
/// `other` for a target that is not a block; `unreachable` when no face can be approached; the
/// planner's failure when the move must be planned and cannot be.
pub(crate) fn start(cell: &mut Cell, spec: &crate::kinds::Reach) -> Result<Option<[f64; 6]>, Failure> {
    use crate::kinds::PathKind;
    let limits = MotionLimits {
        tool_speed: spec.speed,
        ..MotionLimits::default()
    };
    let offset = Vector3::from(spec.offset);
    match route(cell, spec)? {
        Route::Top => Ok(None),
        Route::Above(free) => {
            let from = cell.arm_setpoint();
            go_to(cell, &from, free, &limits, spec.plan_budget()).map(Some)
        }
        Route::Side(b) => match spec.path {
            PathKind::Joint => start_joint(cell, b, &offset, &limits, spec.plan_budget()).map(Some),
            PathKind::Cartesian => start_cartesian(cell, b, &offset, &limits).map(Some),
        },
    }
}

/// Moves the arm from `from` to the first of `goals` (nearest first) by a joint move when that
/// is free, else by the planner to any of them within the leaf's `budget`; returns the
/// configuration it goes to.
fn go_to(
    cell: &mut Cell,
    from: &[f64; 6],
    goals: Vec<[f64; 6]>,
    limits: &MotionLimits,
    budget: PlanBudget,
) -> Result<[f64; 6], Failure> {
    let direct = JointMove::new(*from, goals[0], limits);
    if check_motion(cell, &[&direct], &[], false).is_none() {
        cell.track(Box::new(direct));
        return Ok(goals[0]);
    }
    let motion = plan_motion(cell, PlanFor::Reach, from, &GoalSet::configs(goals), budget, None)?;
    let end = motion.trajectory.end();
    cell.track(Box::new(motion.trajectory));
    Ok(end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_side_grasp_points_the_tool_into_the_face_and_closes_along_it() {
        let n = Vector3::new(-1.0, 0.0, 0.0);
        for r in rotations(&n) {
            let z = r * Vector3::z();
            let y = r * Vector3::y();
            assert!((z - Vector3::x()).norm() < 1e-12, "tool axis {z}");
            assert!(
                y.z.abs() < 1e-12 && y.x.abs() < 1e-12,
                "closing axis {y} is horizontal along the face"
            );
        }
        let [a, b] = rotations(&n);
        assert!((a.angle_to(&b) - std::f64::consts::PI).abs() < 1e-9);
    }

    #[test]
    fn the_approach_frame_puts_the_stand_off_along_the_normal_and_y_up() {
        let n = Vector3::new(0.0, 1.0, 0.0);
        let f = approach_frame(&n);
        assert!((f * Vector3::new(0.0, 0.0, 0.1) - Vector3::new(0.0, 0.1, 0.0)).norm() < 1e-12);
        assert!((f * Vector3::new(0.0, 0.02, 0.0) - Vector3::new(0.0, 0.0, 0.02)).norm() < 1e-12);
        assert!((f.determinant() - 1.0).abs() < 1e-12, "right-handed");
    }
}
