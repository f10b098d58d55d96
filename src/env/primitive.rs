//! [`Primitive`]: the reference tutorial's macro primitives (TorchRL's `RobotMacroAction`: wait,
//! reach joints, reach pose, open gripper, close gripper, reset), with its durations, run on the
//! cell as a controller.
//!
//! What differs from the reference, on purpose: motions start from the commanded set point
//! (not the measured, gravity-sagged joints) and the servos get the same velocity, inertia and
//! gravity feedforward as every leaf, so holding does not sag; joint and Cartesian moves follow macrotree's
//! minimum-jerk profiles ([`crate::motion`]) stretched to the requested duration instead of
//! linear ramps; the gripper command steps to its target instead of ramping.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

use crate::actions::{Arrival, Cell, MacroAction, Progress};
use crate::error::Error;
use crate::failure::{Failure, FailureKind};
use crate::kinds::PathKind;
use crate::motion::{
    CLOSED_CTRL, CartesianMove, JOINT_LIMITS, JointMove, MotionLimits, OPEN_CTRL, Trajectory, ctrl_for_width,
    fk, ik,
};

/// One low-level step of the reference environment, seconds (its `frame_skip` of 5 physics
/// steps of 2 ms): the unit of [`Duration::Steps`].
pub const REFERENCE_STEP: f64 = 0.01;

/// Most reference steps a macro's `steps` may take, and its `settle_steps` (each):
/// [`MAX_DURATION`] in [`REFERENCE_STEP`]s. The Python action space's bound is this one, so
/// every action the space holds is accepted.
pub const MAX_MACRO_STEPS: u32 = (MAX_DURATION / REFERENCE_STEP) as u32;

/// Longest duration of one primitive's motion, and of its settling, seconds (the env's default
/// episode limit).
pub const MAX_DURATION: f64 = 60.0;

/// Farthest a pose target may be from the robot's base, metres (the UR5e reaches about
/// 0.85 m plus the gripper).
pub const MAX_REACH_DISTANCE: f64 = 1.5;

/// How long an `Auto` motion may take beyond its planned duration to arrive, seconds.
const AUTO_SLACK: f64 = 5.0;
/// How long an `Auto` gripper motion may take to stop, seconds.
const AUTO_GRIPPER_LIMIT: f64 = 3.0;
/// Driver-joint speed below which the fingers count as stopped, rad/s.
const STALL_SPEED: f64 = 0.02;
/// Consecutive stopped ticks that end an `Auto` gripper motion.
const STALL_TICKS: u32 = 5;
/// Time the fingers get to start moving before a stop counts, seconds.
const MIN_GRIPPER_TIME: f64 = 0.1;

/// How long a primitive runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Duration {
    /// The motion takes exactly this long (seconds, more than 0, at most [`MAX_DURATION`]),
    /// and the step ends when it has.
    Seconds(f64),
    /// The reference's counts: the motion takes `steps` reference steps ([`REFERENCE_STEP`],
    /// 10 ms each), then the target is held for `settle` more (`steps + settle` ≥ 1).
    Steps {
        /// Reference steps the motion takes.
        steps: u32,
        /// Reference steps the target is then held.
        settle: u32,
    },
    /// macrotree's own: the motion at the planner's speed limits, then until the arm has
    /// arrived (within 2 mm, at rest) or the fingers have stopped; a failure (`blocked`,
    /// `timeout`) if it does not. Not for `Wait`.
    Auto,
    /// [`Duration::Auto`], then the target held for `settle` more reference steps
    /// ([`REFERENCE_STEP`] each; `settle` ≥ 1). Not for `Wait`.
    AutoThen {
        /// Reference steps the target is held after the arrival.
        settle: u32,
    },
}

