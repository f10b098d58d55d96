//! A push: an external force (and torque) on the cube body through MuJoCo's `xfrc_applied`,
//! held for a few physics steps, then cleared.

use nalgebra::Vector3;

use crate::sim::{Sim, TIMESTEP};
use crate::world::CUBE_HALF;

/// A force on the cube's centre of mass (world frame, N) and a torque (N·m), for `steps`
/// physics steps.
#[derive(Debug, Clone)]
pub(super) struct Push {
    force: Vector3<f64>,
    torque: Vector3<f64>,
    steps_left: u32,
    active: bool,
}

impl Push {
    /// A push of `force` and `torque` lasting `steps` physics steps.
    pub fn new(force: Vector3<f64>, torque: Vector3<f64>, steps: u32) -> Self {
        Self {
            force,
            torque,
            steps_left: steps,
            active: false,
        }
    }

    /// A horizontal push meant to slide the cube about `distance` metres along the table in
    /// direction `angle` (radians from world +x): the impulse that gives the cube the speed
    /// friction stops within `distance`, delivered over `steps` steps plus the friction it
    /// overcomes meanwhile. The force's line of action is lowered below the centre of mass (a
    /// torque is added) by just enough to cancel the tipping moment of the table's friction, so
    /// the cube slides without tipping either way while it is pushed.
    pub fn slide(sim: &Sim, angle: f64, distance: f64, steps: u32) -> Self {
        let model = &sim.scene().model;
        let ids = &sim.scene().ids;
        let mass = model.body_mass()[ids.cube_body];
        let mu = model.geom_friction()[ids.cube_geom][0];
        let g = 9.81;
        let duration = steps as f64 * TIMESTEP;
        let speed = (2.0 * mu * g * distance).sqrt();
        let magnitude = mass * speed / duration + mu * mass * g;
        let dir = Vector3::new(angle.cos(), angle.sin(), 0.0);
        let force = dir * magnitude;
        // Friction μ·m·g acts at the bottom face, CUBE_HALF below the centre: the push's moment
        // about the centre must match it.
        let arm = Vector3::new(0.0, 0.0, -mu * mass * g * CUBE_HALF / magnitude);
        Self::new(force, arm.cross(&force), steps)
    }

    /// Writes the force for the coming step, or clears it once the push is over.
    /// Returns true while the push lasts.
    pub fn apply(&mut self, sim: &mut Sim) -> bool {
        let body = sim.scene().ids.cube_body;
        let xfrc = &mut sim.data_mut().xfrc_applied_mut()[body];
        if self.steps_left > 0 {
            let f = self.force;
            let t = self.torque;
            *xfrc = [f.x, f.y, f.z, t.x, t.y, t.z];
            self.steps_left -= 1;
            self.active = true;
            true
        } else {
            if self.active {
                *xfrc = [0.0; 6];
                self.active = false;
            }
            false
        }
    }

    /// The force, N.
    pub fn force(&self) -> Vector3<f64> {
        self.force
    }
}

/// The cube's centre, world frame, metres (read from its free joint).
pub(super) fn cube_pos(sim: &Sim) -> Vector3<f64> {
    let c = sim.scene().ids.cube_qpos;
    let q = sim.data().qpos();
    Vector3::new(q[c], q[c + 1], q[c + 2])
}
