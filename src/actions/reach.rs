//! `reach`: move the pinch to a pose above/at a target, tool pointing down.

use nalgebra::{Isometry3, Translation3, Vector3};

use super::cell::Cell;
use super::grasp_yaw::block_grasp_yaw;
use super::macro_action::{Arrival, MacroAction, Progress};
use super::plan_help::PlanFor;
use super::planning::{arm_link, check_motion, check_straight, describe, look_ahead_clear, plan_motion};
use super::targets::{resolve, segment_distance, target_block, target_object, tool_yaw};
use crate::failure::{Failure, FailureKind};
use crate::kinds::{PathKind, Reach as ReachSpec, Yaw};
use crate::motion::plan::GoalSet;
use crate::motion::{CartesianMove, JointMove, MotionLimits, Trajectory, down_pose, fk, ik_down};
use crate::world::World;

/// A failure of kind `unreachable` (IK or path planning found no way).
fn unreachable(message: String) -> Failure {
    Failure::new(FailureKind::Unreachable, message)
}

/// How far from an object's footprint the open fingers reach around the pinch, metres.
const FINGER_REACH: f64 = 0.05;
/// Height the fingertips keep above the top of anything they pass over, metres.
const PATH_CLEARANCE: f64 = 0.03;
/// Height above the highest object in the way at which a detour passes, metres.
const DETOUR_HEIGHT: f64 = 0.08;
/// Points checked along a joint-space path.
const PATH_SAMPLES: usize = 24;

/// Executes a [`ReachSpec`].
pub struct Reach {
    spec: ReachSpec,
    goal_q: [f64; 6],
    arrival: Arrival,
    /// Motions still to start, in order (a detour over an object: down after over).
    pending: Vec<Box<dyn Trajectory>>,
}

impl Reach {
    /// A reach controller for `spec`.
    pub fn new(spec: ReachSpec) -> Self {
        Self {
            spec,
            goal_q: [0.0; 6],
            arrival: Arrival::default(),
            pending: Vec::new(),
        }
    }
}

impl Reach {
    /// When this reach goes to an approach pose above its target object (`offset` up) and the
    /// straight descent to the object from `reached` would touch something, the goals of `goals`
    /// whose descent is free. `Ok(None)` when the descent from `reached` is free or the target is
    /// not an object; a failure of kind `blocked`, naming what the descent would touch, when no
    /// goal's descent is free (the pick could only run the arm into it).
    fn descent_free_goals(
        &self,
        cell: &mut Cell,
        goals: &GoalSet,
        reached: &[f64; 6],
        offset: Vector3<f64>,
    ) -> Result<Option<GoalSet>, Failure> {
        if offset.z <= 0.0 {
            return Ok(None);
        }
        let w = cell.world();
        let Some(target) = target_object(&self.spec.target, w) else {
            return Ok(None);
        };
        let name = w.name(target).to_string();
        let intended = vec![name.clone()];
        let limits = MotionLimits::default();
        let drop = Vector3::new(0.0, 0.0, offset.z);
        let descent = |q: &[f64; 6]| {
            let top = fk(q);
            let down = Isometry3::from_parts(Translation3::from(top.translation.vector - drop), top.rotation);
            CartesianMove::new(*q, down, &limits).ok()
        };
        let hits = |cell: &mut Cell, q: &[f64; 6]| match descent(q) {
            Some(mv) => look_ahead_clear(cell, &mv, &intended).is_some(),
            None => true,
        };
        if !hits(cell, reached) {
            return Ok(None);
        }
        let free: Vec<[f64; 6]> = goals.configs.iter().filter(|q| !hits(cell, q)).copied().collect();
        if !free.is_empty() {
            return Ok(Some(GoalSet::configs(free)));
        }
        let what = descent(reached)
            .and_then(|mv| look_ahead_clear(cell, &mv, &intended))
            .map_or_else(
                || "the arm's joint limits or a singularity".to_string(),
                |pairs| describe(&pairs),
            );
        Err(Failure::new(
            FailureKind::Blocked,
            format!(
                "the straight descent onto `{name}` would touch {what} from every arm configuration above it ({} checked); the pick cannot be made from above",
                goals.configs.len()
            ),
        ))
    }
}