/// One of the reference tutorial's macro primitives. Positions in metres (world frame),
/// angles in radians, quaternions `[w, x, y, z]`.
#[derive(Debug, Clone, PartialEq)]
pub enum Primitive {
    /// Hold the arm where it is commanded and the gripper's command.
    Wait {
        /// How long (not `Auto`).
        duration: Duration,
        /// The gripper command held meanwhile (0 open … 255 closed; `None`: keep it).
        gripper: Option<f64>,
    },
    /// Move the pinch point to `position` with orientation `quaternion`.
    ReachPose {
        /// Pinch position, metres (within [`MAX_REACH_DISTANCE`] of the base).
        position: [f64; 3],
        /// Pinch orientation `[w, x, y, z]` (normalised here; `None`: keep the current one).
        quaternion: Option<[f64; 4]>,
        /// Joint-space interpolation, or a straight line of the pinch.
        path: PathKind,
        /// How long.
        duration: Duration,
        /// The gripper command during the motion (0 open … 255 closed; `None`: keep it).
        gripper: Option<f64>,
    },
    /// Move the arm to joint angles (radians, within [`crate::motion::JOINT_LIMITS`]).
    ReachJoints {
        /// Target joint angles, radians.
        joints: [f64; 6],
        /// How long.
        duration: Duration,
        /// The gripper command during the motion (0 open … 255 closed; `None`: keep it).
        gripper: Option<f64>,
    },
    /// Open the gripper, fully (command 0) or to a command; the arm holds.
    OpenGripper {
        /// Actuator command to open to, 0 … 255 (`None`: 0, fully open).
        command: Option<f64>,
        /// How long.
        duration: Duration,
    },
    /// Close the gripper to a command or a width; the arm holds. Neither given: fully closed
    /// (255).
    CloseGripper {
        /// Actuator command, 0 … 255.
        command: Option<f64>,
        /// Pad-face opening to close to, metres (0 … 0.085), through the gripper calibration
        /// ([`crate::motion::ctrl_for_width`]).
        width: Option<f64>,
        /// How long.
        duration: Duration,
    },
    /// The arm back to home (joint move), gripper open.
    Reset {
        /// How long.
        duration: Duration,
    },
}

