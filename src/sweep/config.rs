//! [`SweepConfig`]: what to sweep, and the scenario and episode configuration of each index.

use std::sync::Arc;

use crate::actions::CONTROL_PERIOD;
use crate::episode::{EpisodeConfig, Goal};
use crate::faults::FaultKind;
use crate::runtime::substitute::{Resolved, Substitution};
use crate::scene::PlacementError;
use crate::sim::Scene;
use crate::sweep::{Scenario, ScenarioIndices, Shard};

/// Most worker threads of a sweep (`sweep --jobs`, `test --jobs`): each holds one simulation;
/// more threads than this only cost start-up time and memory.
pub const MAX_JOBS: usize = 1024;

/// What to sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepConfig {
    /// Scenarios 0..N of the sweep (before sharding).
    pub scenarios: u64,
    /// Sweep seed S.
    pub seed: u64,
    /// Worker threads (0 = one per core).
    pub jobs: usize,
    /// A fault injected in every scenario.
    pub fault: Option<FaultKind>,
    /// Noise added to what every scenario's arm and gripper execute (`sweep --dataset --noise`);
    /// the recorded commands stay clean.
    pub noise: Option<crate::faults::ActionNoise>,
    /// What counts as success.
    pub goal: Goal,
    /// Only this shard's scenarios.
    pub shard: Option<Shard>,
    /// Per-episode simulated time limit, seconds.
    pub max_sim_time: f64,
    /// The `--scene` file the sweep was given, if any (printed in reproduction commands).
    pub scene_file: Option<String>,
    /// The tree file, as given (written to every result line, printed in reproduction
    /// commands).
    pub tree: String,
    /// Leaves replaced by scripted outcomes in every scenario (see
    /// [`crate::runtime::substitute`]).
    pub substitutions: Vec<Substitution>,
    /// `substitutions` resolved against the sweep's plan once, handed to every episode (see
    /// [`EpisodeConfig::resolved`]); `None`: each episode resolves them.
    pub resolved: Option<Arc<Resolved>>,
    /// The scenario file of `macrotree test` this sweep belongs to, if any.
    pub suite: Option<String>,
    /// The digest of the tree file, its includes and the scene file ([`files_digest`](crate::sweep::digest::files_digest)),
    /// written to every result line: `--resume` refuses lines of other contents.
    pub tree_digest: Option<String>,
    /// What a contact that should not happen does (`--collisions`).
    pub collisions: crate::episode::CollisionPolicy,
    /// How reproduction commands name the program (`macrotree` when it is on `PATH`, else the
    /// path of the binary that ran, e.g. `target/release/macrotree`), shell-quoted.
    pub program: String,
}

impl Default for SweepConfig {
    fn default() -> Self {
        Self {
            scenarios: 100,
            seed: 0,
            jobs: 0,
            fault: None,
            noise: None,
            goal: Goal::default(),
            shard: None,
            max_sim_time: EpisodeConfig::default().max_sim_time,
            scene_file: None,
            tree: String::new(),
            substitutions: Vec::new(),
            resolved: None,
            suite: None,
            tree_digest: None,
            collisions: Default::default(),
            program: "macrotree".to_string(),
        }
    }
}

impl SweepConfig {
    /// The scenario indices this sweep runs, ascending (computed, never listed).
    pub fn indices(&self) -> ScenarioIndices {
        ScenarioIndices::new(self.scenarios, self.shard)
    }

    /// Scenario `index` of this sweep on `scene`, drawn by [`crate::episode::scenario::draw`]
    /// (the draw `run --scenario K` and the step-wise environment's resets use too). A scene
    /// with `sampler: tutorial` (the built-in `cube_bowl`) draws its cube and bowl with the
    /// documented task-region sampler ([`crate::sweep::sample_layout`]), so its sweeps and
    /// reproduction commands (`--cube … --bowl …`) are those of earlier releases; every other
    /// scene draws its own randomization ([`crate::scene::sample_placement`]).
    ///
    /// # Errors
    /// When the scene's randomization cannot place its objects.
    pub fn scenario(&self, scene: &Scene, index: u64) -> Result<Scenario, PlacementError> {
        crate::episode::scenario::draw(scene, self.seed, index)
    }

    /// The episode configuration of `scenario` (see [`Self::scenario`]): for a `sampler:
    /// tutorial` scene, exactly what `macrotree run` builds from the reproduction command
    /// [`ScenarioResult::reproduce`](crate::sweep::ScenarioResult::reproduce) prints.
    pub fn episode_config(&self, scenario: &Scenario) -> EpisodeConfig {
        EpisodeConfig {
            placement: Some(scenario.placement.clone()),
            seed: scenario.seed,
            max_sim_time: self.max_sim_time,
            control_period: CONTROL_PERIOD,
            fault: self.fault,
            noise: self.noise,
            goal: self.goal,
            substitutions: self.substitutions.clone(),
            resolved: self.resolved.clone(),
            collisions: self.collisions,
        }
    }
}
