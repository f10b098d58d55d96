//! [`App`]: the library's entry point — a [`Registry`] of node kinds (the built-in ones plus
//! yours), trees loaded against it, episodes run on physics, and the `macrotree` command line
//! with your nodes in it.

use std::path::Path;
use std::sync::Arc;

use crate::actions::MacroAction;
use crate::episode::{EpisodeConfig, EpisodeReport, NoObserver};
use crate::error::Error;
use crate::plan::Plan;
use crate::registry::{Params, Registry};
use crate::sim::Scene;
use crate::world::World;

/// Largest [`EpisodeConfig::max_sim_time`] [`App::run_episode`] accepts, seconds (one hour, as
/// on the command line).
pub const MAX_SIM_TIME_S: f64 = 3600.0;

/// The node kinds a program knows, and what it does with trees of them.
///
/// ```no_run
/// use macrotree::App;
/// use macrotree::episode::{EpisodeConfig, Goal};
///
/// let app = App::new(); // the built-in node kinds; add yours with `register_action`
/// let plan = app.compile_str("main: {sequence: {children: [{home: {}}, {at_home: {}}]}}", "t.yaml")?;
/// let report = app.run_episode(&plan, &EpisodeConfig { goal: Goal::Tree, ..EpisodeConfig::default() })?;
/// println!("{}", report.tree_status);
/// # Ok::<(), macrotree::Error>(())
/// ```
#[derive(Clone, Debug, Default)]
pub struct App {
    registry: Arc<Registry>,
    /// How [`App::run_cli`] presents the program (name, description, version).
    #[cfg(feature = "cli")]
    cli: crate::cli::CliInfo,
}

impl App {
    /// An app with the built-in node kinds.
    pub fn new() -> App {
        App::default()
    }

    /// An app with the node kinds of `registry`.
    pub fn with_registry(registry: Registry) -> App {
        App {
            registry: Arc::new(registry),
            #[cfg(feature = "cli")]
            cli: crate::cli::CliInfo::default(),
        }
    }

    /// The node kinds.
    pub fn registry(&self) -> &Registry {
        &self.registry
    }

