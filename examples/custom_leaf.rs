//! Your own nodes in Rust: a `push` action and the `near` and `upright` conditions, registered
//! next to the built-in ones and used from YAML.
//!
//! ```text
//! cargo run --release --example custom_leaf                 # run the demo tree on physics, print the report
//! cargo run --release --example custom_leaf -- nodes push   # the macrotree CLI, with `push` and `near` in it
//! cargo run --release --example custom_leaf -- run my_tree.yaml --goal tree --json
//! ```
//!
//! `push` slides a block along the table: it closes the gripper, comes down behind the block
//! at low height and moves the fingers along the push direction until the block has moved
//! `distance`, then backs off and rises. `near` checks where a block's centre is; `upright`
//! reads a block's orientation and its contacts. See `docs/custom_nodes.md` for the walk-through.

use std::process::ExitCode;

use macrotree::actions::{Cell, MacroAction, Progress, object_index};
use macrotree::episode::{EpisodeConfig, Goal};
use macrotree::kinds::{ObjectRef, ObjectRole};
use macrotree::motion::{
    CLOSED_CTRL, CartesianMove, JointMove, MotionLimits, Trajectory, down_pose, ik_down,
};
use macrotree::world::Part;
use macrotree::world::World;
use macrotree::yaml::units::Angle;
use macrotree::{App, Error, Failure, FailureKind, ParamError, Params};
use nalgebra::Vector3;
use schemars::JsonSchema;
use serde::{Deserialize, Deserializer, Serialize};

/// The documentation of `push`, in the format of `docs/nodes/*.md`: `macrotree nodes push`
/// prints it, with the parameters and their units from [`Push`]'s doc comments.
const PUSH_DOC: &str = "Slide a block along the table by a given distance.

Closes the gripper, comes down behind the block (seen from the push direction) with the
fingertips low over the table, and moves the closed fingers along `direction` until the block's
centre has moved `distance`; then backs off 3 cm and rises. Fails when the block is not pushed
that far before the motion ends (missed or blocked): failure kind `short_push`.

Halt: the arm holds where it is.

```yaml
push: {object: cube, direction: deg(-90), distance: 0.1}
```
";

/// The documentation of `near`.
const NEAR_DOC: &str = "The block's centre is within `tolerance` of a point on the table.

Measured in the table plane; the block need not be at rest.

Halt: nothing to halt (instantaneous).

```yaml
near: {object: cube, point: [0.45, -0.28], tolerance: 0.015}
```
";

/// The documentation of `upright`.
const UPRIGHT_DOC: &str =
    "The block rests on a face, tilted at most `max_tilt`, and nothing holds or leans on it.

Reads the block's orientation (the tilt of its most vertical axis from world z) and the cell's
contacts: no pad and no other object touches it (the table does not count).

Halt: nothing to halt (instantaneous).

```yaml
upright: {object: cube, max_tilt: deg(5)}
```
";

/// Shortest push, metres.
const MIN_PUSH: f64 = 0.01;
/// Longest push, metres.
const MAX_PUSH: f64 = 0.25;

/// Parameters of `push`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct Push {
    /// The block to push (a name or `{var}`).
    object: ObjectRef,
    /// Direction of the push in the table plane, radians from the +x axis (or `deg(..)`).
    direction: Angle,
    /// How far the block's centre moves, metres (0.01 … 0.25).
    #[serde(deserialize_with = "push_distance")]
    #[schemars(range(min = MIN_PUSH, max = MAX_PUSH))]
    distance: f64,
    /// Tool speed while pushing, m/s (> 0). Default 0.1.
    #[serde(default = "default_speed", deserialize_with = "macrotree::yaml::units::speed")]
    #[schemars(range(min = 0.0))]
    speed: f64,
    /// Give up after this many simulated seconds (> 0). Default 10.
    #[serde(
        default = "default_timeout",
        deserialize_with = "macrotree::yaml::units::time_limit"
    )]
    #[schemars(range(min = 0.0))]
    timeout: f64,
}

fn default_speed() -> f64 {
    0.1
}

fn default_timeout() -> f64 {
    10.0
}

/// A distance in metres between [`MIN_PUSH`] and [`MAX_PUSH`]: an error points at the value.
fn push_distance<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = macrotree::yaml::units::distance(d)?;
    if (MIN_PUSH..=MAX_PUSH).contains(&v) {
        Ok(v)
    } else {
        Err(serde::de::Error::custom(format!(
            "`distance` must be between {MIN_PUSH} and {MAX_PUSH} m, found {v}"
        )))
    }
}

impl Params for Push {
    /// `object:` must name a block of the scene (checked when the tree loads).
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }
    fn label(&self, _kind: &str) -> Option<String> {
        Some(format!(
            "push {} {:.0}° {} m",
            self.object,
            self.direction.0.to_degrees(),
            self.distance
        ))
    }
    fn timeout(&self) -> Option<f64> {
        Some(self.timeout)
    }
    /// `push`'s own failure kind, besides the built-in ones (`unreachable`, `timeout`, …).
    fn failure_kinds() -> &'static [&'static str] {
        &[SHORT_PUSH]
    }
}

