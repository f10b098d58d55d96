//! The `macrotree` command line: `run`, `validate`, `bench`, `sweep`, `test`, `report`, and the
//! authoring tools `schema`, `graph` and `nodes`.
//!
//! Exit codes are a contract: 0 = the task succeeded (or the input is valid), 1 = the task
//! failed, 2 = bad input (unreadable or invalid tree, bad arguments, missing assets).

mod args;
mod bench;
mod breakpoints;
mod dataset;
mod graph;
mod human;
mod info;
mod limits;
mod logging;
mod nodes;
mod output_set;
mod outputs;
mod plan;
mod report;
mod run;
mod scenario_check;
mod schema;
mod signals;
mod sweep;
mod sweep_args;
mod sweep_out;
mod test;
mod validate;

use std::process::ExitCode;
use std::sync::Arc;

use clap::{Parser, Subcommand};

pub use args::{CubeArg, XyArg};

/// Behavior trees in YAML driving a simulated UR5e + Robotiq 2F-85 (MuJoCo).
#[derive(Debug, Parser)]
#[command(name = "macrotree", version, about, propagate_version = true)]
pub struct Cli {
    /// More log detail (-v: debug, -vv: trace); RUST_LOG overrides.
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    pub verbose: u8,
    /// Log format on stderr.
    #[arg(long, value_enum, default_value_t = logging::LogFormat::Pretty, global = true)]
    pub log_format: logging::LogFormat,
    /// Let `include:` read files outside the main tree file's folder (see docs/security.md).
    #[arg(long, global = true)]
    pub allow_include_outside: bool,
    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run one headless episode of a tree.
    Run(run::RunArgs),
    /// Parse and check trees without simulating.
    Validate(validate::ValidateArgs),
    /// Run an episode, then replay its controls with bare mj_step, and compare wall times.
    Bench(bench::BenchArgs),
    /// Run a tree over many seeded random layouts in parallel (optionally with a fault) and summarize.
    Sweep(sweep_args::SweepArgs),
    /// Print the JSON Schema of tree files (for editors; same as schema/tree.schema.json).
    Schema(schema::SchemaArgs),
    /// Print a tree as a Graphviz DOT or Mermaid diagram.
    Graph(graph::GraphArgs),
    /// List the node kinds with their parameters, units, defaults and examples.
    Nodes(nodes::NodesArgs),
    /// Run scenario files (default: scenarios/) and check their expectations (JUnit for CI).
    Test(test::TestArgs),
    /// Merge the --out files of sharded sweeps or tests into the summary of one run.
    Report(report::ReportArgs),
    /// Plan one arm motion in a scene (from home or given joints to joints or a point) and print the path or the typed reason there is none.
    Plan(plan::PlanArgs),
}

/// A failure that maps to an exit code.
#[derive(Debug)]
pub enum CliError {
    /// Bad input: message already printed or to print; exit 2.
    Input(String),
    /// The task ran and failed; exit 1.
    TaskFailed,
}

impl crate::App {
    /// Runs the `macrotree` command line (`run`, `validate`, `nodes`, `schema`, `graph`,
    /// `sweep`, …) with this app's node kinds, on the process's arguments, and answers its exit
    /// code (0 success, 1 task failed, 2 bad input).
    ///
    /// `--help` and `--version` show macrotree's name, description and version unless the app
    /// sets its own with [`crate::App::cli_name`], [`crate::App::cli_about`] and
    /// [`crate::App::cli_version`].
    pub fn run_cli(self) -> ExitCode {
        main_with(self)
    }
}

/// Entry point of the `macrotree` binary: the command line with the built-in node kinds.
pub fn main() -> ExitCode {
    main_with(crate::App::new())
}

/// How a command printed for people to run (a sweep's reproduction commands) names this
/// program: `macrotree` when that name on `PATH` is this very binary (e.g. after
/// `cargo install --path .`); otherwise the path of this binary, relative to the current folder
/// when it lies inside it (`target/release/macrotree` from the repository), else absolute.
pub fn program_name() -> String {
    let Some(exe) = std::env::current_exe().ok().and_then(|p| p.canonicalize().ok()) else {
        return "macrotree".to_string();
    };
    let on_path = std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|dir| dir.join("macrotree").canonicalize().is_ok_and(|p| p == exe))
    });
    if on_path {
        return "macrotree".to_string();
    }
    let cwd = std::env::current_dir().ok().and_then(|d| d.canonicalize().ok());
    let shown = match cwd.as_deref().and_then(|d| exe.strip_prefix(d).ok()) {
        // `./macrotree`, not `macrotree` (which the shell would look up on PATH).
        Some(rel) if rel.components().count() == 1 => std::path::Path::new(".").join(rel),
        Some(rel) => rel.to_path_buf(),
        None => exe.clone(),
    };
    crate::sweep::shell_quote(&shown.display().to_string())
}

/// When the process started (as near as [`main`] can tell).
static STARTED: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();

/// Seconds since the process started ([`main`] was entered).
fn process_elapsed_s() -> f64 {
    STARTED
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_secs_f64()
}