impl Primitive {
    /// The reference's name of the primitive (`wait`, `reach_pose`, …).
    pub fn name(&self) -> &'static str {
        match self {
            Primitive::Wait { .. } => "wait",
            Primitive::ReachPose { .. } => "reach_pose",
            Primitive::ReachJoints { .. } => "reach_joints",
            Primitive::OpenGripper { .. } => "open_gripper",
            Primitive::CloseGripper { .. } => "close_gripper",
            Primitive::Reset { .. } => "reset",
        }
    }

    fn duration(&self) -> Duration {
        match self {
            Primitive::Wait { duration, .. }
            | Primitive::ReachPose { duration, .. }
            | Primitive::ReachJoints { duration, .. }
            | Primitive::OpenGripper { duration, .. }
            | Primitive::CloseGripper { duration, .. }
            | Primitive::Reset { duration } => *duration,
        }
    }

    /// Every number is in range.
    ///
    /// # Errors
    /// [`Error::Action`] naming the value and the accepted range.
    pub fn check(&self) -> Result<(), Error> {
        let name = self.name();
        let bad = |message: String| Err(Error::Action { message });
        match self.duration() {
            Duration::Seconds(s) if !(s.is_finite() && s > 0.0 && s <= MAX_DURATION) => {
                return bad(format!(
                    "{name}: duration {s} s; expected more than 0 and at most {MAX_DURATION} s"
                ));
            }
            Duration::Steps { steps, settle }
                if steps == 0 && settle == 0 || steps > MAX_MACRO_STEPS || settle > MAX_MACRO_STEPS =>
            {
                return bad(format!(
                    "{name}: steps {steps}, settle {settle}; expected at least 1 in all, and each at most {MAX_MACRO_STEPS} reference steps of {REFERENCE_STEP} s"
                ));
            }
            Duration::Auto | Duration::AutoThen { .. } if matches!(self, Primitive::Wait { .. }) => {
                return bad("wait: needs a duration (Seconds or Steps), not Auto".to_string());
            }
            Duration::AutoThen { settle } if settle == 0 || settle > MAX_MACRO_STEPS => {
                return bad(format!(
                    "{name}: settle {settle}; expected at least 1 and at most {MAX_MACRO_STEPS} reference steps of {REFERENCE_STEP} s"
                ));
            }
            _ => {}
        }
        if let Primitive::Wait { gripper: Some(g), .. }
        | Primitive::ReachPose { gripper: Some(g), .. }
        | Primitive::ReachJoints { gripper: Some(g), .. } = self
            && !(g.is_finite() && (OPEN_CTRL..=CLOSED_CTRL).contains(g))
        {
            return bad(format!(
                "{name}: gripper command {g}; expected {OPEN_CTRL} (open) … {CLOSED_CTRL} (closed)"
            ));
        }
        match self {
            Primitive::ReachPose {
                position, quaternion, ..
            } => {
                if let Some(i) = position.iter().position(|v| !v.is_finite()) {
                    return bad(format!(
                        "reach_pose: position[{i}] is {}; expected metres",
                        position[i]
                    ));
                }
                let r = Vector3::from(*position).norm();
                if r > MAX_REACH_DISTANCE {
                    return bad(format!(
                        "reach_pose: position {position:?} is {r:.3} m from the robot's base; expected at most {MAX_REACH_DISTANCE} m"
                    ));
                }
                if let Some(q) = quaternion {
                    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
                    if !(n.is_finite() && n > 1e-6) {
                        return bad(format!(
                            "reach_pose: quaternion {q:?} (w, x, y, z) has norm {n}; expected a finite, non-zero quaternion"
                        ));
                    }
                }
            }
            Primitive::ReachJoints { joints, .. } => {
                for (i, (&v, (lo, hi))) in joints.iter().zip(JOINT_LIMITS).enumerate() {
                    if !(v.is_finite() && (lo..=hi).contains(&v)) {
                        return bad(format!(
                            "reach_joints: joints[{i}] ({}) is {v}; expected radians within {lo} … {hi}",
                            crate::motion::ARM_JOINTS[i]
                        ));
                    }
                }
            }
            Primitive::OpenGripper { command: Some(c), .. }
                if !(c.is_finite() && (OPEN_CTRL..=CLOSED_CTRL).contains(c)) =>
            {
                return bad(format!(
                    "open_gripper: command {c}; expected {OPEN_CTRL} (open) … {CLOSED_CTRL} (closed)"
                ));
            }
            Primitive::CloseGripper { command, width, .. } => match (command, width) {
                (Some(_), Some(_)) => {
                    return bad("close_gripper: give a command or a width, not both".to_string());
                }
                (Some(c), None) if !(c.is_finite() && (OPEN_CTRL..=CLOSED_CTRL).contains(c)) => {
                    return bad(format!(
                        "close_gripper: command {c}; expected {OPEN_CTRL} (open) … {CLOSED_CTRL} (closed)"
                    ));
                }
                (None, Some(w))
                    if !(w.is_finite() && (0.0..=crate::motion::width_for_ctrl(OPEN_CTRL)).contains(w)) =>
                {
                    return bad(format!(
                        "close_gripper: width {w} m; expected 0 … {} m (the pad opening)",
                        crate::motion::width_for_ctrl(OPEN_CTRL)
                    ));
                }
                _ => {}
            },
            _ => {}
        }
        Ok(())
    }
}

/// A trajectory stretched (or squeezed) in time to last `duration` seconds.
struct Retimed {
    inner: Box<dyn Trajectory>,
    duration: f64,
}

