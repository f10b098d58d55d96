//! The planner's settings: search caps, edge resolution, smoothing and the joint limits the
//! timing keeps, each range-checked.

use std::time::Duration;

use crate::motion::trajectory::MotionLimits;
use crate::motion::ur5e::{JOINT_LIMITS, LEVER_ARMS, RATED_JOINT_SPEED};

/// How far from the pinch point (metres) every point of a held block may lie for
/// [`LEVER_ARMS`] to cover it: the half diagonal of a 7 cm cube held at its centre. A
/// checker holding a block that reaches farther measures no spare clearance (the planner then
/// asks it about every configuration).
pub const HELD_BLOCK_REACH: f64 = 0.061;

/// Per-joint speed and acceleration limits a planned trajectory keeps, base to wrist 3.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimits {
    /// Largest speed of each joint, rad/s; at most [`RATED_JOINT_SPEED`].
    pub velocity: [f64; 6],
    /// Largest acceleration of each joint, rad/s².
    pub acceleration: [f64; 6],
}

impl JointLimits {
    /// The same speed and acceleration for every joint, from the limits every other motion of
    /// the crate keeps ([`MotionLimits::max_joint_speed`], [`MotionLimits::max_joint_acc`]).
    pub fn from_motion(limits: &MotionLimits) -> Self {
        Self {
            velocity: [limits.max_joint_speed; 6],
            acceleration: [limits.max_joint_acc; 6],
        }
    }

    /// Checks every limit is finite and positive, and no speed exceeds the UR5e's rating.
    ///
    /// # Errors
    /// The first limit out of range, and what to do.
    pub fn check(&self) -> Result<(), String> {
        for j in 0..6 {
            let (v, a) = (self.velocity[j], self.acceleration[j]);
            if !(v.is_finite() && v > 0.0 && v <= RATED_JOINT_SPEED) {
                return Err(format!(
                    "joint {} speed limit {v} rad/s: use a value in (0, {RATED_JOINT_SPEED:.4}] (the UR5e's rated 180 °/s)",
                    j + 1
                ));
            }
            if !(a.is_finite() && a > 0.0 && a <= 1000.0) {
                return Err(format!(
                    "joint {} acceleration limit {a} rad/s²: use a value in (0, 1000]",
                    j + 1
                ));
            }
        }
        Ok(())
    }
}

impl Default for JointLimits {
    /// [`JointLimits::from_motion`] of [`MotionLimits::default`]: the speed just under the UR5e's
    /// rated π rad/s and the acceleration the Menagerie servos track well.
    fn default() -> Self {
        Self::from_motion(&MotionLimits::default())
    }
}

