//! [`PolicyAction`]: the `policy` leaf's controller — a model called every period, its set
//! points reached linearly over the period (or its full command held over it), until the
//! leaf's condition holds.

use std::collections::VecDeque;
use std::path::Path;
use std::sync::Arc;

use ort::session::Session;

use super::features::Feature;
use super::layout::{ActionLayout, ModelAction};
use super::metadata::ActionMode;
use super::model::PolicyModel;
use crate::actions::cell::Cell;
use crate::actions::macro_action::{MacroAction, Progress};
use crate::actions::targets::object_index;
use crate::failure::{Failure, FailureKind};
use crate::kinds::{LeafCall, POLICY_OUTPUT_INVALID, Policy};
use crate::motion::{ArmCommand, COMMAND_LEN, CTRL_LIMITS, CellCommand, CommandLimits, JOINT_LIMITS};
use crate::world::World;
use crate::world::vectors::VALUES_PER_OBJECT;

/// Answers a condition leaf in a world (`None`: not a condition kind): how the leaf checks its
/// `until:` with the factory's own checks.
pub type ConditionCheck = Arc<dyn Fn(&LeafCall, &World) -> Option<Result<bool, Failure>> + Send + Sync>;

/// The `policy` leaf's controller.
pub struct PolicyAction {
    params: Policy,
    until: Option<LeafCall>,
    check: ConditionCheck,
    run: Option<Run>,
}

/// How the arm moves over the current model period.
#[derive(Debug, Clone, Copy)]
enum Segment {
    /// Linearly from one set point to another, radians (a [`ActionLayout::Setpoint`] action).
    Linear { from: [f64; 6], to: [f64; 6] },
    /// The full command given at the segment's start, held over it as
    /// [`ArmCommand::at`] says (a [`ActionLayout::Command`] action).
    Held(ArmCommand),
}

/// A started run: the model, its session, and the segment under way.
struct Run {
    model: Arc<PolicyModel>,
    session: Option<Session>,
    object: Option<usize>,
    /// Control periods per model period.
    periods: u32,
    /// Control periods of the current segment done.
    done: u32,
    queue: VecDeque<ModelAction>,
    segment: Segment,
    calls: u64,
}

impl PolicyAction {
    /// A controller for `params`, checking its `until:` with `check`.
    pub fn new(params: Policy, check: ConditionCheck) -> Self {
        let until = params.until.as_ref().map(|u| u.call());
        Self {
            params,
            until,
            check,
            run: None,
        }
    }

    fn invalid(message: String) -> Failure {
        Failure::new(FailureKind::Custom(POLICY_OUTPUT_INVALID), message)
    }

    /// Calls the model when its chunk is used up, takes the next action and starts moving to it.
    fn next_segment(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        let Some(run) = self.run.as_mut() else {
            return Err(Failure::other("the policy was not started"));
        };
        if run.queue.is_empty() {
            let world = cell.world();
            let gripper_joint = cell.sim().gripper_joint();
            let mut inputs = Vec::with_capacity(run.model.info.inputs.len());
            for input in &run.model.info.inputs {
                let mut values = Vec::with_capacity(input.len);
                input
                    .feature
                    .fill(world, gripper_joint, run.object, &mut values)
                    .map_err(Failure::other)?;
                inputs.push(values);
            }
            let session = run
                .session
                .as_mut()
                .ok_or_else(|| Failure::other("the policy's session was given back"))?;
            let actions = run.model.run(session, inputs).map_err(Failure::other)?;
            run.calls += 1;
            let n = match self.params.n_action_steps {
                Some(n) if n as usize > actions.len() => {
                    return Err(Failure::other(format!(
                        "n_action_steps is {n}, but the model returned a chunk of {} actions",
                        actions.len()
                    )));
                }
                Some(n) => n as usize,
                None => actions.len(),
            };
            run.queue.extend(actions.into_iter().take(n));
        }
        let a = run
            .queue
            .pop_front()
            .ok_or_else(|| Failure::other("the model returned no action"))?;
        if let Some(i) = a.iter().position(|v| !v.is_finite()) {
            return Err(Self::invalid(format!(
                "the model's action[{i}] is {}; every value must be finite",
                a[i]
            )));
        }
        let from = cell.arm_setpoint();
        let period = f64::from(run.periods) * cell.control_period();
        let mut q = [0.0; 6];
        for (i, q) in q.iter_mut().enumerate() {
            *q = match run.model.info.mode {
                ActionMode::Absolute => f64::from(a[i]),
                ActionMode::Relative => from[i] + f64::from(a[i]),
            };
            let (lo, hi) = JOINT_LIMITS[i];
            if !(lo..=hi).contains(q) {
                return Err(Self::invalid(format!(
                    "the model asks joint {} ({}) for {q:.3} rad, outside its limits {lo:.3} … {hi:.3}",
                    i,
                    crate::motion::ARM_JOINTS[i]
                )));
            }
        }
        let limits = CommandLimits {
            max_joint_speed: self.params.max_joint_speed,
            ..CTRL_LIMITS
        };
        let mut command = CellCommand {
            arm: ArmCommand::hold(q),
            gripper: f64::from(a[COMMAND_LEN - 1]),
        };
        if run.model.info.layout == ActionLayout::Command {
            for i in 0..6 {
                command.arm.qd[i] = f64::from(a[6 + i]);
                command.arm.qdd[i] = f64::from(a[12 + i]);
            }
        }
        let command = limits.clamp(command, &from, period).command;
        cell.set_gripper(command.gripper);
        run.done = 0;
        run.segment = match run.model.info.layout {
            ActionLayout::Setpoint => Segment::Linear {
                from,
                to: command.arm.q,
            },
            ActionLayout::Command => Segment::Held(command.arm),
        };
        Self::command(run, cell);
        Ok(())
    }

