//! [`EnvConfig`]: how a [`super::MacroEnv`] runs — control period, time limit, fault, seed,
//! per-tick rewards — and its range checks.

use crate::actions::CONTROL_PERIOD;
use crate::episode::{DEFAULT_MAX_SIM_TIME_S, MAX_SIM_TIME_S};
use crate::error::Error;
use crate::faults::FaultKind;
use crate::sim::TIMESTEP;

pub use crate::actions::MAX_CONTROL_PERIOD;

/// How a [`super::MacroEnv`] runs.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvConfig {
    /// The control period, seconds: a whole number of 2 ms physics steps
    /// ([`crate::sim::TIMESTEP`]), at most [`MAX_CONTROL_PERIOD`]. Leaves and subtrees are
    /// ticked once per period, exactly as `run_episode` ticks a tree; one `Action::Ctrl` holds
    /// its target for one period. Default [`crate::actions::CONTROL_PERIOD`] (4 ms = 2 physics
    /// steps), the tree's tick period everywhere else.
    pub control_period: f64,
    /// The episode's time limit, simulated seconds since the last reset (more than 0, at most
    /// [`crate::episode::MAX_SIM_TIME_S`]). A step that reaches it stops there (the running
    /// action is halted) and reports `truncated`. Default 60 s, as `macrotree run`.
    pub max_sim_time: f64,
    /// A fault injected through physics in every episode (`None`: none). It fires as in `run
    /// --fault`: on the leaves (`reach`, `grasp`, `carry`) it watches for; primitives and
    /// `Ctrl` do not trigger it.
    pub fault: Option<FaultKind>,
    /// The episode seed (fault timing and magnitude) for resets that do not draw one
    /// (`Reset::Default`, `Reset::Placement`); `Reset::Seed` and `Reset::Scenario` use the
    /// scenario's own, as a sweep does.
    pub seed: u64,
    /// Noise injected into what the arm and gripper execute while the leaves' clean commands
    /// stay the recorded ones (DART-style, as `sweep --dataset --noise`; see
    /// [`crate::faults::ActionNoise`]), seeded by the episode seed (`None`: none).
    pub noise: Option<crate::faults::ActionNoise>,
    /// Also report the reward of every control period of a step
    /// (`StepResult::rewards`, like the reference's `stack_rewards`). Default off: only their
    /// count ([`super::StepResult::goal_ticks`]).
    pub rewards_per_tick: bool,
}

/// Whether simulated time `now` has reached the time limit `limit` (seconds). MuJoCo adds its
/// time step by step, so 3 330 steps of 2 ms read 6.659999…: within half a physics step of the
/// limit counts as reached, so a limit of a whole number of control periods ends on the period
/// that reaches it, not one later.
pub(crate) fn time_limit_reached(now: f64, limit: f64) -> bool {
    now >= limit - 0.5 * TIMESTEP
}

impl Default for EnvConfig {
    fn default() -> Self {
        Self {
            control_period: CONTROL_PERIOD,
            max_sim_time: DEFAULT_MAX_SIM_TIME_S,
            fault: None,
            noise: None,
            seed: 0,
            rewards_per_tick: false,
        }
    }
}

impl EnvConfig {
    /// Physics steps per control period.
    pub fn steps_per_tick(&self) -> u32 {
        (self.control_period / TIMESTEP).round() as u32
    }

    /// The settings are in range.
    ///
    /// # Errors
    /// [`Error::Config`] naming the setting and the accepted range.
    pub fn check(&self) -> Result<(), Error> {
        crate::actions::check_control_period(self.control_period)?;
        if let Some(noise) = &self.noise {
            noise.check().map_err(|e| Error::Config {
                message: format!("noise: {e}"),
            })?;
        }
        if !(self.max_sim_time.is_finite() && self.max_sim_time > 0.0 && self.max_sim_time <= MAX_SIM_TIME_S)
        {
            return Err(Error::Config {
                message: format!(
                    "max_sim_time must be more than 0 and at most {MAX_SIM_TIME_S} s, got {}",
                    self.max_sim_time
                ),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_settings_are_config_errors() {
        assert!(EnvConfig::default().check().is_ok());
        assert_eq!(EnvConfig::default().steps_per_tick(), 2);
        for bad in [0.0, 1e-300, -0.004, 0.003, f64::NAN, f64::INFINITY, 0.2] {
            let c = EnvConfig {
                control_period: bad,
                ..EnvConfig::default()
            };
            let e = c.check().unwrap_err();
            assert_eq!(e.kind(), "config");
            assert!(e.to_string().contains("control_period"), "{e}");
        }
        for bad in [0.0, -1.0, f64::NAN, 1e9] {
            let c = EnvConfig {
                max_sim_time: bad,
                ..EnvConfig::default()
            };
            assert!(c.check().unwrap_err().to_string().contains("max_sim_time"));
        }
    }

    #[test]
    fn a_time_limit_of_whole_periods_is_reached_on_the_step_that_reaches_it_in_summed_time() {
        // 333 periods of 20 ms, summed 2 ms step by step as MuJoCo does: 6.659999….
        let mut now = 0.0;
        for step in 1..=3330 {
            now += TIMESTEP;
            assert_eq!(time_limit_reached(now, 6.66), step == 3330, "step {step}: {now}");
        }
        assert!(now < 6.66, "summed time {now} reads below the limit");
    }
}
