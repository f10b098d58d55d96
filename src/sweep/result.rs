//! [`ScenarioResult`]: one line of a sweep's JSONL, its reproduction command.

use serde::Serialize;

use crate::episode::{EpisodeConfig, EpisodeOutcome, EpisodeReport, Goal};
use crate::faults::FaultKind;
use crate::runtime::substitute::Substitution;
use crate::sweep::{Scenario, ScenarioLayout, SweepConfig};

/// One line of the sweep's JSONL: the scenario and its episode's outcome (the fields of
/// `run --json`, except the wall time, so that a sweep's output is byte-identical for any number
/// of jobs and any machine).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScenarioResult {
    /// The scenario file of `macrotree test` this result belongs to (absent for sweeps).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub suite: Option<String>,
    /// The tree file, as given to the sweep.
    pub tree: String,
    /// The `--scene` file, if one was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scene_file: Option<String>,
    /// Scenarios in the whole sweep (N, before sharding).
    pub scenarios: u64,
    /// What counted as success (`--goal`).
    pub sweep_goal: Goal,
    /// The per-episode simulated time limit, seconds.
    pub max_sim_time: f64,
    /// Substitutions applied in every scenario (`PATTERN=OUTCOME`).
    #[serde(skip_serializing_if = "Vec::is_empty", serialize_with = "as_rules")]
    pub substitutions: Vec<Substitution>,
    /// `--collisions`: written only when not the default `count` (so the lines of a default sweep
    /// are what they were).
    #[serde(skip_serializing_if = "crate::episode::CollisionPolicy::is_count")]
    pub collision_policy: crate::episode::CollisionPolicy,
    /// Scenario index k.
    pub index: u64,
    /// Sweep seed S.
    pub sweep_seed: u64,
    /// Episode seed (`run --seed`).
    pub seed: u64,
    /// The injected fault.
    pub fault: Option<FaultKind>,
    /// The layout of a `sampler: tutorial` scene (the built-in one), exactly as sampled (and as
    /// `run --cube X,Y,YAW --bowl X,Y` takes it); other scenes list every object in `objects`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub layout: Option<ScenarioLayout>,
    /// How the episode ended (its fields sit at the top level of the line); its `success` is
    /// judged by the sweep's goal.
    #[serde(flatten)]
    pub outcome: EpisodeOutcome,
    /// The digest of the tree, its includes and the scene the sweep ran
    /// ([`SweepConfig::tree_digest`]); a line that has it also ends with its checksum (`crc32`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tree_digest: Option<String>,
    /// Motions checked and planned in the episode.
    pub planning: crate::actions::PlanCounts,
    /// Wall-clock time of the episode, seconds (not written to the JSONL).
    #[serde(skip)]
    pub wall_time_s: f64,
    /// Wall-clock time the episode spent checking and planning motions, seconds (not written to
    /// the JSONL).
    #[serde(skip)]
    pub planning_wall_s: f64,
}

impl ScenarioResult {
    /// The result of `scenario` of the sweep `config` from its episode report.
    pub fn new(scenario: &Scenario, config: &SweepConfig, r: EpisodeReport) -> Self {
        Self {
            wall_time_s: r.wall_time_s,
            planning: r.planning.counts(),
            planning_wall_s: r.planning.planning_wall_s,
            ..Self::of(config, scenario.index, scenario.seed, scenario.layout, r.outcome)
        }
    }

    /// A result of the sweep `config` for an episode that could not run (it panicked, or its
    /// layout could not be drawn).
    pub(super) fn not_run(
        config: &SweepConfig,
        index: u64,
        seed: u64,
        layout: Option<ScenarioLayout>,
        reason: crate::failure::Failure,
    ) -> Self {
        Self::of(config, index, seed, layout, EpisodeOutcome::not_run(reason))
    }

    /// Scenario `index` of the sweep `config` (episode seed `seed`, drawn `layout`) that ended
    /// with `outcome`, with no wall-clock time or planning counted.
    fn of(
        config: &SweepConfig,
        index: u64,
        seed: u64,
        layout: Option<ScenarioLayout>,
        outcome: EpisodeOutcome,
    ) -> Self {
        Self {
            suite: config.suite.clone(),
            tree: config.tree.clone(),
            scene_file: config.scene_file.clone(),
            scenarios: config.scenarios,
            sweep_goal: config.goal,
            max_sim_time: config.max_sim_time,
            substitutions: config.substitutions.clone(),
            collision_policy: config.collisions,
            index,
            sweep_seed: config.seed,
            seed,
            fault: config.fault,
            layout,
            outcome,
            tree_digest: config.tree_digest.clone(),
            wall_time_s: 0.0,
            planning: Default::default(),
            planning_wall_s: 0.0,
        }
    }

    /// The result as one JSON line (without the newline).
    pub fn to_jsonl(&self) -> String {
        let json = serde_json::to_string(self).expect("a scenario result serializes");
        if self.tree_digest.is_some() {
            crate::sweep::digest::with_checksum(&json)
        } else {
            json
        }
    }

    /// The `macrotree run …` command that reproduces this scenario bit for bit (the program
    /// named as [`SweepConfig::program`] says). Floats are
    /// printed with Rust's shortest round-trip formatting, so they parse back to the same bits.
    pub fn reproduce(&self, tree: &str, config: &SweepConfig) -> String {
        let mut cmd = match &self.layout {
            Some(l) => format!(
                "{} run {} --cube {},{},{}deg --bowl {},{} --seed {}",
                config.program,
                shell_quote(tree),
                l.cube[0],
                l.cube[1],
                l.cube[2],
                l.bowl[0],
                l.bowl[1],
                self.seed
            ),
            None => format!(
                "{} run {} --sweep-seed {} --scenario {}",
                config.program,
                shell_quote(tree),
                self.sweep_seed,
                self.index
            ),
        };
        if let Some(scene) = &config.scene_file {
            cmd += &format!(" --scene {}", shell_quote(scene));
        }
        if let Some(fault) = self.fault {
            cmd += &format!(" --fault {fault}");
        }
        if config.goal != Goal::default() {
            cmd += &format!(" --goal {}", config.goal.name());
        }
        if config.max_sim_time != EpisodeConfig::default().max_sim_time {
            cmd += &format!(" --max-sim-time {}", config.max_sim_time);
        }
        for sub in &config.substitutions {
            cmd += &format!(" --substitute {}", shell_quote(&sub.to_string()));
        }
        if config.collisions != crate::episode::CollisionPolicy::Count {
            cmd += &format!(" --collisions {}", config.collisions.name());
        }
        cmd
    }
}

/// Substitutions as their `PATTERN=OUTCOME` text.
fn as_rules<S: serde::Serializer>(subs: &[Substitution], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(subs.iter().map(|x| x.to_string()))
}

/// Quotes `s` for a POSIX shell when it holds anything but `[A-Za-z0-9_./+-]`.
pub(crate) fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "_./+-".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_quoting() {
        assert_eq!(shell_quote("trees/a_b-1.yaml"), "trees/a_b-1.yaml");
        assert_eq!(shell_quote("my tree.yaml"), "'my tree.yaml'");
        assert_eq!(shell_quote("it's.yaml"), r"'it'\''s.yaml'");
    }
}
