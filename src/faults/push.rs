//! A push: an external force (and torque) on the cube body through MuJoCo's `xfrc_applied`,
//! held for a few physics steps, then cleared.

use nalgebra::Vector3;

use crate::scene::Shape;
use crate::sim::{Sim, TIMESTEP};

/// A force on a block's centre of mass (world frame, N) and a torque (N·m), for `steps`
/// physics steps.
#[derive(Debug, Clone)]
pub(super) struct Push {
    /// The block pushed (index into the scene's objects).
    block: usize,
    force: Vector3<f64>,
    torque: Vector3<f64>,
    steps_left: u32,
    active: bool,
}

impl Push {
    /// A push of `force` and `torque` on block `block` lasting `steps` physics steps.
    pub fn new(block: usize, force: Vector3<f64>, torque: Vector3<f64>, steps: u32) -> Self {
        Self {
            block,
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
    pub fn slide(sim: &Sim, block: usize, angle: f64, distance: f64, steps: u32) -> Self {
        let model = &sim.scene().model;
        let ids = &sim.scene().objects[block];
        let mass = model.body_mass()[ids.body];
        let mu = model.geom_friction()[ids.geoms[0]][0];
        let half = match sim.scene().spec.objects[block].shape {
            Shape::Block { half, .. } => half,
            _ => 0.0,
        };
        let g = 9.81;
        let duration = steps as f64 * TIMESTEP;
        let speed = (2.0 * mu * g * distance).sqrt();
        let magnitude = mass * speed / duration + mu * mass * g;
        let dir = Vector3::new(angle.cos(), angle.sin(), 0.0);
        let force = dir * magnitude;
        // Friction μ·m·g acts at the bottom face, half an edge below the centre: the push's
        // moment about the centre must match it.
        let arm = Vector3::new(0.0, 0.0, -mu * mass * g * half / magnitude);
        Self::new(block, force, arm.cross(&force), steps)
    }

    /// Writes the force for the coming step, or clears it once the push is over.
    /// Returns true while the push lasts.
    pub fn apply(&mut self, sim: &mut Sim) -> bool {
        let body = sim.scene().objects[self.block].body;
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

/// Block `block`'s centre, world frame, metres (read from its free joint).
pub(super) fn block_pos(sim: &Sim, block: usize) -> Vector3<f64> {
    let c = sim.scene().objects[block].qpos.unwrap_or_default();
    let q = sim.data().qpos();
    Vector3::new(q[c], q[c + 1], q[c + 2])
}