impl Trajectory for Retimed {
    fn sample(&self, t: f64) -> ([f64; 6], [f64; 6]) {
        let k = self.inner.duration() / self.duration;
        let (q, qd) = self.inner.sample(t * k);
        (q, qd.map(|v| v * k))
    }
    fn acceleration(&self, t: f64) -> [f64; 6] {
        let k = self.inner.duration() / self.duration;
        self.inner.acceleration(t * k).map(|a| a * k * k)
    }
    fn duration(&self) -> f64 {
        self.duration
    }
    fn end(&self) -> [f64; 6] {
        self.inner.end()
    }
    fn name(&self) -> &'static str {
        self.inner.name()
    }
}

/// When a running primitive ends.
enum Until {
    /// After this many control periods.
    Ticks(u64),
    /// When the arm has arrived at `goal` (or is blocked), at most `limit` ticks; then
    /// `settle` more ticks holding it.
    Arrived { goal: [f64; 6], limit: u64, settle: u64 },
    /// When the fingers have stopped, at most `limit` ticks.
    GripperStopped { limit: u64 },
}

/// A primitive running on the cell ([`MacroAction`]: planned on the first tick, checked on
/// every tick after).
pub(super) struct PrimitiveRun {
    primitive: Primitive,
    dt: f64,
    until: Until,
    ticks: u64,
    arrival: Arrival,
    stopped: u32,
}

impl PrimitiveRun {
    /// A run of `primitive` (already checked) on a cell ticked every `dt` seconds.
    pub fn new(primitive: Primitive, dt: f64) -> Self {
        Self {
            primitive,
            dt,
            until: Until::Ticks(1),
            ticks: 0,
            arrival: Arrival::default(),
            stopped: 0,
        }
    }

    /// Control periods covering `seconds` (at least one).
    fn ticks_for(&self, seconds: f64) -> u64 {
        ((seconds / self.dt - 1e-9).ceil() as u64).max(1)
    }

    /// Starts the arm along `mv` for the configured duration; sets when the run ends.
    fn start_motion(&mut self, cell: &mut Cell, mv: Box<dyn Trajectory>) {
        let goal = mv.end();
        match self.primitive.duration() {
            Duration::Seconds(s) => {
                self.until = Until::Ticks(self.ticks_for(s));
                cell.track(Box::new(Retimed {
                    inner: mv,
                    duration: s,
                }));
            }
            Duration::Steps { steps, settle } => {
                let total = f64::from(steps + settle) * REFERENCE_STEP;
                self.until = Until::Ticks(self.ticks_for(total));
                if steps == 0 {
                    cell.track(Box::new(crate::motion::Hold::new(goal, 0.0)));
                } else {
                    let duration = f64::from(steps) * REFERENCE_STEP;
                    cell.track(Box::new(Retimed { inner: mv, duration }));
                }
            }
            Duration::Auto | Duration::AutoThen { .. } => {
                let limit = self.ticks_for(mv.duration() + AUTO_SLACK);
                let settle = match self.primitive.duration() {
                    Duration::AutoThen { settle } => self.ticks_for(f64::from(settle) * REFERENCE_STEP),
                    _ => 0,
                };
                self.until = Until::Arrived { goal, limit, settle };
                cell.track(mv);
            }
        }
    }

    /// Commands the gripper to `ctrl` with the arm holding; sets when the run ends.
    fn start_gripper(&mut self, cell: &mut Cell, ctrl: f64) {
        if cell.arm_motion_finished() {
            cell.hold();
        }
        cell.set_gripper(ctrl);
        self.until = match self.primitive.duration() {
            Duration::Seconds(s) => Until::Ticks(self.ticks_for(s)),
            Duration::Steps { steps, settle } => {
                Until::Ticks(self.ticks_for(f64::from(steps + settle) * REFERENCE_STEP))
            }
            Duration::Auto | Duration::AutoThen { .. } => Until::GripperStopped {
                limit: self.ticks_for(AUTO_GRIPPER_LIMIT),
            },
        };
    }
}

