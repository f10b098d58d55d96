//! A step-wise environment: reset the cell, then run one macro action per [`MacroEnv::step`]
//! — a registered leaf, a primitive of the reference tutorial, one control period of joint
//! targets, or a named subtree of a tree — and read the observation, reward and flags, as a
//! Gymnasium-style policy loop does. [`VecEnv`] steps several environments on worker threads.
//! The Python package is built on this; `docs/env.md` describes the semantics.
//!
//! ```no_run
//! use macrotree::App;
//! use macrotree::env::{Action, EnvConfig, MacroEnv, Primitive, Reset};
//!
//! let app = App::new();
//! let scene = macrotree::sim::Scene::load()?; // the built-in cube_bowl scene
//! let mut env = MacroEnv::new(&app, scene, None, EnvConfig::default())?;
//! let obs = env.reset(&Reset::Seed(7))?;
//! println!("cube at {:?}", obs.object("cube").unwrap().pos);
//! let r = env.step(&Action::Leaf(r#"{"reach": {"target": "cube", "offset": [0, 0, 0.12]}}"#.into()))?;
//! println!("{:?} after {} s, reward {}", r.status, r.sim_time, r.reward);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # What holds
//! - Determinism: the same scene, tree, config, reset and actions give bit-identical
//!   observations and results (any thread, any [`VecEnv`] size).
//! - A leaf runs exactly as in a tree. [`crate::episode::run_in_cell`] ticks the tree at the
//!   start of every control period and then advances the physics one period; a leaf's first
//!   tick starts its controller, and the tick where one leaf finishes also starts the next.
//!   A step runs the same loop on a one-leaf tree and returns at the tick where the leaf
//!   finishes, before any physics after it; the next step's first tick starts the next leaf. So
//!   stepping the leaves a tree started, in order, gives `run_episode`'s physics bit for bit —
//!   up to the control period `run_episode` still simulates after the tree has finished — as
//!   long as no leaf was halted (a guard or a race preempting a running leaf) and no loop
//!   started a new iteration (a `retry` attempt after the first, a `repeat`: each starts on a
//!   fresh tick). `tests/physics/env_replay.rs` checks this on the flagship tree.

mod action;
mod config;
#[cfg(feature = "render")]
mod film;
mod leaf;
mod memory;
mod observation;
mod primitive;
#[cfg(feature = "render")]
mod render;
mod reset;
mod residual;
mod step;
mod subtree;
mod vector;

use std::sync::Arc;

pub use crate::motion::{CTRL_LIMITS, CommandLimits};
pub use action::{Action, SETPOINT_LEN};
pub use config::{EnvConfig, MAX_CONTROL_PERIOD};
pub use leaf::{LEAF_SOURCE_NAME, MAX_LEAF_TEXT, compile_leaf};
pub use memory::ENV_MEMORY_BYTES;
pub use observation::{
    Contact, ENVIRONMENT_VALUES_PER_OBJECT, ObjectObservation, Observation, STATE_LEN, STATE_NAMES,
};
pub use primitive::{Duration, MAX_DURATION, MAX_MACRO_STEPS, MAX_REACH_DISTANCE, Primitive, REFERENCE_STEP};
#[cfg(feature = "render")]
pub use render::Image;
pub use reset::Reset;
pub use residual::{RESIDUAL_LEN, RESIDUAL_LIMITS, ResidualLimits};
pub use step::{BaseStep, Status, StepResult};
pub use vector::{Finished, INTERRUPT_POLL, MAX_ENVS, SPIN_WAIT, VecEnv};

use crate::actions::Cell;
use crate::episode::MacroDriver;
use crate::error::Error;
use crate::factory::Factory;
use crate::faults::FaultLog;
use crate::plan::{Loader, Plan};
use crate::runtime::TreeRunner;
use crate::scene::Placement;
use crate::sim::{Layout, Scene};
use config::time_limit_reached;
use step::{ControllerStepper, PlanStepper, Stepper};

/// One simulated cell driven one macro action at a time (see the module docs). `Send`: it can
/// move to a worker thread.
pub struct MacroEnv {
    cell: Cell,
    factory: Arc<Factory>,
    loader: Loader,
    tree: Option<Arc<Plan>>,
    config: EnvConfig,
    leaves: leaf::LeafCache,
    subtrees: subtree::Subtrees,
    fault_log: Option<FaultLog>,
    fault_reported: bool,
    unstable: bool,
    placement: Placement,
    episode_seed: u64,
    /// The base tree's run across residual steps, once one has started.
    base: Option<residual::BaseRun>,
    /// The last step was interrupted: a reset is needed.
    interrupted: bool,
    #[cfg(feature = "render")]
    film: Option<film::Film>,
}