/// The failure kind of a push that did not move the block far enough.
const SHORT_PUSH: &str = "short_push";

/// Parameters of `near`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct Near {
    /// The block (a name or `{var}`).
    object: ObjectRef,
    /// The point, `[x, y]` on the table, world metres.
    #[serde(deserialize_with = "macrotree::yaml::units::vec2")]
    point: [f64; 2],
    /// Largest horizontal distance of the block's centre from `point`, metres (≥ 0). Default 0.01.
    #[serde(
        default = "default_tolerance",
        deserialize_with = "macrotree::yaml::units::distance"
    )]
    #[schemars(range(min = 0.0))]
    tolerance: f64,
}

fn default_tolerance() -> f64 {
    0.01
}

impl Params for Near {
    /// `object:` must name a block of the scene (checked when the tree loads).
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }
}

/// Largest `max_tilt` of `upright`, degrees.
const MAX_TILT_DEG: f64 = 45.0;

/// Parameters of `upright`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
struct Upright {
    /// The block (a name or `{var}`).
    object: ObjectRef,
    /// Largest tilt of the block from resting flat, radians (or `deg(..)`), 0 … 45°. Default
    /// deg(10).
    #[serde(default = "ten_degrees")]
    max_tilt: Angle,
}

fn ten_degrees() -> Angle {
    Angle(10f64.to_radians())
}

impl Params for Upright {
    /// `object:` must name a block of the scene (checked when the tree loads).
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }
    /// A range the type cannot express, reported at the `max_tilt` value in the file.
    fn validate_fields(&self) -> Result<(), ParamError> {
        let deg = self.max_tilt.0.to_degrees();
        if (0.0..=MAX_TILT_DEG).contains(&deg) {
            Ok(())
        } else {
            Err(ParamError::at(
                "max_tilt",
                format!("must be between 0 and {MAX_TILT_DEG}°, found {deg:.1}°"),
            ))
        }
    }
}

/// `upright`: reads orientation (`objects[i].quat`) and contacts (the pads' flags and
/// `touches`).
fn upright(w: &World, p: &Upright) -> Result<bool, Failure> {
    let i = object_index(&p.object, w)?;
    let o = &w.objects[i];
    // The block's axis closest to world z, and its angle from it (a block may rest on any face).
    let r = o.quat.to_rotation_matrix();
    let up = (0..3).map(|k| r[(2, k)].abs()).fold(0.0, f64::max);
    let tilt = up.clamp(-1.0, 1.0).acos();
    let held = o.left_pad_contact || o.right_pad_contact;
    let touched = w.touches.iter().any(|&(a, b)| {
        let is_i = |p: Part| matches!(p, Part::Object { index, .. } if index == i);
        is_i(a) || is_i(b)
    });
    Ok(tilt <= p.max_tilt.0 && !held && !touched)
}

/// `near`: a pure function of the world snapshot and the parameters.
fn near(w: &World, p: &Near) -> Result<bool, Failure> {
    let i = object_index(&p.object, w)?;
    let c = w.objects[i].pos;
    Ok((c.x - p.point[0]).hypot(c.y - p.point[1]) <= p.tolerance)
}

/// Height of the pinch above the table while pushing, metres (the fingertips stay clear of it).
const PUSH_HEIGHT: f64 = 0.015;
/// Height of the approach above the table, metres.
const APPROACH_HEIGHT: f64 = 0.12;
/// Distance from the block's near face to the pinch where the push starts, metres.
const STANDOFF: f64 = 0.04;
/// Back-off after the push, metres.
const BACK_OFF: f64 = 0.03;

/// The phases of a push, in order.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Approach,
    Down,
    Push,
    Retreat,
}

/// Executes a [`Push`].
struct PushAction {
    params: Push,
    block: usize,
    start: Vector3<f64>,
    dir: Vector3<f64>,
    yaw: f64,
    phase: Phase,
    /// Block displacement along the push when the push motion stopped, metres.
    pushed: f64,
}

impl PushAction {
    fn new(params: Push) -> Self {
        Self {
            params,
            block: 0,
            start: Vector3::zeros(),
            dir: Vector3::x(),
            yaw: 0.0,
            phase: Phase::Approach,
            pushed: 0.0,
        }
    }

    fn limits(&self, speed: f64) -> MotionLimits {
        MotionLimits {
            tool_speed: speed,
            ..MotionLimits::default()
        }
    }

    /// A straight move of the pinch to `to`, fingers down at the push yaw.
    fn line_to(&self, cell: &Cell, to: Vector3<f64>, speed: f64) -> Result<Box<dyn Trajectory>, Failure> {
        CartesianMove::new(cell.arm_setpoint(), down_pose(&to, self.yaw), &self.limits(speed))
            .map(|m| Box::new(m) as Box<dyn Trajectory>)
            .map_err(|e| Failure::new(FailureKind::Unreachable, format!("unreachable: {e}")))
    }

    /// How far the block's centre has moved along the push, metres.
    fn moved(&self, w: &World) -> f64 {
        (w.objects[self.block].pos - self.start).dot(&self.dir)
    }
}