/// How the planner searches, smooths and times a path. Every decision is driven by `seed` and
/// the counts here; `time_cap` is the only wall-clock term, and it can only end a search early
/// (with [`PlanFailure::TimeCap`](super::PlanFailure::TimeCap)), never change a path.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannerConfig {
    /// Seed of the search and the shortcutting (ChaCha8): the same seed, checker and query give
    /// the same path, bit for bit.
    pub seed: u64,
    /// Edge-checking resolution: the largest change of any joint between two configurations
    /// checked along a straight joint-space segment, radians. Default 0.05 rad (a point on the
    /// arm moves at most about 1 m per radian, so ≲ 5 cm between checks at the wrist).
    pub resolution: f64,
    /// Largest displacement of any point of the robot between two checked configurations,
    /// metres, bounded through `lever_arms` (see [`Resolution`](super::edge::Resolution)).
    /// Default 0.01 m: with a checker margin of at least half of it (the MuJoCo checker's default
    /// is 5 mm), nothing touches between checks either. `f64::INFINITY` turns the bound off.
    pub max_displacement: f64,
    /// Lever arm of each joint, metres: an upper bound on how far any point of the moving robot
    /// (and a held block) lies from the joint's axis. Default [`LEVER_ARMS`].
    pub lever_arms: [f64; 6],
    /// Longest step the search tree grows by in one extension, radians (Euclidean in joint
    /// space). Default 1.0 rad.
    pub range: f64,
    /// Search iterations at most (one sample, one extension, one connection attempt each).
    /// Default 2000.
    pub max_iterations: usize,
    /// Tree nodes at most (both trees together). Default 20 000.
    pub max_nodes: usize,
    /// Collision checks at most for the start, the goals, the direct segments and the search
    /// together; when the search reaches it, the plan ends with
    /// [`PlanFailure::SearchExhausted`](super::PlanFailure::SearchExhausted). The deterministic
    /// hard cap of the search (not one search check past it; the stages before it are bounded
    /// by the goal set): at the MuJoCo checker's 6–10 µs per check the default
    /// 20 000 is 0.1–0.2 s. Shortcutting and blending a found path come after it and are bounded
    /// by `shortcut_attempts` and the path. 1 to 10 000 000.
    pub max_checks: u64,
    /// Random shortcut attempts on the found path, after its greedy pass. Default 16 (48 gave
    /// paths 2–4 % shorter for about twice the planning time: `cargo bench --bench motion`).
    pub shortcut_attempts: usize,
    /// Least share of the stretch of path a random shortcut replaces that it must save to be
    /// checked, in [0, 1): an attempt whose straight segment is not shorter than
    /// `(1 − shortcut_min_gain)` times the path between its ends is skipped unchecked (its
    /// segment would cost a full check of a stretch that is almost straight already). Default
    /// 0.02: on the shelf family 18 % fewer instructions per plan than with 0, paths 0.1–0.4 %
    /// longer and trajectories as long within 0.6 % (`cargo bench --bench motion`); 0.05 saved
    /// 19 % but lengthened `go_around`'s episodes by 48 ms on average (0.02: 20 ms).
    pub shortcut_min_gain: f64,
    /// Largest joint-space deviation of a corner blend from the path's corner, radians. Blends
    /// are collision-checked at `resolution` and halved (down to none: the arm stops at the
    /// corner) until free. Default 0.1 rad; 0 turns blending off.
    pub blend_deviation: f64,
    /// The box the search samples in and every path stays in, radians per joint. Default
    /// [`JOINT_LIMITS`].
    pub bounds: [(f64, f64); 6],
    /// Speed and acceleration limits of the timed trajectory.
    pub limits: JointLimits,
    /// Largest speed of the pinch point along the timed trajectory, m/s (a held block moves
    /// with it): the path speed is capped at every cell boundary of the timing
    /// (`CELL` apart) by this over the pinch's displacement per radian
    /// of path there. `f64::INFINITY` (the default) leaves the joint limits alone; any other
    /// value must be positive.
    pub tool_speed: f64,
    /// Optional wall-clock safety cap on the search, 1 ms to 60 s; reaching it ends the plan
    /// with [`PlanFailure::TimeCap`](super::PlanFailure::TimeCap), the only outcome that depends
    /// on the machine's speed. Default none (the budgets `max_iterations`, `max_nodes` and
    /// `max_checks` decide alone).
    pub time_cap: Option<Duration>,
}

impl Default for PlannerConfig {
    /// Seed 0, 0.05 rad and 0.01 m resolution with [`LEVER_ARMS`], 1.0 rad range, 2000
    /// iterations, 20 000 nodes, 20 000 checks, 16 shortcuts that save at least 2 %, 0.1 rad
    /// blends, the joint limits as bounds, [`JointLimits::default`], no tool speed
    /// bound, no time cap.
    fn default() -> Self {
        Self {
            seed: 0,
            resolution: 0.05,
            max_displacement: 0.01,
            lever_arms: LEVER_ARMS,
            range: 1.0,
            max_iterations: 2000,
            max_nodes: 20_000,
            max_checks: 20_000,
            shortcut_attempts: 16,
            shortcut_min_gain: 0.02,
            blend_deviation: 0.1,
            bounds: JOINT_LIMITS,
            limits: JointLimits::default(),
            tool_speed: f64::INFINITY,
            time_cap: None,
        }
    }
}

impl PlannerConfig {
    /// The edge-checking resolution these settings describe.
    pub fn edge_resolution(&self) -> super::edge::Resolution {
        super::edge::Resolution {
            joint: self.resolution,
            displacement: self.max_displacement,
            lever_arms: self.lever_arms,
        }
    }