fn unreachable(what: &str, e: impl std::fmt::Display) -> Failure {
    Failure::new(FailureKind::Unreachable, format!("unreachable: {what}: {e}"))
}

impl MacroAction for PrimitiveRun {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        let from = cell.arm_setpoint();
        let limits = MotionLimits::default();
        match self.primitive.clone() {
            Primitive::Wait { duration, gripper } => {
                if cell.arm_motion_finished() {
                    cell.hold();
                }
                if let Some(g) = gripper {
                    cell.set_gripper(g);
                }
                let seconds = match duration {
                    Duration::Seconds(s) => s,
                    Duration::Steps { steps, settle } => f64::from(steps + settle) * REFERENCE_STEP,
                    Duration::Auto | Duration::AutoThen { .. } => self.dt,
                };
                self.until = Until::Ticks(self.ticks_for(seconds));
            }
            Primitive::ReachPose {
                position,
                quaternion,
                path,
                gripper,
                ..
            } => {
                if let Some(g) = gripper {
                    cell.set_gripper(g);
                }
                let rotation = match quaternion {
                    Some([w, x, y, z]) => UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)),
                    None => fk(&from).rotation,
                };
                let pose = Isometry3::from_parts(Translation3::from(Vector3::from(position)), rotation);
                let mv: Box<dyn Trajectory> = match path {
                    PathKind::Joint => {
                        let goal =
                            ik(&pose, &from).map_err(|e| unreachable("no joint solution for the pose", e))?;
                        Box::new(JointMove::new(from, goal, &limits))
                    }
                    PathKind::Cartesian => Box::new(
                        CartesianMove::new(from, pose, &limits)
                            .map_err(|e| unreachable("no straight-line path to the pose", e))?,
                    ),
                };
                self.start_motion(cell, mv);
            }
            Primitive::ReachJoints { joints, gripper, .. } => {
                if let Some(g) = gripper {
                    cell.set_gripper(g);
                }
                self.start_motion(cell, Box::new(JointMove::new(from, joints, &limits)));
            }
            Primitive::OpenGripper { command, .. } => self.start_gripper(cell, command.unwrap_or(OPEN_CTRL)),
            Primitive::CloseGripper { command, width, .. } => {
                let ctrl = match (command, width) {
                    (Some(c), _) => c,
                    (None, Some(w)) => ctrl_for_width(w),
                    (None, None) => CLOSED_CTRL,
                };
                self.start_gripper(cell, ctrl);
            }
            Primitive::Reset { .. } => {
                cell.set_gripper(OPEN_CTRL);
                self.start_motion(cell, Box::new(JointMove::new(from, crate::sim::HOME_Q, &limits)));
            }
        }
        Ok(())
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        self.ticks += 1;
        match &self.until {
            Until::Ticks(n) => {
                if self.ticks >= *n {
                    Progress::Done
                } else {
                    Progress::Running
                }
            }
            Until::Arrived { goal, limit, settle } => {
                let (goal, limit, settle) = (*goal, *limit, *settle);
                match self.arrival.progress(cell, &goal) {
                    Progress::Done if settle > 0 => {
                        self.until = Until::Ticks(self.ticks + settle);
                        Progress::Running
                    }
                    Progress::Running if self.ticks >= limit => {
                        let waiting = self.arrival.waiting_for(cell, &goal);
                        cell.hold();
                        Progress::Failed(Failure::new(
                            FailureKind::Timeout,
                            format!("timeout after {:.2} s: {waiting}", self.ticks as f64 * self.dt),
                        ))
                    }
                    p => p,
                }
            }
            Until::GripperStopped { limit } => {
                let w = cell.world();
                if self.ticks as f64 * self.dt < MIN_GRIPPER_TIME {
                    return Progress::Running;
                }
                if w.gripper_speed.abs() < STALL_SPEED {
                    self.stopped += 1;
                } else {
                    self.stopped = 0;
                }
                if self.stopped >= STALL_TICKS {
                    Progress::Done
                } else if self.ticks >= *limit {
                    Progress::Failed(Failure::new(
                        FailureKind::Timeout,
                        format!(
                            "timeout after {AUTO_GRIPPER_LIMIT} s: gripper still moving, width {:.3} m",
                            w.gripper_width
                        ),
                    ))
                } else {
                    Progress::Running
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn secs(s: f64) -> Duration {
        Duration::Seconds(s)
    }

    #[test]
    fn bad_numbers_are_refused_with_the_value_and_the_range() {
        let cases = [
            (
                Primitive::Wait {
                    duration: secs(-1.0),
                    gripper: None,
                },
                "duration -1",
            ),
            (
                Primitive::Wait {
                    duration: secs(f64::NAN),
                    gripper: None,
                },
                "duration NaN",
            ),
            (
                Primitive::Wait {
                    duration: Duration::Auto,
                    gripper: None,
                },
                "not Auto",
            ),
            (
                Primitive::OpenGripper {
                    command: None,
                    duration: Duration::Steps { steps: 0, settle: 0 },
                },
                "at least 1",
            ),
            (
                Primitive::ReachPose {
                    position: [0.4, f64::INFINITY, 0.2],
                    quaternion: None,
                    path: PathKind::Joint,
                    duration: Duration::Auto,
                    gripper: None,
                },
                "position[1] is inf",
            ),
            (
                Primitive::ReachPose {
                    position: [0.4, 0.0, 0.2],
                    quaternion: Some([0.0; 4]),
                    path: PathKind::Joint,
                    duration: Duration::Auto,
                    gripper: None,
                },
                "norm 0",
            ),
            (
                Primitive::ReachPose {
                    position: [4.0, 0.0, 0.2],
                    quaternion: None,
                    path: PathKind::Joint,
                    duration: Duration::Auto,
                    gripper: None,
                },
                "from the robot's base",
            ),
            (
                Primitive::ReachJoints {
                    joints: [0.0, 0.0, 4.0, 0.0, 0.0, 0.0],
                    duration: Duration::Auto,
                    gripper: None,
                },
                "joints[2] (elbow) is 4",
            ),
            (
                Primitive::CloseGripper {
                    command: Some(300.0),
                    width: None,
                    duration: Duration::Auto,
                },
                "command 300",
            ),
            (
                Primitive::CloseGripper {
                    command: None,
                    width: Some(-0.01),
                    duration: Duration::Auto,
                },
                "width -0.01 m",
            ),
            (
                Primitive::CloseGripper {
                    command: Some(100.0),
                    width: Some(0.01),
                    duration: Duration::Auto,
                },
                "not both",
            ),
        ];
        for (p, expected) in cases {
            let e = p.check().unwrap_err();
            assert_eq!(e.kind(), "invalid_action");
            assert!(e.to_string().contains(expected), "{e} (expected `{expected}`)");
        }
        assert!(
            Primitive::Reset {
                duration: Duration::Auto
            }
            .check()
            .is_ok()
        );
    }

    #[test]
    fn a_retimed_trajectory_keeps_its_path_and_scales_its_speed() {
        let to = [-1.0, -1.2, 1.4, -1.5, -1.5, 0.3];
        let inner = JointMove::new(crate::sim::HOME_Q, to, &MotionLimits::default());
        let d = inner.duration();
        let (qh, vh) = inner.sample(d / 2.0);
        let slow = Retimed {
            inner: Box::new(inner),
            duration: 2.0 * d,
        };
        let (q, v) = slow.sample(d);
        assert_eq!(q, qh);
        for i in 0..6 {
            assert!((v[i] - vh[i] / 2.0).abs() < 1e-12);
        }
        assert_eq!(slow.end(), to);
        assert_eq!(slow.duration(), 2.0 * d);
    }
}
