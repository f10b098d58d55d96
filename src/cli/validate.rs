//! `macrotree validate FILE...`: parse and check trees, scene files and scenario files without
//! simulating. A file whose top level has `objects:` and no `main:` is read as a scene; one
//! with `tree:`, `count:` or `expect:` and no `main:` as a scenario file, checked as `macrotree
//! test` checks it before running (its scene, its tree, its substitutions, its node patterns).

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::CliError;
use crate::spec::Diagnostic;

/// Arguments of `validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// Tree, scene or scenario files (YAML).
    #[arg(required = true)]
    pub trees: Vec<PathBuf>,
    /// Check the trees' object names against this scene instead of each tree's own `scene:`
    /// (a scenario file keeps the scene it names).
    #[arg(long, value_name = "FILE.yaml")]
    pub scene: Option<PathBuf>,
    /// How to print the result.
    #[arg(long, value_enum, default_value_t = DiagnosticFormat::Human)]
    pub format: DiagnosticFormat,
}

/// How `validate` prints its findings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DiagnosticFormat {
    /// rustc-style errors on stderr (source line, caret, help); "FILE: ok" on stdout.
    Human,
    /// One JSON object per file on stdout: `{file, valid, nodes, leaves, diagnostics: [...]}`,
    /// each diagnostic with 1-based `line`, `column`, `end_column` (exclusive), `message`,
    /// `label`, `help`, `note`. For editors and scripts.
    Json,
    /// GitHub Actions workflow commands on stdout (`::error file=…,line=…,col=…::…`), so that
    /// a CI run annotates the offending lines of a pull request.
    Github,
}

/// What a file given to `validate` is, judged by its top-level keys.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FileKind {
    /// A behavior tree (`main:`, `include:` or `subtrees:`; also anything unrecognised, which
    /// the tree loader then explains).
    Tree,
    /// A scene: `objects:` and no `main:`.
    Scene,
    /// A scenario file of `macrotree test`: `tree:`, `count:` or `expect:` and no `main:`.
    Scenario,
}

impl FileKind {
    /// The kind of the file at `path` (read cheaply: a file that cannot be read or parsed is
    /// left to the tree loader, which reports why).
    fn of(path: &std::path::Path) -> Self {
        let Ok(bytes) = crate::yaml::read_limited(path) else {
            return Self::Tree;
        };
        let Ok(text) = std::str::from_utf8(&bytes) else {
            return Self::Tree;
        };
        let Ok(v) = crate::yaml::value::parse_yaml(text, 0) else {
            return Self::Tree;
        };
        if v.get("main").is_some() {
            Self::Tree
        } else if v.get("objects").is_some() {
            Self::Scene
        } else if crate::suite::is_scenario_file(&v) {
            Self::Scenario
        } else {
            Self::Tree
        }
    }

    /// `tree`, `scene` or `scenario` (the `kind` of `--format json`).
    fn name(self) -> &'static str {
        match self {
            Self::Tree => "tree",
            Self::Scene => "scene",
            Self::Scenario => "scenario",
        }
    }
}

/// A valid file: what to print about it.
struct Valid {
    /// Nodes of the tree (a scene: its objects).
    nodes: usize,
    /// Leaves of the tree (a scene: its goal predicates).
    leaves: usize,
    /// The summary after `ok`, e.g. `12 nodes, 7 leaves`.
    summary: String,
    /// The tree's warnings.
    warnings: Vec<Diagnostic>,
}

/// Checks one file of `kind`.
fn check_file(
    app: &crate::App,
    path: &std::path::Path,
    kind: FileKind,
    scene: Option<&std::sync::Arc<crate::scene::SceneSpec>>,
) -> Result<Valid, Vec<Diagnostic>> {
    match kind {
        FileKind::Scene => crate::scene::load_scene_file(path).map(|s| Valid {
            nodes: s.objects.len(),
            leaves: s.goal.atoms.len(),
            summary: format!(
                "scene: {} objects, {} goal predicates",
                s.objects.len(),
                s.goal.atoms.len()
            ),
            warnings: Vec::new(),
        }),
        FileKind::Scenario => super::scenario_check::check_scenario(app, path).map(|c| Valid {
            nodes: c.plan.nodes.len(),
            leaves: c.plan.leaves.len(),
            summary: format!(
                "scenario: {} scenarios of {}, {} nodes, {} leaves",
                c.file.sweep.scenarios,
                c.file.tree.display(),
                c.plan.nodes.len(),
                c.plan.leaves.len()
            ),
            warnings: c.plan.warnings,
        }),
        FileKind::Tree => {
            let p = app.loader().load_for(path, scene.cloned())?;
            super::breakpoints::declared(&p)?;
            Ok(Valid {
                nodes: p.nodes.len(),
                leaves: p.leaves.len(),
                summary: format!("{} nodes, {} leaves", p.nodes.len(), p.leaves.len()),
                warnings: p.warnings,
            })
        }
    }
}

