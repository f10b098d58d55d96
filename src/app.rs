//! [`App`]: the library's entry point — a [`Registry`] of node kinds (the built-in ones plus
//! yours), trees loaded against it, episodes run on physics, and the `macrotree` command line
//! with your nodes in it.

use std::path::Path;
use std::sync::Arc;

use crate::actions::MacroAction;
use crate::episode::MAX_SIM_TIME_S;
use crate::episode::{EpisodeConfig, EpisodeReport, NoObserver};
use crate::error::Error;
use crate::factory::Factory;
use crate::failure::Failure;
use crate::kinds::{ActionRole, Params, Registry};
use crate::plan::{Loader, Plan};
use crate::sim::Scene;
use crate::world::World;

/// The name, one-line description and version a `macrotree`-like program shows in `--help`,
/// usage lines and `--version` (`App::run_cli`); `None` keeps macrotree's own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ProgramInfo {
    /// The program's name (default `macrotree`).
    pub name: Option<&'static str>,
    /// The description at the top of `--help` (default: macrotree's).
    pub about: Option<&'static str>,
    /// The version `--version` prints (default: macrotree's).
    pub version: Option<&'static str>,
}

/// The node kinds a program knows, and what it does with trees of them.
///
/// ```no_run
/// use macrotree::App;
/// use macrotree::episode::{EpisodeConfig, Goal};
///
/// let app = App::new(); // the built-in node kinds; add yours with `register_action`
/// let plan = app.compile_str("main: {sequence: {children: [{home: {}}, {at_home: {}}]}}", "t.yaml")?;
/// let report = app.run_episode(&plan, &EpisodeConfig { goal: Goal::Tree, ..EpisodeConfig::default() })?;
/// println!("{}", report.outcome.tree_status);
/// # Ok::<(), macrotree::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct App {
    loader: Loader,
    factory: Arc<Factory>,
    program: ProgramInfo,
}

impl Default for App {
    /// The built-in node kinds, bound to the built-in controllers and checks.
    fn default() -> Self {
        App {
            loader: Loader::new(Arc::new(builtin_registry())),
            factory: Factory::builtin(),
            program: ProgramInfo::default(),
        }
    }
}

impl App {
    /// An app with the built-in node kinds.
    pub fn new() -> App {
        App::default()
    }

    /// The node kinds trees may use.
    pub fn registry(&self) -> &Registry {
        self.loader.registry()
    }

    /// How this app reads trees (its node kinds, where includes may come from).
    pub fn loader(&self) -> &Loader {
        &self.loader
    }

    /// How this app runs each action and condition kind.
    pub fn factory(&self) -> &Arc<Factory> {
        &self.factory
    }

    /// Lets `include:` read files outside the main tree file's folder (`true`) or not
    /// (`false`, the default; see `docs/security.md`).
    pub fn includes_anywhere(mut self, allow: bool) -> Self {
        self.loader = self.loader.includes_anywhere(allow);
        self
    }

    /// Registers an action leaf: declares the kind `name` with parameters `P` and `doc` (see
    /// [`Registry::declare_action`]) and binds `start`, which makes a new controller from the
    /// parameters each time the leaf starts (its `start` runs on the first tick, `update` on
    /// every tick after, `halt` when the tree preempts it). Its failures are typed
    /// ([`Failure`]): of a built-in [`FailureKind`](crate::FailureKind), or of a custom kind `P`
    /// declares in [`Params::failure_kinds`].
    ///
    /// # Errors
    /// [`Error::Registry`] when the name is not a lower-case identifier, is already registered,
    /// the doc lacks its summary, halt paragraph or example, or a declared failure kind is not a
    /// valid custom name.
    pub fn register_action<P, F>(
        &mut self,
        name: &'static str,
        doc: &'static str,
        start: F,
    ) -> Result<&mut Self, Error>
    where
        P: Params,
        F: Fn(&P) -> Box<dyn MacroAction> + Send + Sync + 'static,
    {
        self.register_action_as(name, doc, ActionRole::Other, start)
    }