impl Reach {
    /// Plans a motion to the pose (any IK branch, any equivalent grasp yaw) around whatever is
    /// in the way, to the branches whose straight descent is free when the reach is a pick's
    /// approach ([`Self::descent_free_goals`]), and starts it.
    fn plan(
        &mut self,
        cell: &mut Cell,
        from: &[f64; 6],
        position: &Vector3<f64>,
        yaw: f64,
        quarter: bool,
        offset: Vector3<f64>,
    ) -> Result<(), Failure> {
        let goals = GoalSet::down(position, yaw, quarter, from);
        let mut motion = plan_motion(cell, PlanFor::Reach, from, &goals, self.spec.plan_budget(), None)?;
        if let Some(free) = self.descent_free_goals(cell, &goals, &motion.trajectory.end(), offset)? {
            // The straight descent a pick runs next from the pose reached would touch
            // (the forearm on the table): plan again to the branches whose descent is free.
            tracing::debug!(target: "macrotree::actions", "reach: the descent from the planned pose would touch; planning to the {} goal(s) whose descent is free", free.configs.len());
            motion = plan_motion(cell, PlanFor::Reach, from, &free, self.spec.plan_budget(), None)?;
        }
        self.goal_q = motion.trajectory.end();
        cell.track(Box::new(motion.trajectory));
        Ok(())
    }
}

/// Motions run one after the other, and the configuration they end in.
type Legs = (Vec<Box<dyn Trajectory>>, [f64; 6]);

/// The legs of a detour from `from` (the pinch at `here`) to `position`: straight up to `z`
/// (metres), a joint move over to above `position`, straight down; and the configuration it
/// ends in. A failure of kind `unreachable` names the leg no straight line or IK solution makes.
fn detour(
    from: &[f64; 6],
    here: &Isometry3<f64>,
    z: f64,
    position: &Vector3<f64>,
    yaw: f64,
    quarter: bool,
    limits: &MotionLimits,
) -> Result<Legs, Failure> {
    let up = Isometry3::from_parts(
        Translation3::new(here.translation.x, here.translation.y, z),
        here.rotation,
    );
    let rise = CartesianMove::new(*from, up, limits)
        .map_err(|e| unreachable(format!("unreachable detour (up): {e}")))?;
    let over_at = Vector3::new(position.x, position.y, z);
    let over_q = ik_down(&over_at, yaw, quarter, &rise.end())
        .map_err(|e| unreachable(format!("unreachable detour (over): {e}")))?;
    let over = JointMove::new(rise.end(), over_q, limits);
    let down_pose = down_pose(position, yaw_of_solution(&over_q));
    let down = CartesianMove::new(over_q, down_pose, limits)
        .map_err(|e| unreachable(format!("unreachable detour (down): {e}")))?;
    let end = down.end();
    Ok((vec![Box::new(rise), Box::new(over), Box::new(down)], end))
}

/// The first object (other than `skip`) the pinch passes over lower than [`PATH_CLEARANCE`]
/// above its top on the joint-space line from `from` to `to`, with the pinch there.
/// Objects taller than [`super::carry::MAX_LIFT_OVER`] are not detoured over (the check of the
/// joint move sees them and the planner goes around).
fn joint_path_conflict(w: &World, from: &[f64; 6], to: &[f64; 6], skip: Option<usize>) -> Option<usize> {
    (1..PATH_SAMPLES).find_map(|k| {
        let t = k as f64 / PATH_SAMPLES as f64;
        let q: [f64; 6] = std::array::from_fn(|i| from[i] + t * (to[i] - from[i]));
        let p = fk(&q).translation.vector;
        (0..w.objects.len()).find(|&j| {
            Some(j) != skip
                && w.top(j) <= super::carry::MAX_LIFT_OVER
                && w.from_footprint(j, &p).norm() < FINGER_REACH
                && p.z < w.top(j) + PATH_CLEARANCE
        })
    })
}