    /// Commands the coming control period: along a linear segment, at its speed, or the held
    /// command as far into its period as the segment is.
    fn command(run: &Run, cell: &mut Cell) {
        let (from, to) = match run.segment {
            Segment::Linear { from, to } => (from, to),
            Segment::Held(c) => {
                cell.command_arm(c.at(f64::from(run.done) * cell.control_period()));
                return;
            }
        };
        let period = f64::from(run.periods) * cell.control_period();
        let s = f64::from(run.done) / f64::from(run.periods);
        let mut c = ArmCommand::hold(from);
        for i in 0..6 {
            let d = to[i] - from[i];
            c.q[i] = from[i] + d * s;
            c.qd[i] = d / period;
        }
        cell.command_arm(c);
    }

    fn give_back(&mut self) {
        if let Some(run) = self.run.as_mut()
            && let Some(s) = run.session.take()
        {
            run.model.give_back(s);
        }
    }
}

impl Drop for PolicyAction {
    fn drop(&mut self) {
        self.give_back();
    }
}

impl MacroAction for PolicyAction {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        let model = PolicyModel::load(Path::new(&self.params.model)).map_err(Failure::other)?;
        let world = cell.world();
        for input in &model.info.inputs {
            if input.feature == Feature::EnvironmentState
                && input.len != world.objects.len() * VALUES_PER_OBJECT
            {
                return Err(Failure::other(format!(
                    "the model's `{}` takes {} values; the scene has {} objects ({} values)",
                    input.name,
                    input.len,
                    world.objects.len(),
                    world.objects.len() * VALUES_PER_OBJECT
                )));
            }
        }
        let object = self
            .params
            .object
            .as_ref()
            .map(|o| object_index(o, world))
            .transpose()?;
        let control = cell.control_period();
        let period = self.params.period.or(model.info.period).unwrap_or(control);
        let periods = (period / control).round();
        if periods < 1.0 || (periods * control - period).abs() > 1e-9 * period.max(1.0) {
            return Err(Failure::other(format!(
                "the policy's period {period} s is not a whole number of control periods ({control} s)"
            )));
        }
        let session = model.session().map_err(Failure::other)?;
        let from = cell.arm_setpoint();
        self.run = Some(Run {
            model,
            session: Some(session),
            object,
            periods: periods as u32,
            done: 0,
            queue: VecDeque::new(),
            segment: Segment::Linear { from, to: from },
            calls: 0,
        });
        self.next_segment(cell)
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        if let Some(until) = &self.until {
            match (self.check)(until, cell.world()) {
                Some(Ok(true)) => {
                    self.give_back();
                    return Progress::Done;
                }
                Some(Ok(false)) => {}
                Some(Err(e)) => return Progress::Failed(e),
                None => {
                    return Progress::Failed(Failure::other(format!(
                        "`{}` is not a condition",
                        until.kind()
                    )));
                }
            }
        }
        let Some(run) = self.run.as_mut() else {
            return Progress::Failed(Failure::other("the policy was not started"));
        };
        run.done += 1;
        if run.done >= run.periods {
            if let Err(e) = self.next_segment(cell) {
                cell.hold();
                self.give_back();
                return Progress::Failed(e);
            }
        } else {
            Self::command(run, cell);
        }
        Progress::Running
    }

    fn halt(&mut self, cell: &mut Cell) {
        cell.hold();
        self.give_back();
    }

    fn waiting_for(&self, _cell: &Cell) -> String {
        let calls = self.run.as_ref().map_or(0, |r| r.calls);
        match &self.until {
            Some(u) => format!("`{}` to hold after {calls} model calls", u.label()),
            None => format!("a halt (no `until:`) after {calls} model calls"),
        }
    }
}
