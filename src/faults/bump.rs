//! `bump`: while the arm makes its first approach (the first `reach`), the table is bumped and
//! the cube slides 3–6 cm, in a seeded direction within 60° of straight away from the bowl (in a
//! scene without a bowl, away from the robot's base). The approach was planned for where the cube
//! was; the tree must look again before it grasps. A scene without a cube (see
//! [`World::cube`]) is not bumped.

use rand_chacha::ChaCha8Rng;

use super::push::{Push, block_pos};
use super::{Fault, uniform};
use crate::kinds::ActionRole;
use crate::sim::Sim;
use crate::world::World;

/// Range of the intended slide, metres.
const DISTANCE: [f64; 2] = [0.03, 0.06];
/// Range of the delay after the first reach starts, seconds.
const DELAY: [f64; 2] = [0.1, 0.5];
/// Largest angle between the push and the bowl-to-cube direction, radians.
const SPREAD: f64 = std::f64::consts::FRAC_PI_3;
/// Length of the push, physics steps (2 ms each).
const STEPS: u32 = 10;

enum State {
    Idle,
    /// The first reach started; the bump comes at `at` (simulated seconds) and pushes `block`
    /// (the cube) toward `away` (radians about world z, away from the bowl).
    Armed {
        at: Option<f64>,
        away: f64,
        block: usize,
    },
    Pushing(Push),
    Done,
}

/// The `bump` fault.
pub struct Bump {
    delay: f64,
    spread: f64,
    distance: f64,
    state: State,
}

impl Bump {
    /// A bump with its delay, direction and distance drawn from `rng`.
    pub fn new(rng: &mut ChaCha8Rng) -> Self {
        Self {
            delay: uniform(rng, DELAY[0], DELAY[1]),
            spread: uniform(rng, -SPREAD, SPREAD),
            distance: uniform(rng, DISTANCE[0], DISTANCE[1]),
            state: State::Idle,
        }
    }
}

impl Fault for Bump {
    fn on_action_start(&mut self, role: ActionRole, world: &World) {
        if role == ActionRole::Reach && matches!(self.state, State::Idle) {
            let Some(block) = world.cube() else {
                self.state = State::Done;
                return;
            };
            let cube = world.objects[block].pos;
            let from = world
                .bowl()
                .map_or(nalgebra::Vector3::zeros(), |b| world.objects[b].pos);
            let away = cube - from;
            self.state = State::Armed {
                at: None,
                away: away.y.atan2(away.x),
                block,
            };
        }
    }

    fn before_step(&mut self, sim: &mut Sim) -> Option<String> {
        match &mut self.state {
            State::Idle | State::Done => None,
            State::Armed { at, away, block } => {
                let at = *at.get_or_insert(sim.time() + self.delay);
                if sim.time() < at {
                    return None;
                }
                let angle = *away + self.spread;
                let block = *block;
                let mut push = Push::slide(sim, block, angle, self.distance, STEPS);
                push.apply(sim);
                let c = block_pos(sim, block);
                let detail = format!(
                    "a bump pushes the cube at ({:.3}, {:.3}) m {:.1} N toward {:.0}° (about {:.0} mm) during the approach",
                    c.x,
                    c.y,
                    push.force().norm(),
                    angle.to_degrees(),
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