/// Height at which a detour from `a` to `b` (table plane) clears every object near its line,
/// metres.
fn detour_height(w: &World, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    (0..w.objects.len())
        .filter(|&j| {
            segment_distance(w.objects[j].pos.xy(), a.xy(), b.xy())
                < w.spec(j).shape.footprint_radius() + FINGER_REACH
        })
        .map(|j| w.top(j) + DETOUR_HEIGHT)
        .fold(a.z.max(b.z), f64::max)
}

impl Reach {
    /// A joint-space `reach` from `from` (goal configuration `goal_q`, pinch at `position`):
    /// straight in joint space, or a detour over an object the pinch would pass low over, or
    /// planned around whatever is in the way; to the branches whose straight descent is free when
    /// the reach is a pick's approach.
    #[allow(clippy::too_many_arguments)]
    fn start_joint(
        &mut self,
        cell: &mut Cell,
        from: &[f64; 6],
        position: &Vector3<f64>,
        (yaw, quarter): (f64, bool),
        goal_q: [f64; 6],
        offset: Vector3<f64>,
        limits: &MotionLimits,
    ) -> Result<(), Failure> {
        let (from, position, limits) = (*from, *position, *limits);
        let w = cell.world();
        let skip = target_object(&self.spec.target, w);
        // Today's motion: straight in joint space, or up, over and down around an
        // object the pinch would pass low over.
        let (legs, goal_q): (Vec<Box<dyn Trajectory>>, [f64; 6]) = match joint_path_conflict(
            w, &from, &goal_q, skip,
        ) {
            None => (vec![Box::new(JointMove::new(from, goal_q, &limits))], goal_q),
            Some(j) => {
                // Up, over at a height that clears everything in the way, then down.
                let here = fk(&from);
                let z = detour_height(w, &here.translation.vector, &position);
                tracing::debug!(target: "macrotree::actions", "reach: the direct path passes low over {}; detour at {z:.3} m", w.name(j));
                match detour(&from, &here, z, &position, yaw, quarter, &limits) {
                    Ok(legs) => legs,
                    // Far out the straight rise can leave the workspace (the elbow
                    // straightens): the planner finds the way instead.
                    Err(e) => {
                        tracing::debug!(target: "macrotree::actions", "reach: {e}; planning");
                        return self.plan(cell, &from, &position, yaw, quarter, offset);
                    }
                }
            }
        };
        let refs: Vec<&dyn Trajectory> = legs.iter().map(|l| l.as_ref()).collect();
        if let Some((_, pairs)) = check_motion(cell, &refs, &[], false) {
            // The motion would collide: plan one to the same pose (any IK branch, any
            // equivalent grasp yaw) around whatever is in the way.
            tracing::debug!(target: "macrotree::actions", "reach: the {} would touch {}; planning", if legs.len() == 1 { "direct joint move" } else { "detour" }, describe(&pairs));
            return self.plan(cell, &from, &position, yaw, quarter, offset);
        }
        // The direct motion is free; the straight descent a pick runs next from where it
        // ends may not be (the forearm on a post beside the block): then plan to the
        // branches whose descent is free.
        let goals = GoalSet::down(&position, yaw, quarter, &from);
        if let Some(free) = self.descent_free_goals(cell, &goals, &goal_q, offset)? {
            tracing::debug!(target: "macrotree::actions", "reach: the descent from the direct move's end would touch; planning to the {} goal(s) whose descent is free", free.configs.len());
            let motion = plan_motion(cell, PlanFor::Reach, &from, &free, self.spec.plan_budget(), None)?;
            self.goal_q = motion.trajectory.end();
            cell.track(Box::new(motion.trajectory));
            return Ok(());
        }
        let mut legs = legs;
        self.goal_q = goal_q;
        let first = legs.remove(0);
        legs.reverse();
        self.pending = legs;
        cell.track(first);
        Ok(())
    }