impl MacroEnv {
    /// An environment of `scene` that knows `app`'s node kinds (built-in and registered ones:
    /// leaves given as mappings may use any of them), with `tree` for `Action::Subtree` (its
    /// object names must have been checked against this scene: load it with
    /// [`crate::App::load_tree_for_scene`] or give the tree's own scene), reset to the scene's
    /// poses.
    ///
    /// # Errors
    /// [`Error::Config`] for settings out of range or a tree made for another scene.
    pub fn new(
        app: &crate::App,
        scene: Scene,
        tree: Option<Arc<Plan>>,
        config: EnvConfig,
    ) -> Result<Self, Error> {
        config.check()?;
        if let Some(t) = &tree
            && *t.scene != *scene.spec
        {
            return Err(Error::Config {
                message: format!(
                    "the tree {} was checked against scene `{}`, not the environment's scene `{}`; load it for this scene (App::load_tree_for_scene)",
                    t.file, t.scene.name, scene.spec.name
                ),
            });
        }
        let cell = Cell::new(&scene, &Layout::default(), config.control_period);
        let placement = scene.default_placement();
        let mut env = Self {
            cell,
            factory: app.factory().clone(),
            loader: app.loader().clone(),
            tree,
            episode_seed: config.seed,
            config,
            leaves: leaf::LeafCache::default(),
            subtrees: subtree::Subtrees::default(),
            fault_log: None,
            #[cfg(feature = "render")]
            film: None,
            fault_reported: false,
            unstable: false,
            placement,
            base: None,
            interrupted: false,
        };
        env.reset(&Reset::Default)?;
        Ok(env)
    }

    /// Starts a new episode: the arm at home with the gripper open, every object where `how`
    /// puts it, time zero; the configured fault (if any) armed with the episode seed.
    ///
    /// # Errors
    /// [`Error::Action`] for a placement that is not allowed or a scene that cannot be drawn.
    pub fn reset(&mut self, how: &Reset) -> Result<Observation, Error> {
        let (placement, seed) = reset::resolve(self.cell.sim().scene(), how)?;
        self.episode_seed = seed.unwrap_or(self.config.seed);
        self.base = None;
        self.interrupted = false;
        self.cell.observers.clear();
        self.cell.reset_placement(&placement);
        self.placement = placement;
        self.fault_log = None;
        self.fault_reported = false;
        if let Some(kind) = self.config.fault {
            let (injector, log) = crate::faults::injector_with_log(kind, self.episode_seed);
            self.cell.observers.push(injector);
            self.fault_log = Some(log);
        }
        if let Some(noise) = self.config.noise {
            self.cell.observers.push(noise.injector(self.episode_seed));
        }
        self.unstable = false;
        #[cfg(feature = "render")]
        if let Some(f) = &mut self.film {
            f.take();
            f.restart(self.cell.world().time);
            f.tick(&self.cell)?;
        }
        Ok(self.observe())
    }

    /// Runs `action` to completion on simulated time (see [`Action`]) and reports what happened.
    /// A failed action is a result with `status` Failure and a typed `failure`, not an error.
    ///
    /// # Errors
    /// Only for invalid input, before anything is simulated: [`Error::Tree`] for a leaf mapping
    /// that does not parse or check (located in its text), [`Error::Action`] for numbers out
    /// of range, an unknown subtree, a subtree without a tree, or a step after the simulation
    /// became unstable (reset first).
    pub fn step(&mut self, action: &Action) -> Result<StepResult, Error> {
        self.step_with(action, &mut || false)
    }

