//! `slip`: during the first carry, shortly after the cube is lifted, the grasp fails: the
//! gripper's squeeze drops for a moment (its drive relaxes to a few millimetres wider than the
//! cube, as on a pressure or power glitch) while a small jolt pushes the cube down and sideways.
//! The cube slides out of the pads and falls to the table near where it was lifted; the carry's
//! grasp check fails and the tree must pick the cube up again where it now lies.
//!
//! Why not a push alone: with the unmodified 2F-85 closed at full command, the pads' friction
//! holds a 50 g cube against more than 100 N for 50 ms (measured), so only a hammer blow would
//! knock it out — that is not how grasps fail. Both parts act through MuJoCo: the gripper
//! actuator's command for those steps, and `xfrc_applied` on the cube.

use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;

use super::push::cube_pos;
use super::{Fault, uniform};
use crate::motion::gripper::ctrl_for_width;
use crate::sim::Sim;
use crate::world::conditions::Tolerances;
use crate::world::{CUBE_HALF, World};

/// How far the pads relax beyond the cube's width, metres.
const RELAX: f64 = 0.008;
/// How long the grip stays relaxed, seconds.
const WINDOW: f64 = 0.15;
/// Downward part of the jolt, N (the cube weighs 0.49 N).
const DOWN_FORCE: f64 = 1.5;
/// Sideways part of the jolt, N.
const SIDE_FORCE: f64 = 0.5;
/// Range of the delay after the cube is lifted, seconds.
const DELAY: [f64; 2] = [0.0, 0.15];

enum State {
    /// Waiting for the first carry.
    Idle,
    /// The first carry started; waiting for the cube to be lifted.
    Armed,
    /// Lifted; the slip starts at `at` (simulated seconds).
    Lifted { at: f64 },
    /// The grip is relaxed and the jolt acts until `until`.
    Slipping { until: f64, force: Vector3<f64> },
    /// Fired (once per episode).
    Done,
}

/// The `slip` fault.
pub struct Slip {
    delay: f64,
    side_angle: f64,
    state: State,
}

impl Slip {
    /// A slip with its delay and sideways direction drawn from `rng`.
    pub fn new(rng: &mut ChaCha8Rng) -> Self {
        Self {
            delay: uniform(rng, DELAY[0], DELAY[1]),
            side_angle: uniform(rng, -std::f64::consts::PI, std::f64::consts::PI),
            state: State::Idle,
        }
    }
}

impl Fault for Slip {
    fn on_action_start(&mut self, kind: &str, _world: &World) {
        if kind == "carry" && matches!(self.state, State::Idle) {
            self.state = State::Armed;
        }
    }

    fn before_step(&mut self, sim: &mut Sim) -> Option<String> {
        let body = sim.scene().ids.cube_body;
        let mut fired = None;
        if let State::Armed = self.state
            && cube_pos(sim).z - CUBE_HALF >= Tolerances::LIFT_HEIGHT
        {
            self.state = State::Lifted {
                at: sim.time() + self.delay,
            };
        }
        if let State::Lifted { at } = self.state
            && sim.time() >= at
        {
            let side = Vector3::new(self.side_angle.cos(), self.side_angle.sin(), 0.0) * SIDE_FORCE;
            let force = side - Vector3::z() * DOWN_FORCE;
            let c = cube_pos(sim);
            fired = Some(format!(
                "the grip relaxes for {:.0} ms and a {:.1} N jolt pushes the cube at ({:.3}, {:.3}, {:.3}) m out of the pads",
                WINDOW * 1e3,
                force.norm(),
                c.x,
                c.y,
                c.z
            ));
            self.state = State::Slipping {
                until: sim.time() + WINDOW,
                force,
            };
        }
        if let State::Slipping { until, force } = self.state {
            if sim.time() < until {
                sim.data_mut().xfrc_applied_mut()[body] = [force.x, force.y, force.z, 0.0, 0.0, 0.0];
                sim.set_gripper_ctrl(ctrl_for_width(2.0 * CUBE_HALF + RELAX));
            } else {
                sim.data_mut().xfrc_applied_mut()[body] = [0.0; 6];
                self.state = State::Done;
            }
        }
        fired
    }
}