    /// A pick's approach whose straight-down pre-grasps are all blocked (`why`): to a tilted
    /// pre-grasp ([`super::tilted`]) of the target block when its offset is straight up and one
    /// has a free configuration and descent; `why` otherwise.
    fn start_tilted(
        &mut self,
        cell: &mut Cell,
        from: &[f64; 6],
        grasp_yaw: (f64, bool),
        offset: Vector3<f64>,
        why: Failure,
    ) -> Result<(), Failure> {
        let w = cell.world();
        let Some(b) = target_block(&self.spec.target, w) else {
            return Err(why);
        };
        if offset.z <= 0.0 || offset.x != 0.0 || offset.y != 0.0 {
            return Err(why);
        }
        let centre = w.objects[b].pos;
        let name = w.name(b).to_string();
        tracing::debug!(target: "macrotree::actions", "reach: {why}; trying tilted pre-grasps");
        match super::tilted::plan(
            cell,
            from,
            &centre,
            grasp_yaw,
            offset.z,
            &name,
            self.spec.plan_budget(),
        ) {
            Ok(Some(motion)) => {
                self.goal_q = motion.trajectory.end();
                cell.track(Box::new(motion.trajectory));
                Ok(())
            }
            Ok(None) => Err(why),
            Err(e) => {
                tracing::debug!(target: "macrotree::actions", "reach: no path to a tilted pre-grasp: {e}");
                Err(why)
            }
        }
    }

    /// The straight final approach from `from` (radians) to the tool pose `pose`, checked along
    /// its length: only real contact counts and the target may be touched; refused
    /// ([`refuse_arm_contact`]) when it would run the arm's links into something else.
    fn straight_descent(
        &self,
        cell: &mut Cell,
        from: [f64; 6],
        pose: Isometry3<f64>,
        limits: &MotionLimits,
    ) -> Result<CartesianMove, Failure> {
        let mv = CartesianMove::new(from, pose, limits)
            .map_err(|e| unreachable(format!("unreachable path: {e}")))?;
        let intended: Vec<String> = {
            let w = cell.world();
            target_object(&self.spec.target, w)
                .map(|j| w.name(j).to_string())
                .into_iter()
                .collect()
        };
        refuse_arm_contact(check_straight(cell, "descent", &mv, &intended), &intended)?;
        Ok(mv)
    }
}

/// A straight descent onto an object (`intended` names it) that would run the arm's links
/// (`ur5e/…`, not the fingers) into something else (`touching`: the pairs [`check_straight`]
/// found) is refused with a failure of kind `blocked` before it moves (the world changed since
/// its approach was chosen: the block slid on); a retry approaches it again. Other contacts run
/// as before.
fn refuse_arm_contact(
    touching: Option<Vec<crate::motion::plan::Collision>>,
    intended: &[String],
) -> Result<(), Failure> {
    let Some(pairs) = touching else {
        return Ok(());
    };
    let arm: Vec<_> = pairs.into_iter().filter(arm_link).collect();
    if arm.is_empty() || intended.is_empty() {
        return Ok(());
    }
    Err(Failure::new(
        FailureKind::Blocked,
        format!(
            "the straight descent onto `{}` would run the arm into {}; not started",
            intended.join(", "),
            describe(&arm)
        ),
    ))
}

/// Failure kinds of a pick's approach that a tilted pre-grasp may avoid: every straight-down
/// descent blocked, every straight-down pre-grasp configuration in collision, or no path to them.
fn tilt_may_help(kind: FailureKind) -> bool {
    matches!(
        kind,
        FailureKind::Blocked | FailureKind::GoalInCollision | FailureKind::NoPath
    )
}