    /// [`step`](Self::step), asking `interrupt` at the start of every control period after the
    /// first whether to stop (a caller's Ctrl-C: the closure decides how often it really
    /// looks). When it says so, the running action is halted there, the step returns
    /// [`Error::Interrupted`] and the environment must be reset before it steps again.
    ///
    /// # Errors
    /// As [`step`](Self::step); [`Error::Interrupted`] as above.
    pub fn step_with(
        &mut self,
        action: &Action,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<StepResult, Error> {
        self.check_usable()?;
        if !matches!(action, Action::Residual(_)) {
            self.end_base_run();
        }
        let dt = self.cell.control_period();
        let mut clamped = 0;
        let mut stepper: Box<dyn Stepper> = match action {
            Action::Leaf(text) => {
                let plan = self
                    .leaves
                    .get(&self.loader, &self.cell.sim().scene().spec, text)?;
                Box::new(PlanStepper(TreeRunner::new(plan)))
            }
            Action::Subtree(name) => {
                let tree = self.tree.as_ref().ok_or_else(|| Error::Action {
                    message: format!(
                        "subtree `{name}`: this environment has no tree; give one to MacroEnv::new"
                    ),
                })?;
                let plan = self.subtrees.get(tree, name)?;
                Box::new(PlanStepper(TreeRunner::new(plan)))
            }
            Action::Primitive(p) => {
                p.check()?;
                Box::new(ControllerStepper::new(
                    Box::new(primitive::PrimitiveRun::new(p.clone(), dt)),
                    p.name(),
                ))
            }
            Action::Ctrl(_) | Action::Setpoint(_) => {
                let values = action::ctrl_of(action).expect("a ctrl or setpoint action");
                let checked = action::check_ctrl(&values, &self.cell.arm_setpoint(), dt)?;
                clamped = checked.clamped;
                Box::new(ControllerStepper::new(
                    Box::new(CtrlRun(checked.command)),
                    action.name(),
                ))
            }
            Action::Residual(r) => return self.step_residual(r),
        };
        let t0 = self.cell.world().time;
        let s0 = self.cell.sim().steps();
        let mut driver = MacroDriver::new(&mut self.cell, &self.factory);
        #[cfg(feature = "render")]
        let film = &mut self.film;
        let mut filmed = Ok(());
        let ran = step::run(
            &mut driver,
            stepper.as_mut(),
            self.config.max_sim_time,
            self.config.rewards_per_tick,
            &mut |_cell: &Cell| {
                #[cfg(feature = "render")]
                if let Some(f) = film.as_mut()
                    && filmed.is_ok()
                {
                    filmed = f.tick(_cell);
                }
            },
            interrupt,
        );
        drop(driver);
        filmed?;
        if ran.interrupted {
            self.interrupted = true;
            return Err(Error::Interrupted {
                message: format!(
                    "the step was interrupted at {:.3} s of simulated time; reset the environment",
                    self.cell.world().time
                ),
            });
        }
        self.unstable = ran.unstable;
        let world = self.cell.world();
        let goal = crate::world::goal::evaluate(world);
        let holds = step::goal_holds(world);
        let truncated =
            ran.truncated || (!ran.unstable && time_limit_reached(world.time, self.config.max_sim_time));
        Ok(StepResult {
            observation: self.observe(),
            status: if ran.outcome.is_ok() {
                Status::Success
            } else {
                Status::Failure
            },
            failure: ran.outcome.err(),
            sim_time: world.time - t0,
            physics_steps: self.cell.sim().steps() - s0,
            reward: if holds { 1.0 } else { 0.0 },
            goal_ticks: ran.goal_ticks,
            rewards: ran.rewards,
            terminated: holds || ran.unstable,
            truncated,
            collisions: ran.collisions,
            goal,
            faults_fired: self.faults_fired(),
            ctrl_clamped: clamped,
            base: None,
        })
    }

    /// Checks `action` as [`step`](Self::step) would before simulating anything, without
    /// running it: the leaf mapping compiles, the subtree exists, every number is in range, the
    /// simulation is usable. A vector environment checks a whole batch this way before any
    /// sub-environment moves.
    ///
    /// # Errors
    /// The error [`step`](Self::step) would give for invalid input.
    pub fn check_action(&mut self, action: &Action) -> Result<(), Error> {
        self.check_usable()?;
        let no_tree = |what: &str| Error::Action {
            message: format!("{what}: this environment has no tree; give one to MacroEnv::new"),
        };
        match action {
            Action::Leaf(text) => self
                .leaves
                .get(&self.loader, &self.cell.sim().scene().spec, text)
                .map(drop),
            Action::Subtree(name) => {
                let tree = self
                    .tree
                    .as_ref()
                    .ok_or_else(|| no_tree(&format!("subtree `{name}`")))?;
                self.subtrees.get(tree, name).map(drop)
            }
            Action::Primitive(p) => p.check(),
            Action::Ctrl(_) | Action::Setpoint(_) => {
                let values = action::ctrl_of(action).expect("a ctrl or setpoint action");
                action::check_ctrl(&values, &self.cell.arm_setpoint(), self.cell.control_period()).map(drop)
            }
            Action::Residual(r) => {
                if self.tree.is_none() {
                    return Err(no_tree("a residual step needs a base tree"));
                }
                residual::check(r)
            }
        }
    }

    /// The environment may step: no earlier step was interrupted or became unstable since the
    /// last reset.
    fn check_usable(&self) -> Result<(), Error> {
        let why = if self.interrupted {
            "the last step was interrupted"
        } else if self.unstable {
            "the simulation became unstable in an earlier step"
        } else {
            return Ok(());
        };
        Err(Error::Action {
            message: format!("{why}; reset the environment"),
        })
    }

    /// The fault that fired since the last report, if any, as `kind: what it did`.
    fn faults_fired(&mut self) -> Vec<String> {
        if self.fault_reported {
            return Vec::new();
        }
        let Some(log) = &self.fault_log else {
            return Vec::new();
        };
        let fired = log.lock().unwrap_or_else(|e| e.into_inner()).clone();
        match fired {
            Some(e) => {
                self.fault_reported = true;
                vec![format!("{}: {}", e.kind, e.detail)]
            }
            None => Vec::new(),
        }
    }

    /// Records every physics step's actuator commands from now until the next reset (for a
    /// bare-physics replay: [`crate::episode::replay::replay_controls`] from
    /// [`placement`](Self::placement) ends in this environment's state, bit for bit).
    pub fn record_controls(&mut self) -> crate::episode::replay::Controls {
        let (recorder, log) = crate::episode::replay::ControlRecorder::new();
        self.cell.observers.push(Box::new(recorder));
        log
    }

    /// The observation now.
    pub fn observe(&self) -> Observation {
        Observation::of(&self.cell)
    }

    /// The simulation of the environment's scene.
    pub fn scene(&self) -> &Scene {
        self.cell.sim().scene()
    }

    /// The tree `Action::Subtree` runs nodes of, if any.
    pub fn tree(&self) -> Option<&Arc<Plan>> {
        self.tree.as_ref()
    }

    /// The settings.
    pub fn config(&self) -> &EnvConfig {
        &self.config
    }

    /// Where the current episode's objects started.
    pub fn placement(&self) -> &Placement {
        &self.placement
    }

    /// The current episode's seed (fault timing and magnitude).
    pub fn episode_seed(&self) -> u64 {
        self.episode_seed
    }

    /// The action leaf kinds a mapping may name (built-in and registered), in registration order.
    pub fn action_kinds(&self) -> Vec<&'static str> {
        self.kinds(crate::kinds::Category::Action)
    }