    /// Checks every setting is in range.
    ///
    /// # Errors
    /// The first setting out of range, and the range to use.
    pub fn check(&self) -> Result<(), String> {
        if !(self.resolution.is_finite() && (1e-4..=0.5).contains(&self.resolution)) {
            return Err(format!(
                "edge resolution {} rad: use a value in [0.0001, 0.5]",
                self.resolution
            ));
        }
        if self.max_displacement.is_nan() || self.max_displacement < 1e-4 {
            return Err(format!(
                "max_displacement {} m: use a value of at least 0.0001 (or infinity for no bound)",
                self.max_displacement
            ));
        }
        if !self
            .lever_arms
            .iter()
            .all(|r| r.is_finite() && (0.0..=10.0).contains(r))
        {
            return Err(format!(
                "lever_arms {:?} m: use values in [0, 10]",
                self.lever_arms
            ));
        }
        if !(self.range.is_finite() && self.range >= self.resolution && self.range <= 10.0) {
            return Err(format!(
                "range {} rad: use a value in [resolution, 10]",
                self.range
            ));
        }
        if self.max_iterations == 0 || self.max_iterations > 10_000_000 {
            return Err(format!(
                "max_iterations {}: use 1 to 10 000 000",
                self.max_iterations
            ));
        }
        if self.max_nodes < 2 || self.max_nodes > 10_000_000 {
            return Err(format!("max_nodes {}: use 2 to 10 000 000", self.max_nodes));
        }
        if self.max_checks == 0 || self.max_checks > 10_000_000 {
            return Err(format!("max_checks {}: use 1 to 10 000 000", self.max_checks));
        }
        if let Some(cap) = self.time_cap
            && !(Duration::from_millis(1)..=Duration::from_secs(60)).contains(&cap)
        {
            return Err(format!(
                "time_cap {} s: use 0.001 to 60 seconds",
                cap.as_secs_f64()
            ));
        }
        if self.shortcut_attempts > 100_000 {
            return Err(format!(
                "shortcut_attempts {}: use at most 100 000",
                self.shortcut_attempts
            ));
        }
        if !(self.shortcut_min_gain.is_finite() && (0.0..1.0).contains(&self.shortcut_min_gain)) {
            return Err(format!(
                "shortcut_min_gain {}: use a share in [0, 1)",
                self.shortcut_min_gain
            ));
        }
        if !(self.blend_deviation.is_finite() && (0.0..=1.0).contains(&self.blend_deviation)) {
            return Err(format!(
                "blend_deviation {} rad: use a value in [0, 1]",
                self.blend_deviation
            ));
        }
        if self.tool_speed.is_nan() || self.tool_speed <= 0.0 {
            return Err(format!(
                "tool_speed {} m/s: use a positive value (or infinity for no bound)",
                self.tool_speed
            ));
        }
        for (j, &(lo, hi)) in self.bounds.iter().enumerate() {
            let (jl, jh) = JOINT_LIMITS[j];
            if !(lo.is_finite() && hi.is_finite() && lo < hi && lo >= jl && hi <= jh) {
                return Err(format!(
                    "bounds of joint {} [{lo}, {hi}] rad: use lo < hi inside the joint limits [{jl}, {jh}]",
                    j + 1
                ));
            }
        }
        self.limits.check()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_pass_their_own_check_and_bad_values_are_named() {
        PlannerConfig::default().check().unwrap();
        let c = PlannerConfig {
            resolution: 0.0,
            ..PlannerConfig::default()
        };
        assert!(c.check().unwrap_err().contains("resolution"));
        let mut c = PlannerConfig::default();
        c.limits.velocity[2] = 4.0;
        assert!(c.check().unwrap_err().contains("joint 3 speed"));
        let mut c = PlannerConfig::default();
        c.bounds[0] = (1.0, f64::NAN);
        assert!(c.check().unwrap_err().contains("joint 1"));
        for gain in [-0.1, 1.0, f64::NAN] {
            let c = PlannerConfig {
                shortcut_min_gain: gain,
                ..PlannerConfig::default()
            };
            assert!(c.check().unwrap_err().contains("shortcut_min_gain"), "{gain}");
        }
    }
}