/// Entry point of a `macrotree`-like program whose trees may use the node kinds of `app` (the
/// built-in ones plus its own): `nodes`, `schema`, `validate`, `run`, `sweep`, `test` and
/// `graph` all know its kinds.
pub fn main_with(app: crate::App) -> ExitCode {
    STARTED.get_or_init(std::time::Instant::now);
    let cli = info::parse(app.program());
    let quiet = matches!(
        cli.command,
        Command::Bench(_) | Command::Sweep(_) | Command::Test(_) | Command::Report(_)
    );
    logging::init(cli.verbose, cli.log_format, quiet);
    let app = app.includes_anywhere(cli.allow_include_outside);
    let app = &app;
    signals::install();
    let result = match cli.command {
        Command::Run(args) => run::run(app, args),
        Command::Validate(args) => validate::validate(app, args),
        Command::Bench(args) => bench::bench(app, args),
        Command::Plan(args) => plan::plan(args),
        Command::Sweep(args) => sweep::sweep(app, args),
        Command::Schema(args) => schema::schema(app, args),
        Command::Graph(args) => graph::graph(app, args),
        Command::Nodes(args) => nodes::nodes(app, args),
        Command::Test(args) => test::test(app, args),
        Command::Report(args) => report::report(app, args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::TaskFailed) => ExitCode::from(1),
        Err(CliError::Input(msg)) => {
            if !msg.is_empty() {
                eprintln!("{msg}");
            }
            ExitCode::from(2)
        }
    }
}

/// Diagnostics as a bad-input error: each one, then a line saying `what` is invalid.
fn invalid(diags: Vec<crate::spec::Diagnostic>, what: String) -> CliError {
    let text: Vec<String> = diags.iter().map(|d| d.to_string()).collect();
    CliError::Input(format!(
        "{}\nerror: {what} is invalid ({} error(s))",
        text.join("\n"),
        diags.len()
    ))
}

/// Loads and compiles a tree, or returns its diagnostics as a bad-input error. Warnings are
/// printed on stderr.
fn load_plan_or_exit(app: &crate::App, path: &std::path::Path) -> Result<crate::plan::Plan, CliError> {
    let plan = app
        .loader()
        .load(path)
        .map_err(|diags| invalid(diags, path.display().to_string()))?;
    print_warnings(&plan);
    Ok(plan)
}

/// Prints the tree's warnings on stderr.
fn print_warnings(plan: &crate::plan::Plan) {
    for w in &plan.warnings {
        eprintln!("{w}");
    }
}

/// Loads a tree for the scene it runs on — `scene_file` (a `--scene` override) when given, else
/// the tree's own `scene:` or the built-in scene — and compiles that scene with the robot.
/// Diagnostics of either file are a bad-input error.
fn load_task(
    app: &crate::App,
    tree: &std::path::Path,
    scene_file: Option<&std::path::Path>,
) -> Result<(crate::plan::Plan, crate::sim::Scene), CliError> {
    let plan = match scene_file {
        Some(path) => {
            let scene = crate::scene::load_scene_file(path)
                .map_err(|diags| invalid(diags, path.display().to_string()))?;
            let plan = app
                .loader()
                .load_for(tree, Some(std::sync::Arc::new(scene)))
                .map_err(|diags| {
                    invalid(diags, format!("{} for scene {}", tree.display(), path.display()))
                })?;
            print_warnings(&plan);
            plan
        }
        None => load_plan_or_exit(app, tree)?,
    };
    let scene =
        crate::sim::Scene::load_spec(&plan.scene).map_err(|e| CliError::Input(format!("error: {e}")))?;
    Ok((plan, scene))
}

/// The shard to run: `--shard K/M` as given, `--shard auto` from the environment (Slurm array
/// or Kubernetes Indexed Job, with `--shard-count`), or none.
fn resolve_shard(
    spec: Option<crate::sweep::ShardSpec>,
    count: Option<u64>,
) -> Result<Option<crate::sweep::Shard>, CliError> {
    match spec {
        None => Ok(None),
        Some(crate::sweep::ShardSpec::Fixed(s)) => {
            if count.is_some_and(|m| m != s.count) {
                return Err(CliError::Input(format!(
                    "error: --shard {s} and --shard-count {} disagree; --shard-count is for --shard auto",
                    count.unwrap_or(0)
                )));
            }
            Ok(Some(s))
        }
        Some(crate::sweep::ShardSpec::Auto) => {
            let shard = crate::sweep::Shard::from_env(|k| std::env::var(k).ok(), count)
                .map_err(|e| CliError::Input(format!("error: --shard auto: {e}")))?;
            eprintln!("shard {shard} (from the environment)");
            Ok(Some(shard))
        }
    }
}

/// `subs` resolved against `plan`, once for the whole command (every episode reuses them);
/// substitutions that do not fit `plan` (no leaf matched, a leaf matched twice, …) are bad
/// input.
fn resolve_substitutions(
    plan: &crate::plan::Plan,
    subs: &[crate::runtime::substitute::Substitution],
) -> Result<Arc<crate::runtime::substitute::Resolved>, CliError> {
    crate::runtime::substitute::resolve(plan, subs)
        .map(Arc::new)
        .map_err(|e| CliError::Input(format!("error: {e}")))
}

/// Writes `text` to `out` (safely, see [`crate::output`]; `inputs` are the files the command
/// read, which are never overwritten), or to stdout when `out` is `None`. A closed stdout pipe
/// (`| head`) ends the output quietly; a file that cannot be written is bad input (exit 2).
fn write_output(
    out: Option<&std::path::Path>,
    inputs: &[std::path::PathBuf],
    text: &str,
) -> Result<(), CliError> {
    use std::io::Write as _;
    match out {
        None => match std::io::stdout().lock().write_all(text.as_bytes()) {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                Err(CliError::Input(format!("error: cannot write to stdout: {e}")))
            }
            _ => Ok(()),
        },
        Some(path) => outputs::check_output(path, inputs)?
            .write_all(text.as_bytes())
            .map_err(outputs::output_error),
    }
}
