//! `late_bowl`: during the first carry the bowl (a mocap body, like a tray on a conveyor) slides
//! 3–6 cm in a seeded direction, smoothly over a quarter of a second. A carry planned for the
//! old place lowers the cube beside the target, possibly onto the rim; the tree must check where
//! the cube ended up and, if it is not in the bowl, pick it up again and carry it to the new place.

use rand_chacha::ChaCha8Rng;

use super::{Fault, uniform};
use crate::kinds::ActionRole;
use crate::sim::Sim;
use crate::world::World;

/// Range of the shift, metres.
const DISTANCE: [f64; 2] = [0.03, 0.06];
/// Range of the delay after the first carry starts, seconds.
const DELAY: [f64; 2] = [0.1, 0.4];
/// Time the slide takes, seconds.
const DURATION: f64 = 0.25;

enum State {
    Idle,
    /// The first carry started; the bowl starts moving at `at`.
    Armed {
        at: Option<f64>,
    },
    /// Moving from `from` since `t0`.
    Moving {
        t0: f64,
        from: [f64; 3],
    },
    Done,
}

/// The `late_bowl` fault.
pub struct LateBowl {
    delay: f64,
    angle: f64,
    distance: f64,
    state: State,
}

impl LateBowl {
    /// A shift with its delay, direction and distance drawn from `rng`.
    pub fn new(rng: &mut ChaCha8Rng) -> Self {
        Self {
            delay: uniform(rng, DELAY[0], DELAY[1]),
            angle: uniform(rng, -std::f64::consts::PI, std::f64::consts::PI),
            distance: uniform(rng, DISTANCE[0], DISTANCE[1]),
            state: State::Idle,
        }
    }
}

impl Fault for LateBowl {
    fn on_action_start(&mut self, role: ActionRole, _world: &World) {
        if role == ActionRole::Carry && matches!(self.state, State::Idle) {
            self.state = State::Armed { at: None };
        }
    }

    fn before_step(&mut self, sim: &mut Sim) -> Option<String> {
        // A scene without a container has no bowl to move.
        let scene = sim.scene();
        let mocap = scene.spec.legacy_bowl().and_then(|b| scene.objects[b].mocap)?;
        match &mut self.state {
            State::Idle | State::Done => None,
            State::Armed { at } => {
                let at = *at.get_or_insert(sim.time() + self.delay);
                if sim.time() < at {
                    return None;
                }
                let from = sim.data().mocap_pos()[mocap];
                self.state = State::Moving { t0: sim.time(), from };
                Some(format!(
                    "the bowl at ({:.3}, {:.3}) m slides {:.0} mm toward {:.0}° during the carry",
                    from[0],
                    from[1],
                    self.distance * 1e3,
                    self.angle.to_degrees()
                ))
            }
            State::Moving { t0, from } => {
                let s = ((sim.time() - *t0) / DURATION).clamp(0.0, 1.0);
                // Smooth start and stop (minimum-jerk profile).
                let p = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
                let d = self.distance * p;
                let to = [
                    from[0] + d * self.angle.cos(),
                    from[1] + d * self.angle.sin(),
                    from[2],
                ];
                sim.data_mut().mocap_pos_mut()[mocap] = to;
                if s >= 1.0 {
                    self.state = State::Done;
                }
                None
            }
        }
    }
}
