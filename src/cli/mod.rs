//! The `macrotree` command line: `run`, `validate`, `bench`, `sweep`, and the authoring tools
//! `schema`, `graph` and `nodes`.
//!
//! Exit codes are a contract: 0 = the task succeeded (or the input is valid), 1 = the task
//! failed, 2 = bad input (unreadable or invalid tree, bad arguments, missing assets).

mod args;
mod bench;
mod dataset;
mod graph;
mod limits;
mod logging;
mod nodes;
mod outputs;
mod run;
mod schema;
mod sweep;
mod sweep_out;
mod validate;

use std::process::ExitCode;

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
    Sweep(sweep::SweepArgs),
    /// Print the JSON Schema of tree files (for editors; same as schema/tree.schema.json).
    Schema(schema::SchemaArgs),
    /// Print a tree as a Graphviz DOT or Mermaid diagram.
    Graph(graph::GraphArgs),
    /// List the node kinds with their parameters, units, defaults and examples.
    Nodes(nodes::NodesArgs),
}

/// A failure that maps to an exit code.
#[derive(Debug)]
pub enum CliError {
    /// Bad input: message already printed or to print; exit 2.
    Input(String),
    /// The task ran and failed; exit 1.
    TaskFailed,
}

/// Entry point of the `macrotree` binary.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let quiet = matches!(cli.command, Command::Bench(_) | Command::Sweep(_));
    logging::init(cli.verbose, cli.log_format, quiet);
    crate::spec::set_includes_anywhere(cli.allow_include_outside);
    let result = match cli.command {
        Command::Run(args) => run::run(args),
        Command::Validate(args) => validate::validate(args),
        Command::Bench(args) => bench::bench(args),
        Command::Sweep(args) => sweep::sweep(args),
        Command::Schema(args) => schema::schema(args),
        Command::Graph(args) => graph::graph(args),
        Command::Nodes(args) => nodes::nodes(args),
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

/// Loads and compiles a tree, or returns its diagnostics as a bad-input error.
fn load_plan_or_exit(path: &std::path::Path) -> Result<crate::plan::Plan, CliError> {
    crate::plan::load_plan(path).map_err(|diags| invalid(diags, path.display().to_string()))
}

/// Loads a tree for the scene it runs on — `scene_file` (a `--scene` override) when given, else
/// the tree's own `scene:` or the built-in scene — and compiles that scene with the robot.
/// Diagnostics of either file are a bad-input error.
fn load_task(
    tree: &std::path::Path,
    scene_file: Option<&std::path::Path>,
) -> Result<(crate::plan::Plan, crate::sim::Scene), CliError> {
    let plan = match scene_file {
        Some(path) => {
            let scene = crate::scene::load_scene_file(path)
                .map_err(|diags| invalid(diags, path.display().to_string()))?;
            crate::plan::load_plan_for(tree, Some(std::sync::Arc::new(scene)))
                .map_err(|diags| invalid(diags, format!("{} for scene {}", tree.display(), path.display())))?
        }
        None => load_plan_or_exit(tree)?,
    };
    let scene =
        crate::sim::Scene::load_spec(&plan.scene).map_err(|e| CliError::Input(format!("error: {e}")))?;
    Ok((plan, scene))
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