    /// Adds an action leaf kind; see [`Registry::register_action`].
    ///
    /// # Errors
    /// [`Error::Registry`] for an invalid or duplicate name, or an incomplete doc.
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
        Arc::make_mut(&mut self.registry).register_action(name, doc, start)?;
        Ok(self)
    }

    /// Adds a condition leaf kind; see [`Registry::register_condition`].
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
        F: Fn(&World, &P) -> Result<bool, String> + Send + Sync + 'static,
    {
        Arc::make_mut(&mut self.registry).register_condition(name, doc, check)?;
        Ok(self)
    }

    /// Reads, validates and compiles a tree from text. `file_name` appears in diagnostics, and
    /// its folder (if any) is the base for relative `include:` and `scene:` paths.
    ///
    /// # Errors
    /// [`Error::Tree`] with located diagnostics.
    pub fn compile_str(&self, yaml: &str, file_name: &str) -> Result<Plan, Error> {
        crate::spec::load::load_str_in(&self.registry, yaml, file_name)
            .and_then(|spec| crate::plan::compile_spec(&spec))
            .map_err(|diagnostics| Error::Tree {
                file: file_name.to_string(),
                diagnostics,
            })
    }

    /// Reads, validates and compiles a tree file (following its `include:`s) for its own
    /// `scene:` (or the built-in `cube_bowl` scene).
    ///
    /// # Errors
    /// [`Error::Tree`] with located diagnostics.
    pub fn load_tree(&self, path: &Path) -> Result<Plan, Error> {
        crate::spec::load::load_file_in(&self.registry, path, None)
            .and_then(|spec| crate::plan::compile_spec(&spec))
            .map_err(|diagnostics| Error::Tree {
                file: path.display().to_string(),
                diagnostics,
            })
    }

    /// Like [`load_tree`](Self::load_tree), for the scene file `scene` instead of the tree's own.
    ///
    /// # Errors
    /// [`Error::Scene`] when the scene is invalid, [`Error::Tree`] when the tree is (or names
    /// objects the scene does not have).
    pub fn load_tree_for_scene(&self, path: &Path, scene: &Path) -> Result<Plan, Error> {
        let spec = crate::scene::load_scene_file(scene).map_err(|diagnostics| Error::Scene {
            file: scene.display().to_string(),
            diagnostics,
        })?;
        crate::spec::load::load_file_in(&self.registry, path, Some(Arc::new(spec)))
            .and_then(|spec| crate::plan::compile_spec(&spec))
            .map_err(|diagnostics| Error::Tree {
                file: path.display().to_string(),
                diagnostics,
            })
    }

    /// Builds the simulation of `plan`'s scene (the robot and the scene's objects).
    ///
    /// # Errors
    /// [`Error::Simulator`] when the robot's model files are missing (run `tools/bootstrap`) or
    /// MuJoCo refuses the model.
    pub fn simulator(&self, plan: &Plan) -> Result<Scene, Error> {
        Scene::load_spec(&plan.scene).map_err(|e| Error::Simulator {
            message: e.to_string(),
        })
    }

    /// Runs one episode of `plan` on physics, in a fresh cell of its scene, and reports it.
    ///
    /// # Errors
    /// [`Error::Config`] when `config`'s time limit is not in (0, [`MAX_SIM_TIME_S`]] or its
    /// control period is not a positive whole number of 2 ms physics steps up to 0.1 s;
    /// [`Error::Simulator`] as for [`simulator`](Self::simulator).
    pub fn run_episode(&self, plan: &Plan, config: &EpisodeConfig) -> Result<EpisodeReport, Error> {
        check_config(config)?;
        let scene = self.simulator(plan)?;
        Ok(crate::episode::run_episode(
            &scene,
            Arc::new(plan.clone()),
            config,
            &mut NoObserver,
        ))
    }

    /// Runs the `macrotree` command line (`run`, `validate`, `nodes`, `schema`, `graph`,
    /// `sweep`, …) with this app's node kinds, on the process's arguments, and answers its exit
    /// code (0 success, 1 task failed, 2 bad input).
    ///
    /// `--help` and `--version` show macrotree's name, description and version unless the app
    /// sets its own with [`App::cli_name`], [`App::cli_about`] and [`App::cli_version`].
    #[cfg(feature = "cli")]
    pub fn run_cli(self) -> std::process::ExitCode {
        crate::cli::main_as(Arc::unwrap_or_clone(self.registry), self.cli)
    }

    /// The program's name in [`App::run_cli`]'s `--help`, usage lines and `--version`
    /// (default `macrotree`).
    #[cfg(feature = "cli")]
    pub fn cli_name(&mut self, name: &'static str) -> &mut Self {
        self.cli.name = Some(name);
        self
    }

    /// The one-line description at the top of [`App::run_cli`]'s `--help` (default:
    /// macrotree's).
    #[cfg(feature = "cli")]
    pub fn cli_about(&mut self, about: &'static str) -> &mut Self {
        self.cli.about = Some(about);
        self
    }

    /// The version [`App::run_cli`]'s `--version` prints (default: macrotree's), e.g.
    /// `env!("CARGO_PKG_VERSION")` of your crate.
    #[cfg(feature = "cli")]
    pub fn cli_version(&mut self, version: &'static str) -> &mut Self {
        self.cli.version = Some(version);
        self
    }
}

/// The physics step the control period must be a multiple of, seconds.
const PHYSICS_STEP: f64 = 0.002;

fn check_config(c: &EpisodeConfig) -> Result<(), Error> {
    if !(c.max_sim_time.is_finite() && c.max_sim_time > 0.0 && c.max_sim_time <= MAX_SIM_TIME_S) {
        return Err(Error::Config {
            message: format!(
                "max_sim_time must be more than 0 and at most {MAX_SIM_TIME_S} s, got {}",
                c.max_sim_time
            ),
        });
    }
    let steps = c.control_period / PHYSICS_STEP;
    if !(c.control_period.is_finite()
        && c.control_period > 0.0
        && c.control_period <= 0.1
        && (steps - steps.round()).abs() < 1e-9)
    {
        return Err(Error::Config {
            message: format!(
                "control_period must be a whole number of 2 ms physics steps, at most 0.1 s, got {}",
                c.control_period
            ),
        });
    }
    Ok(())
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