    /// The condition leaf kinds a mapping may name, in registration order.
    pub fn condition_kinds(&self) -> Vec<&'static str> {
        self.kinds(crate::kinds::Category::Condition)
    }

    fn kinds(&self, category: crate::kinds::Category) -> Vec<&'static str> {
        self.loader
            .registry()
            .types()
            .filter(|t| t.category() == category)
            .map(|t| t.name())
            .collect()
    }

    /// The names `Action::Subtree` accepts: `main` and every named node of the tree (subtree
    /// calls are named after their subtree), in tree order; empty without a tree.
    pub fn subtree_names(&self) -> Vec<String> {
        let Some(tree) = &self.tree else {
            return Vec::new();
        };
        let mut out = vec!["main".to_string()];
        for n in &tree.nodes {
            if let Some(name) = &n.name
                && !out.contains(name)
            {
                out.push(name.clone());
            }
        }
        out
    }

    /// The cell (read-only: the simulation, the world snapshot), for inspection and tests.
    pub fn cell(&self) -> &Cell {
        &self.cell
    }
}

/// `Action::Ctrl` and `Action::Setpoint`: one control period of a checked command.
struct CtrlRun(crate::motion::CellCommand);

impl crate::actions::MacroAction for CtrlRun {
    fn start(&mut self, cell: &mut Cell) -> Result<(), crate::Failure> {
        cell.command_arm(self.0.arm);
        cell.set_gripper(self.0.gripper);
        Ok(())
    }
    fn update(&mut self, _cell: &mut Cell) -> crate::actions::Progress {
        crate::actions::Progress::Done
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn an_environment_can_move_to_another_thread() {
        fn send<T: Send>() {}
        send::<super::MacroEnv>();
        send::<super::StepResult>();
    }
}