    /// Registers an action leaf like [`register_action`](Self::register_action) that plays
    /// `role` in the pick-and-place cycle (see [`Registry::declare_action_as`]): a custom pick
    /// registered as [`ActionRole::Grasp`] is counted in the report's `grasp_attempts`, gets
    /// the tutorial's grasp checks, and arms the `nudge` fault, like the built-in `grasp`.
    ///
    /// # Errors
    /// As for [`register_action`](Self::register_action).
    pub fn register_action_as<P, F>(
        &mut self,
        name: &'static str,
        doc: &'static str,
        role: ActionRole,
        start: F,
    ) -> Result<&mut Self, Error>
    where
        P: Params,
        F: Fn(&P) -> Box<dyn MacroAction> + Send + Sync + 'static,
    {
        let mut registry = Registry::clone(self.loader.registry());
        registry.declare_action_as::<P>(name, doc, role)?;
        let mut factory = Factory::clone(&self.factory);
        factory.bind_action(name, start).map_err(|e| Error::Registry {
            kind: name.to_string(),
            message: e.0,
        })?;
        self.replace(registry, factory);
        Ok(self)
    }

    /// Registers a condition leaf: declares the kind `name` with parameters `P` and `doc` and
    /// binds `check`, which answers from the world snapshot alone (a pure function: called every
    /// tick the condition is checked, it must not keep state). `Ok(false)` fails the leaf with
    /// `not satisfied` (kind `condition_false`), `Err(failure)` fails it with that failure (e.g.
    /// an unknown object, kind `other`).
    ///
    /// # Errors
    /// As for [`register_action`](Self::register_action).
    pub fn register_condition<P, F>(
        &mut self,
        name: &'static str,
        doc: &'static str,
        check: F,
    ) -> Result<&mut Self, Error>
    where
        P: Params,
        F: Fn(&World, &P) -> Result<bool, Failure> + Send + Sync + 'static,
    {
        let mut registry = Registry::clone(self.loader.registry());
        registry.declare_condition::<P>(name, doc)?;
        let mut factory = Factory::clone(&self.factory);
        factory.bind_condition(name, check).map_err(|e| Error::Registry {
            kind: name.to_string(),
            message: e.0,
        })?;
        self.replace(registry, factory);
        Ok(self)
    }

    fn replace(&mut self, registry: Registry, factory: Factory) {
        let anywhere = self.loader.allows_includes_anywhere();
        self.loader = Loader::new(Arc::new(registry)).includes_anywhere(anywhere);
        self.factory = Arc::new(factory);
    }

    /// Reads, validates and compiles a tree from text (`file_name` appears in diagnostics and
    /// is the base of relative includes).
    ///
    /// # Errors
    /// [`Error::Tree`] with every located diagnostic.
    pub fn compile_str(&self, yaml: &str, file_name: &str) -> Result<Plan, Error> {
        self.loader
            .compile_str(yaml, file_name)
            .map_err(|diagnostics| Error::Tree {
                file: file_name.to_string(),
                diagnostics,
            })
    }

    /// Reads, validates and compiles a tree file (following its includes) for its own `scene:`.
    ///
    /// # Errors
    /// [`Error::Tree`] with every located diagnostic.
    pub fn load_tree(&self, path: &Path) -> Result<Plan, Error> {
        self.loader.load(path).map_err(|diagnostics| Error::Tree {
            file: path.display().to_string(),
            diagnostics,
        })
    }

    /// Reads a scene file and a tree file, and compiles the tree for that scene (instead of the
    /// tree's own `scene:`).
    ///
    /// # Errors
    /// [`Error::Scene`] or [`Error::Tree`] with every located diagnostic.
    pub fn load_tree_for_scene(&self, path: &Path, scene: &Path) -> Result<Plan, Error> {
        let spec = crate::scene::load_scene_file(scene).map_err(|diagnostics| Error::Scene {
            file: scene.display().to_string(),
            diagnostics,
        })?;
        self.loader
            .load_for(path, Some(Arc::new(spec)))
            .map_err(|diagnostics| Error::Tree {
                file: path.display().to_string(),
                diagnostics,
            })
    }

