//! `nudge`: just as the gripper starts to close for the first time, the cube is pushed 2–4 cm
//! along the table in a seeded direction. Depending on the direction the fingers close on an
//! off-centre cube, or miss it and the grasp fails.

use rand_chacha::ChaCha8Rng;

use super::push::{Push, block_pos};
use super::{Fault, uniform};
use crate::kinds::ActionRole;
use crate::sim::Sim;
use crate::world::World;

/// Range of the intended slide, metres.
const DISTANCE: [f64; 2] = [0.02, 0.04];
/// Length of the push, physics steps (2 ms each).
const STEPS: u32 = 10;

enum State {
    Idle,
    /// The first grasp started: push on the next step.
    /// The first grasp started on block `block` (the block nearest the fingers).
    Armed {
        block: usize,
    },
    Pushing(Push),
    Done,
}

/// The `nudge` fault.
pub struct Nudge {
    angle: f64,
    distance: f64,
    state: State,
}

impl Nudge {
    /// A nudge with its direction and distance drawn from `rng`.
    pub fn new(rng: &mut ChaCha8Rng) -> Self {
        Self {
            angle: uniform(rng, -std::f64::consts::PI, std::f64::consts::PI),
            distance: uniform(rng, DISTANCE[0], DISTANCE[1]),
            state: State::Idle,
        }
    }
}

impl Fault for Nudge {
    fn on_action_start(&mut self, role: ActionRole, world: &World) {
        if role == ActionRole::Grasp && matches!(self.state, State::Idle) {
            // The block being grasped: the one nearest the pinch point.
            let nearest = world
                .scene
                .of_kind(crate::scene::ObjectKind::Block)
                .min_by(|&a, &b| {
                    let d = |i: usize| (world.objects[i].pos - world.pinch_pos).norm();
                    d(a).total_cmp(&d(b))
                });
            if let Some(block) = nearest {
                self.state = State::Armed { block };
            }
        }
    }

    fn before_step(&mut self, sim: &mut Sim) -> Option<String> {
        match &mut self.state {
            State::Idle | State::Done => None,
            State::Armed { block } => {
                let block = *block;
                let mut push = Push::slide(sim, block, self.angle, self.distance, STEPS);
                push.apply(sim);
                let c = block_pos(sim, block);
                let detail = format!(
                    "{} at ({:.3}, {:.3}) m is pushed {:.1} N toward {:.0}° (about {:.0} mm) as the gripper closes",
                    sim.scene().spec.objects[block].name,
                    c.x,
                    c.y,
                    push.force().norm(),
                    self.angle.to_degrees(),
                    self.distance * 1e3
                );
                self.state = State::Pushing(push);
                Some(detail)
            }
            State::Pushing(push) => {
                if !push.apply(sim) {
                    self.state = State::Done;
                }
                None
            }
        }
    }
}
