//! Noise injected into what the arm and gripper execute, while the command the cell records
//! (a dataset's `action`) stays the clean one: demonstrations that show corrections, not only the
//! perfect path (DART, Laskey et al. 2017).
//!
//! Every [`NOISE_HOLD_S`] of simulated time each joint's servo set point gets a fresh offset
//! drawn from N(0, σ²) (σ = [`ActionNoise::joint_sigma`]) and the gripper command one from
//! N(0, σ_g²); the offsets are held in between, so the arm really leaves its path and the
//! leaves' next commands lead it back. They act only while the arm is commanded to move (a
//! period whose command has a velocity): a leaf holding still to settle at its goal, or a grasp
//! closing on a block, is left alone, so every leaf can still finish. The draws come from the episode seed: the same seed gives
//! the same noise, bit for bit, for any number of workers.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use serde::Serialize;

use super::uniform;
use crate::actions::StepObserver;
use crate::motion::CellCommand;
use crate::sim::{Sim, TIMESTEP};

/// How long one draw of the offsets is held, seconds.
pub const NOISE_HOLD_S: f64 = 0.1;

/// Largest joint σ accepted, radians.
pub const MAX_JOINT_SIGMA: f64 = 0.2;

/// Largest gripper σ accepted, actuator units (of 0 … 255).
pub const MAX_GRIPPER_SIGMA: f64 = 100.0;

/// The noise of an episode's executed commands (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ActionNoise {
    /// Standard deviation of each joint's set-point offset, radians (0 … [`MAX_JOINT_SIGMA`]).
    pub joint_sigma: f64,
    /// Standard deviation of the gripper command's offset, actuator units
    /// (0 … [`MAX_GRIPPER_SIGMA`]).
    pub gripper_sigma: f64,
}

impl ActionNoise {
    /// Reads `JOINT_SIGMA[,GRIPPER_SIGMA]` (radians, actuator units; the gripper's default 0).
    pub fn parse(s: &str) -> Result<Self, String> {
        let shown: String = s.chars().take(40).collect();
        let mut parts = s.split(',');
        let mut next = |what: &str, max: f64| -> Result<Option<f64>, String> {
            let Some(p) = parts.next() else { return Ok(None) };
            match p.trim().parse::<f64>() {
                Ok(v) if v.is_finite() && (0.0..=max).contains(&v) => Ok(Some(v)),
                _ => Err(format!(
                    "{what} must be a number within 0 … {max}, in `JOINT_SIGMA[,GRIPPER_SIGMA]` (radians, actuator units), got {shown}"
                )),
            }
        };
        let joint_sigma = next("the joint σ", MAX_JOINT_SIGMA)?.unwrap_or(0.0);
        let gripper_sigma = next("the gripper σ", MAX_GRIPPER_SIGMA)?.unwrap_or(0.0);
        if parts.next().is_some() {
            return Err(format!("expected `JOINT_SIGMA[,GRIPPER_SIGMA]`, got {shown}"));
        }
        Ok(Self {
            joint_sigma,
            gripper_sigma,
        })
    }

    /// Both σ are finite and within their ranges (0 … [`MAX_JOINT_SIGMA`] radians, 0 …
    /// [`MAX_GRIPPER_SIGMA`]).
    pub fn check(&self) -> Result<(), String> {
        let within = |v: f64, max: f64| v.is_finite() && (0.0..=max).contains(&v);
        if !within(self.joint_sigma, MAX_JOINT_SIGMA) {
            return Err(format!(
                "the joint σ must be within 0 … {MAX_JOINT_SIGMA} rad, got {}",
                self.joint_sigma
            ));
        }
        if !within(self.gripper_sigma, MAX_GRIPPER_SIGMA) {
            return Err(format!(
                "the gripper σ must be within 0 … {MAX_GRIPPER_SIGMA}, got {}",
                self.gripper_sigma
            ));
        }
        Ok(())
    }

    /// The observer that adds this noise in an episode seeded with `seed` (a stream of its own,
    /// apart from the faults').
    pub fn injector(self, seed: u64) -> Box<dyn StepObserver> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(0x2015_e000);
        Box::new(NoiseInjector {
            noise: self,
            rng,
            offsets: Offsets::default(),
            steps_left: 0,
            moving: false,
            ctrl: Vec::new(),
        })
    }
}

/// The offsets held now.
#[derive(Default)]
struct Offsets {
    /// Per arm joint, radians.
    joints: [f64; 6],
    /// Gripper command, actuator units.
    gripper: f64,
}

struct NoiseInjector {
    noise: ActionNoise,
    rng: ChaCha8Rng,
    offsets: Offsets,
    /// Physics steps until the next draw.
    steps_left: u32,
    /// The period's command moves the arm (the offsets act).
    moving: bool,
    /// The actuator commands being offset (kept to spare an allocation per physics step).
    ctrl: Vec<f64>,
}

impl NoiseInjector {
    /// A draw from N(0, σ²) (Box–Muller).
    fn gaussian(&mut self, sigma: f64) -> f64 {
        let u1 = uniform(&mut self.rng, f64::MIN_POSITIVE, 1.0);
        let u2 = uniform(&mut self.rng, 0.0, 1.0);
        sigma * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

impl StepObserver for NoiseInjector {
    fn on_period(&mut self, command: &CellCommand) {
        self.moving = command.arm.qd.iter().any(|v| *v != 0.0);
    }

    fn before_step(&mut self, sim: &mut Sim) {
        if self.steps_left == 0 {
            for j in 0..6 {
                self.offsets.joints[j] = self.gaussian(self.noise.joint_sigma);
            }
            self.offsets.gripper = self.gaussian(self.noise.gripper_sigma);
            self.steps_left = (NOISE_HOLD_S / TIMESTEP).round() as u32;
        }
        self.steps_left -= 1;
        if !self.moving {
            return;
        }
        let ids = &sim.scene().ids;
        let (arm, gripper) = (ids.arm_act, ids.gripper_act);
        self.ctrl.clear();
        self.ctrl.extend_from_slice(sim.ctrl());
        for (a, offset) in arm.iter().zip(self.offsets.joints) {
            self.ctrl[*a] += offset;
        }
        let g = &mut self.ctrl[gripper];
        *g = (*g + self.offsets.gripper).clamp(0.0, 255.0);
        sim.set_ctrl(&self.ctrl);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_read_with_its_ranges() {
        assert_eq!(
            ActionNoise::parse("0.02,10").unwrap(),
            ActionNoise {
                joint_sigma: 0.02,
                gripper_sigma: 10.0
            }
        );
        assert_eq!(ActionNoise::parse("0.05").unwrap().gripper_sigma, 0.0);
        for bad in ["", "-0.1", "0.3", "nan", "0.01,500", "0.01,1,2", "x"] {
            assert!(ActionNoise::parse(bad).is_err(), "{bad:?}");
        }
    }
}