/// Runs `macrotree validate`: every error of every file, exit 2 if any.
pub fn validate(app: &crate::App, args: ValidateArgs) -> Result<(), CliError> {
    let mut failed = 0;
    let override_scene = match &args.scene {
        Some(path) => Some(std::sync::Arc::new(crate::scene::load_scene_file(path).map_err(
            |diags| {
                diags.iter().for_each(|d| eprintln!("{d}"));
                CliError::Input(format!("error: the scene {} is invalid", path.display()))
            },
        )?)),
        None => None,
    };
    for file in &args.trees {
        let kind = FileKind::of(file);
        let result = check_file(app, file, kind, override_scene.as_ref());
        if result.is_err() {
            failed += 1;
        }
        match args.format {
            DiagnosticFormat::Human => match &result {
                Ok(v) => {
                    v.warnings.iter().for_each(|d| eprintln!("{d}"));
                    let with = match v.warnings.len() {
                        0 => String::new(),
                        n => format!(" with {n} warning(s)"),
                    };
                    println!("{}: ok{with} ({})", file.display(), v.summary);
                }
                Err(diags) => diags.iter().for_each(|d| eprintln!("{d}")),
            },
            DiagnosticFormat::Json => {
                let (nodes, leaves, diags) = match &result {
                    Ok(v) => (v.nodes, v.leaves, &v.warnings[..]),
                    Err(diags) => (0, 0, &diags[..]),
                };
                let line = serde_json::json!({
                    "file": file.display().to_string(),
                    "kind": kind.name(),
                    "valid": result.is_ok(),
                    "nodes": nodes,
                    "leaves": leaves,
                    "diagnostics": diags.iter().map(diagnostic_json).collect::<Vec<_>>(),
                });
                println!("{line}");
            }
            DiagnosticFormat::Github => {
                let diags = match &result {
                    Ok(v) => &v.warnings,
                    Err(diags) => diags,
                };
                diags.iter().for_each(|d| println!("{}", github_annotation(d)));
            }
        }
    }
    if failed > 0 {
        Err(CliError::Input(format!(
            "error: {failed} of {} file(s) invalid",
            args.trees.len()
        )))
    } else {
        Ok(())
    }
}

/// A diagnostic as JSON (`end_column` is exclusive, in characters).
fn diagnostic_json(d: &Diagnostic) -> serde_json::Value {
    serde_json::json!({
        "file": d.file,
        "line": d.line,
        "column": d.column,
        "end_column": d.column + d.width,
        "severity": if d.warning { "warning" } else { "error" },
        "message": d.message,
        "label": d.label,
        "help": d.help,
        "note": d.note,
    })
}

/// A diagnostic as a GitHub Actions `::error` (or `::warning`) workflow command (one line; `endColumn` is
/// inclusive).
pub fn github_annotation(d: &Diagnostic) -> String {
    let mut text = d.message.clone();
    for extra in [&d.label, &d.note, &d.help].into_iter().flatten() {
        text += &format!("\n{extra}");
    }
    format!(
        "::{} file={},line={},col={},endColumn={},title=macrotree::{}",
        if d.warning { "warning" } else { "error" },
        escape_property(&d.file),
        d.line,
        d.column,
        d.column + d.width.max(1) - 1,
        escape_data(&text)
    )
}

/// Escapes a workflow command's message (`%`, CR, LF).
fn escape_data(s: &str) -> String {
    s.replace('%', "%25").replace('\r', "%0D").replace('\n', "%0A")
}

/// Escapes a workflow command's property value (also `:` and `,`).
fn escape_property(s: &str) -> String {
    escape_data(s).replace(':', "%3A").replace(',', "%2C")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn github_annotations_escape_what_the_runner_would_split_on() {
        let d = Diagnostic {
            file: "trees/a,b:c.yaml".into(),
            line: 4,
            column: 17,
            message: "unknown parameter `targt` in `reach` (100%)".into(),
            label: Some("expected one of `target`, `offset`".into()),
            help: Some("did you mean `target`?".into()),
            note: None,
            source_line: None,
            source_column: 17,
            width: 5,
            warning: false,
        };
        assert_eq!(
            github_annotation(&d),
            "::error file=trees/a%2Cb%3Ac.yaml,line=4,col=17,endColumn=21,title=macrotree::\
             unknown parameter `targt` in `reach` (100%25)%0Aexpected one of `target`, `offset`\
             %0Adid you mean `target`?"
        );
    }
}
