//! `macrotree validate FILE...`: parse and check trees and scene files without simulating. A
//! file whose top level has `objects:` and no `main:` is read as a scene.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::CliError;
use crate::spec::Diagnostic;

/// Arguments of `validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// Tree or scene files (YAML).
    #[arg(required = true)]
    pub trees: Vec<PathBuf>,
    /// Check the trees' object names against this scene instead of each tree's own `scene:`.
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
    for tree in &args.trees {
        let mut warnings = Vec::new();
        let result = if is_scene_file(tree) {
            crate::scene::load_scene_file(tree).map(|s| (s.objects.len(), s.goal.atoms.len()))
        } else {
            app.loader().load_for(tree, override_scene.clone()).map(|p| {
                warnings.clone_from(&p.warnings);
                (p.nodes.len(), p.leaves.len())
            })
        };
        if result.is_err() {
            failed += 1;
        }
        match args.format {
            DiagnosticFormat::Human => match &result {
                _ if !warnings.is_empty() && result.is_ok() => {
                    warnings.iter().for_each(|d| eprintln!("{d}"));
                    let (nodes, leaves) = result.as_ref().map_or((0, 0), |r| *r);
                    println!(
                        "{}: ok with {} warning(s) ({nodes} nodes, {leaves} leaves)",
                        tree.display(),
                        warnings.len()
                    );
                }
                Ok((a, b)) if is_scene_file(tree) => {
                    println!("{}: ok (scene: {a} objects, {b} goal predicates)", tree.display())
                }
                Ok((nodes, leaves)) => println!("{}: ok ({nodes} nodes, {leaves} leaves)", tree.display()),
                Err(diags) => diags.iter().for_each(|d| eprintln!("{d}")),
            },
            DiagnosticFormat::Json => {
                let (nodes, leaves, diags) = match &result {
                    Ok((a, b)) => (*a, *b, &warnings[..]),
                    Err(diags) => (0, 0, &diags[..]),
                };
                let line = serde_json::json!({
                    "file": tree.display().to_string(),
                    "valid": result.is_ok(),
                    "nodes": nodes,
                    "leaves": leaves,
                    "diagnostics": diags.iter().map(diagnostic_json).collect::<Vec<_>>(),
                });
                println!("{line}");
            }
            DiagnosticFormat::Github => {
                let diags = result.as_ref().err().unwrap_or(&warnings);
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

/// True for a scene file: a YAML mapping with `objects:` and without `main:` (read cheaply: a
/// file that cannot be read is left to the tree loader, which reports why).
fn is_scene_file(path: &std::path::Path) -> bool {
    let Ok(bytes) = crate::yaml::read_limited(path) else {
        return false;
    };
    let Ok(text) = std::str::from_utf8(&bytes) else {
        return false;
    };
    match crate::yaml::value::parse_yaml(text, 0) {
        Ok(v) => v.get("objects").is_some() && v.get("main").is_none(),
        Err(_) => false,
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
