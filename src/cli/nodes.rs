//! `macrotree nodes [KIND] [--json]`: the catalog of node kinds — composites, decorators,
//! actions and conditions — with parameters, units, defaults, halt behaviour and an example.
//!
//! The text is [`crate::kinds::catalog`], generated from the same documentation as each node's
//! rustdoc.

use std::fmt::Write as _;

use clap::Args;

use super::{CliError, write_output};
use crate::kinds::NodeDoc;

/// Arguments of `nodes`.
#[derive(Debug, Args)]
pub struct NodesArgs {
    /// Show only this node kind (e.g. `reach`, `retry`).
    pub kind: Option<String>,
    /// Print the catalog as one JSON array instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `macrotree nodes`; an unknown KIND is bad input (exit 2) with a suggestion.
pub fn nodes(app: &crate::App, args: NodesArgs) -> Result<(), CliError> {
    let all = app.registry().catalog();
    let shown: Vec<&NodeDoc> = match &args.kind {
        None => all.iter().collect(),
        Some(kind) => match all.iter().find(|d| d.kind == kind.as_str()) {
            Some(d) => vec![d],
            None => {
                let hint = crate::yaml::suggest::did_you_mean(kind, all.iter().map(|d| d.kind))
                    .map(|s| format!("\n  = help: {s}"))
                    .unwrap_or_default();
                return Err(CliError::Input(format!(
                    "error: unknown node kind `{kind}`{hint}\n  = note: `macrotree nodes` lists all {} kinds",
                    all.len()
                )));
            }
        },
    };
    let text = if args.json {
        serde_json::to_string(&shown).expect("the catalog serializes") + "\n"
    } else {
        render(&shown)
    };
    write_output(None, &[], &text)
}

/// Plain-text catalog: kinds grouped by category, each with its summary, parameters, halt
/// behaviour and example.
pub fn render(docs: &[&NodeDoc]) -> String {
    let mut out = String::new();
    for category in ["composite", "decorator", "action", "runtime", "condition"] {
        let group: Vec<&&NodeDoc> = docs.iter().filter(|d| d.category == category).collect();
        if group.is_empty() {
            continue;
        }
        let _ = writeln!(out, "{}", heading(category));
        for d in group {
            let _ = writeln!(out, "\n  {} — {}", d.kind, d.summary);
            for paragraph in d.details.lines() {
                for line in wrap(paragraph, 90) {
                    let _ = writeln!(out, "      {line}");
                }
            }
            let width = d.params.iter().map(|p| p.name.len()).max().unwrap_or(0);
            for p in &d.params {
                let when = match (&p.default, p.required) {
                    (_, true) => "required".to_string(),
                    (Some(v), false) => format!("default {v}"),
                    (None, false) => "optional".to_string(),
                };
                let _ = writeln!(out, "      {:width$}  {} ({when}): {}", p.name, p.ty, p.doc);
            }
            let _ = writeln!(out, "      halt: {}", d.halt);
            for line in d.example.lines() {
                let _ = writeln!(out, "      | {line}");
            }
        }
        out.push('\n');
    }
    out
}

fn heading(category: &str) -> &'static str {
    match category {
        "composite" => "COMPOSITES (control flow over children)",
        "decorator" => "DECORATORS (one child)",
        "action" => "ACTIONS (macro actions on the arm and gripper)",
        "runtime" => "RUNTIME LEAVES (handled by the tree runtime)",
        _ => "CONDITIONS (instantaneous checks of the world)",
    }
}

/// Greedy word wrap to lines of at most `width` characters (a longer word gets a line).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![];
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}