impl MacroAction for PushAction {
    fn start(&mut self, cell: &mut Cell) -> Result<(), Failure> {
        let w = cell.world();
        self.block = object_index(&self.params.object, w)?;
        self.start = w.objects[self.block].pos;
        let a = self.params.direction.0;
        self.dir = Vector3::new(a.cos(), a.sin(), 0.0);
        // The pads separate across the push, so the edges of both closed fingers push side by
        // side. (Pushing with one finger's back, the 2F-85's knuckle tips a 44 mm cube over.)
        self.yaw = a + std::f64::consts::FRAC_PI_2;
        let behind = self.start - self.dir * (w.half(self.block) + STANDOFF);
        let above = Vector3::new(behind.x, behind.y, APPROACH_HEIGHT);
        let from = cell.arm_setpoint();
        let goal = ik_down(&above, self.yaw, false, &from)
            .map_err(|e| Failure::new(FailureKind::Unreachable, format!("unreachable: {e}")))?;
        cell.set_gripper(CLOSED_CTRL);
        cell.track(Box::new(JointMove::new(from, goal, &self.limits(0.5))));
        self.phase = Phase::Approach;
        Ok(())
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        if self.phase == Phase::Push {
            self.pushed = self.moved(cell.world());
            if self.pushed >= self.params.distance {
                cell.hold();
            }
        }
        if !cell.arm_motion_finished() {
            return Progress::Running;
        }
        let w = cell.world();
        let next = match self.phase {
            Phase::Approach => {
                let mut down = w.pinch_pos;
                down.z = PUSH_HEIGHT;
                self.line_to(cell, down, 0.2).map(|t| (Phase::Down, t))
            }
            Phase::Down => {
                // Far enough for the fingers to reach the block and move it `distance`.
                let travel = STANDOFF + self.params.distance;
                let to = w.pinch_pos + self.dir * travel;
                self.line_to(cell, to, self.params.speed)
                    .map(|t| (Phase::Push, t))
            }
            Phase::Push => {
                if self.pushed < self.params.distance - 0.002 {
                    return Progress::Failed(Failure::new(
                        FailureKind::Custom(SHORT_PUSH),
                        format!(
                            "the block moved {:.1} mm of {:.1} mm (missed or blocked)",
                            self.pushed * 1e3,
                            self.params.distance * 1e3
                        ),
                    ));
                }
                let mut back = w.pinch_pos - self.dir * BACK_OFF;
                back.z = APPROACH_HEIGHT;
                self.line_to(cell, back, 0.3).map(|t| (Phase::Retreat, t))
            }
            Phase::Retreat => return Progress::Done,
        };
        match next {
            Ok((phase, trajectory)) => {
                cell.track(trajectory);
                self.phase = phase;
                Progress::Running
            }
            Err(e) => Progress::Failed(e),
        }
    }
}

/// The demo tree: push the cube 10 cm away from the bowl, check it got there, go home, check
/// the cube still stands flat and free.
const TREE: &str = "description: push the cube 10 cm along -y, check where it is, go home, check it stands
main:
  sequence:
    children:
      - push: {object: cube, direction: deg(-90), distance: 0.10}
      - near: {object: cube, point: [0.45, -0.28], tolerance: 0.01}
      - home: {}
      - upright: {object: cube}
";

/// The built-in node kinds plus `push`, `near` and `upright`.
fn app() -> Result<App, Error> {
    let mut app = App::new();
    app.register_action("push", PUSH_DOC, |p: &Push| Box::new(PushAction::new(p.clone())))?
        .register_condition("near", NEAR_DOC, near)?
        .register_condition("upright", UPRIGHT_DOC, upright)?;
    Ok(app)
}

fn main() -> ExitCode {
    let app = match app() {
        Ok(app) => app,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    // With arguments: the `macrotree` command line, knowing `push` and `near`.
    if std::env::args_os().len() > 1 {
        let mut app = app;
        app.cli_name("custom_leaf")
            .cli_about(
                "The macrotree command line with a `push` action and the `near` and `upright` conditions",
            )
            .cli_version(env!("CARGO_PKG_VERSION"));
        return app.run_cli();
    }
    // Without: run the demo tree on physics and print its report.
    let result = app.compile_str(TREE, "push_demo.yaml").and_then(|plan| {
        let config = EpisodeConfig {
            goal: Goal::Tree,
            ..EpisodeConfig::default()
        };
        app.run_episode(&plan, &config)
    });
    match result {
        Ok(report) => {
            let json = serde_json::to_string_pretty(&report).unwrap_or_default();
            println!("{json}");
            eprintln!(
                "push demo: {} ({} after {:.2} s simulated)",
                if report.outcome.success {
                    "success"
                } else {
                    "failure"
                },
                report
                    .outcome
                    .failure_reason
                    .as_deref()
                    .unwrap_or("the tree succeeded"),
                report.outcome.sim_time_s
            );
            if report.outcome.success {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
        Err(e) => {
            eprintln!("{e}");
            ExitCode::from(2)
        }
    }
}