impl MacroAction for Reach {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        // `approach: side | auto`: docs/motion.md "Side grasps"; `top` goes on below.
        if let Some(goal_q) = super::side::start(cell, &self.spec)? {
            self.pending.clear();
            self.goal_q = goal_q;
            return Ok(());
        }
        let w = cell.world();
        let offset = Vector3::from(self.spec.offset);
        let position = resolve(&self.spec.target, w)? + offset;
        let current_yaw = tool_yaw(&w.pinch_rot);
        let (yaw, quarter) = match (&self.spec.yaw, &self.spec.target) {
            (Yaw::Object, t) => match target_block(t, w) {
                Some(b) => block_grasp_yaw(w, b),
                None => (current_yaw, false),
            },
            (Yaw::Keep, _) => (current_yaw, false),
            (Yaw::Angle(a), _) => (*a, false),
        };
        let from = cell.arm_setpoint();
        let limits = MotionLimits {
            tool_speed: self.spec.speed,
            ..MotionLimits::default()
        };
        if matches!(self.spec.path, PathKind::Cartesian)
            && let Some(rotation) = super::tilted::keeps_tilt(&from)
        {
            // A tilted pick's descent: along the tool axis, the tilt kept.
            let pose = Isometry3::from_parts(Translation3::from(position), rotation);
            let mv = self.straight_descent(cell, from, pose, &limits)?;
            self.pending.clear();
            self.goal_q = mv.end();
            cell.track(Box::new(mv));
            return Ok(());
        }
        let goal_q =
            ik_down(&position, yaw, quarter, &from).map_err(|e| unreachable(format!("unreachable: {e}")))?;
        self.pending.clear();
        match self.spec.path {
            PathKind::Joint => {
                match self.start_joint(cell, &from, &position, (yaw, quarter), goal_q, offset, &limits) {
                    Err(e) if tilt_may_help(e.kind) => {
                        self.start_tilted(cell, &from, (yaw, quarter), offset, e)
                    }
                    started => started,
                }
            }
            PathKind::Cartesian => {
                let pose = down_pose(&position, yaw_of_solution(&goal_q));
                let mv = self.straight_descent(cell, from, pose, &limits)?;
                cell.track(Box::new(mv));
                self.goal_q = goal_q;
                Ok(())
            }
        }
    }

    fn waiting_for(&self, cell: &Cell) -> String {
        let detour = if self.pending.is_empty() {
            String::new()
        } else {
            format!(" ({} more leg(s) of the detour to go)", self.pending.len())
        };
        format!("{}{detour}", self.arrival.waiting_for(cell, &self.goal_q))
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        if !self.pending.is_empty() {
            if cell.arm_motion_finished()
                && let Some(next) = self.pending.pop()
            {
                cell.track(next);
            }
            return Progress::Running;
        }
        self.arrival.progress(cell, &self.goal_q)
    }
}

/// The tool yaw that joint solution `q` gives, radians.
fn yaw_of_solution(q: &[f64; 6]) -> f64 {
    tool_yaw(crate::motion::fk(q).rotation.to_rotation_matrix().matrix())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::tests_support::resting;

    fn q_at(x: f64, y: f64, z: f64) -> [f64; 6] {
        ik_down(&Vector3::new(x, y, z), 0.0, false, &crate::motion::HOME_Q).expect("reachable")
    }

    #[test]
    fn a_joint_path_low_over_the_bowl_is_found_and_a_high_one_is_not() {
        // The bowl of the built-in scene stands at (0.45, 0.08), its rim 6 cm high.
        let w = resting();
        let low = joint_path_conflict(&w, &q_at(0.45, -0.06, 0.05), &q_at(0.45, 0.22, 0.05), None);
        assert_eq!(
            low,
            Some(1),
            "the pinch passes 5 cm above the table across the bowl"
        );
        let high = joint_path_conflict(&w, &q_at(0.45, -0.06, 0.25), &q_at(0.45, 0.22, 0.25), None);
        assert_eq!(high, None);
        // The target itself is not in the way of a reach to it.
        assert_eq!(
            joint_path_conflict(&w, &q_at(0.45, -0.06, 0.05), &q_at(0.45, 0.22, 0.05), Some(1)),
            None
        );
    }

    #[test]
    fn a_detour_passes_above_the_highest_object_near_its_line() {
        let w = resting();
        let z = detour_height(
            &w,
            &Vector3::new(0.45, -0.06, 0.05),
            &Vector3::new(0.45, 0.22, 0.05),
        );
        assert!((z - (0.06 + DETOUR_HEIGHT)).abs() < 1e-9, "{z}");
        // Nothing near a line far from both objects: the higher end decides.
        let z = detour_height(&w, &Vector3::new(0.2, 0.4, 0.05), &Vector3::new(0.3, 0.5, 0.10));
        assert_eq!(z, 0.10);
    }
}
