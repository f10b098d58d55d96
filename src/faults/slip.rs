//! `slip`: during the first carry, while the cube is being lifted (at a seeded height 3–10 cm
//! above where it was grasped), the grasp fails: the gripper's squeeze drops for a moment (its
//! drive relaxes to a few millimetres wider than the cube, as on a pressure or power glitch)
//! while a short jolt pushes the cube down and a little sideways. The cube slides out of the pads
//! and falls to the table near where it was picked; the carry's grasp check fails and the tree
//! must pick the cube up again where it now lies.
//!
//! Why not a push alone: with the unmodified 2F-85 closed at full command, the pads' friction
//! holds a 50 g cube against more than 100 N for 50 ms (measured), so only a hammer blow would
//! knock it out — that is not how grasps fail. Both parts act through MuJoCo: the gripper
//! actuator's command for those steps, and `xfrc_applied` on the cube.

use nalgebra::Vector3;
use rand_chacha::ChaCha8Rng;

use super::push::block_pos;
use super::{Fault, uniform};
use crate::kinds::ActionRole;
use crate::motion::gripper::ctrl_for_width;
use crate::sim::Sim;
use crate::world::World;
use crate::world::conditions::Tolerances;

/// How far the pads relax beyond the cube's width, metres.
const RELAX: f64 = 0.008;
/// How long the grip stays relaxed, seconds.
const WINDOW: f64 = 0.15;
/// How long the jolt lasts, seconds.
const JOLT: f64 = 0.03;
/// Downward part of the jolt, N (the cube weighs 0.49 N).
const DOWN_FORCE: f64 = 1.5;
/// Sideways part of the jolt, N.
const SIDE_FORCE: f64 = 0.3;
/// Range of the height above the grasp at which the grasp fails, metres.
const HEIGHT: [f64; 2] = [0.03, 0.10];

enum State {
    /// Waiting for the first carry.
    Idle,
    /// The first carry started with block `block` (the one it carries) at height `from`;
    /// waiting for it to rise by `height`.
    Armed { block: usize, from: f64 },
    /// The grip is relaxed since `t0`, and the jolt acts on `block` for the first [`JOLT`]
    /// seconds.
    Slipping {
        block: usize,
        t0: f64,
        force: Vector3<f64>,
    },
    /// Fired (once per episode).
    Done,
}

/// The `slip` fault.
pub struct Slip {
    height: f64,
    side_angle: f64,
    state: State,
}

impl Slip {
    /// A slip with its height and sideways direction drawn from `rng`.
    pub fn new(rng: &mut ChaCha8Rng) -> Self {
        Self {
            height: uniform(rng, HEIGHT[0], HEIGHT[1]),
            side_angle: uniform(rng, -std::f64::consts::PI, std::f64::consts::PI),
            state: State::Idle,
        }
    }
}

impl Fault for Slip {
    fn on_action_start(&mut self, role: ActionRole, world: &World) {
        if role == ActionRole::Carry
            && matches!(self.state, State::Idle)
            && let Some(block) = world.held_block(Tolerances::GRASP_OFF_AXIS)
        {
            self.state = State::Armed {
                block,
                from: world.objects[block].pos.z,
            };
        }
    }

    fn before_step(&mut self, sim: &mut Sim) -> Option<String> {
        let mut fired = None;
        if let State::Armed { block, from } = self.state
            && block_pos(sim, block).z >= from + self.height
        {
            let side = Vector3::new(self.side_angle.cos(), self.side_angle.sin(), 0.0) * SIDE_FORCE;
            let force = side - Vector3::z() * DOWN_FORCE;
            let c = block_pos(sim, block);
            fired = Some(format!(
                "{:.0} mm up, the grip relaxes for {:.0} ms and a {:.1} N jolt pushes {} at ({:.3}, {:.3}, {:.3}) m out of the pads",
                self.height * 1e3,
                WINDOW * 1e3,
                force.norm(),
                sim.scene().spec.objects[block].name,
                c.x,
                c.y,
                c.z
            ));
            self.state = State::Slipping {
                block,
                t0: sim.time(),
                force,
            };
        }
        if let State::Slipping { block, t0, force } = self.state {
            let t = sim.time() - t0;
            let jolt = if t < JOLT { force } else { Vector3::zeros() };
            let body = sim.scene().objects[block].body;
            sim.data_mut().xfrc_applied_mut()[body] = [jolt.x, jolt.y, jolt.z, 0.0, 0.0, 0.0];
            let edge = match sim.scene().spec.objects[block].shape {
                crate::scene::Shape::Block { half, .. } => 2.0 * half,
                _ => 0.0,
            };
            if t < WINDOW {
                sim.set_gripper_ctrl(ctrl_for_width(edge + RELAX));
            } else {
                self.state = State::Done;
            }
        }
        fired
    }
}
