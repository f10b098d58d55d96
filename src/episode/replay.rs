//! Bare-physics replays: record every physics step's actuator commands while an episode runs,
//! then step a fresh simulation through them with nothing but `mj_step`. The ratio of the two
//! wall times is what everything that is not physics costs (`macrotree bench`, and the Python
//! benchmark of the step-wise environment).

use std::sync::{Arc, Mutex};
use std::time::Instant;

use crate::actions::StepObserver;
use crate::scene::Placement;
use crate::sim::{Scene, Sim};

/// The recorded commands: `nu` values per physics step, in step order.
pub type Controls = Arc<Mutex<Vec<f64>>>;

/// A [`StepObserver`] appending the actuator commands of every physics step to a [`Controls`].
pub struct ControlRecorder(Controls);

impl ControlRecorder {
    /// A recorder and the log it fills.
    pub fn new() -> (Self, Controls) {
        let log = Controls::default();
        (Self(log.clone()), log)
    }
}

impl StepObserver for ControlRecorder {
    fn before_step(&mut self, sim: &mut Sim) {
        self.0
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .extend_from_slice(sim.ctrl());
    }
}

/// Wall time of stepping a fresh simulation of `scene`, started at `placement`, through
/// `controls` (`nu` values per step), seconds, and the state it ends in
/// ([`Sim::state_fingerprint`]).
pub fn replay_controls(scene: &Scene, placement: &Placement, controls: &[f64]) -> (f64, Vec<u64>) {
    let mut sim = Sim::new(scene);
    sim.reset_placement(placement);
    let nu = sim.ctrl().len();
    let t = Instant::now();
    for ctrl in controls.chunks_exact(nu) {
        sim.set_ctrl(ctrl);
        sim.step();
    }
    let wall = t.elapsed().as_secs_f64();
    (wall, sim.state_fingerprint())
}