    /// Builds the simulation of the plan's scene (the robot and the scene's objects).
    ///
    /// # Errors
    /// [`Error::Simulator`] when the robot assets are missing or MuJoCo refuses the model.
    pub fn simulator(&self, plan: &Plan) -> Result<Scene, Error> {
        Scene::load_spec(&plan.scene).map_err(|e| Error::Simulator {
            message: e.to_string(),
        })
    }

    /// Runs one episode of `plan` on a fresh simulation of its scene.
    ///
    /// # Errors
    /// [`Error::Config`] for settings out of range, [`Error::Simulator`] when the simulation
    /// cannot be built.
    pub fn run_episode(&self, plan: &Plan, config: &EpisodeConfig) -> Result<EpisodeReport, Error> {
        check_config(config)?;
        let scene = self.simulator(plan)?;
        Ok(crate::episode::run_episode(
            &scene,
            Arc::new(plan.clone()),
            &self.factory,
            config,
            &mut NoObserver,
        ))
    }

    /// How [`App::run_cli`] presents the program (name, description, version).
    pub fn program(&self) -> &ProgramInfo {
        &self.program
    }

    /// The program's name in `App::run_cli`'s `--help`, usage lines and `--version`
    /// (default `macrotree`).
    pub fn cli_name(&mut self, name: &'static str) -> &mut Self {
        self.program.name = Some(name);
        self
    }

    /// The one-line description at the top of `App::run_cli`'s `--help` (default:
    /// macrotree's).
    pub fn cli_about(&mut self, about: &'static str) -> &mut Self {
        self.program.about = Some(about);
        self
    }

    /// The version `App::run_cli`'s `--version` prints (default: macrotree's), e.g.
    /// `env!("CARGO_PKG_VERSION")` of your crate.
    pub fn cli_version(&mut self, version: &'static str) -> &mut Self {
        self.program.version = Some(version);
        self
    }
}

fn check_config(c: &EpisodeConfig) -> Result<(), Error> {
    if !(c.max_sim_time.is_finite() && c.max_sim_time > 0.0 && c.max_sim_time <= MAX_SIM_TIME_S) {
        return Err(Error::Config {
            message: format!(
                "max_sim_time must be more than 0 and at most {MAX_SIM_TIME_S} s, got {}",
                c.max_sim_time
            ),
        });
    }
    crate::actions::check_control_period(c.control_period)
}

/// The built-in node kinds, with the checks of the files their leaves name (a `policy`'s model
/// is checked when the tree loads).
fn builtin_registry() -> Registry {
    let registry = Registry::builtin();
    #[cfg(feature = "policy")]
    let registry = {
        let mut r = registry;
        r.check_files_with("policy", crate::actions::policy::check_model_file);
        r
    };
    registry
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_episode_settings_are_config_errors() {
        let bad = EpisodeConfig {
            max_sim_time: 0.0,
            ..EpisodeConfig::default()
        };
        assert_eq!(check_config(&bad).unwrap_err().kind(), "config");
        let bad = EpisodeConfig {
            control_period: 0.003,
            ..EpisodeConfig::default()
        };
        let e = check_config(&bad).unwrap_err();
        assert!(e.message().contains("2 ms"), "{e}");
        assert!(check_config(&EpisodeConfig::default()).is_ok());
    }

    #[test]
    fn an_invalid_tree_is_a_located_tree_error() {
        let e = App::new()
            .compile_str("main: {sequense: {children: [{home: {}}]}}", "t.yaml")
            .unwrap_err();
        assert_eq!(e.kind(), "invalid_tree");
        assert_eq!(e.diagnostics().len(), 1);
        let text = e.to_string();
        assert!(text.contains("t.yaml:1:8"), "{text}");
        assert!(text.contains("did you mean `sequence`?"), "{text}");
    }
}
