//! Scenario files: read with located errors, their paths resolved, their node patterns checked
//! against the tree; their JSON Schema.

use std::path::{Component, Path, PathBuf};

use schemars::JsonSchema;
use serde::Deserialize;

use super::{Expect, Outcome};
use crate::episode::Goal;
use crate::failure::FailureKind;
use crate::faults::FaultKind;
use crate::plan::Plan;
use crate::runtime::substitute::{Resolved, Substitution, glob_match, resolve};
use crate::sweep::SweepConfig;
use crate::yaml::de::from_value;
use crate::yaml::diag::{Diagnostic, Issue, Loc, Sources};
use crate::yaml::suggest::did_you_mean;
use crate::yaml::value::{Value, decode_utf8, parse_yaml};

/// Most scenarios in one scenario file (suites are for CI; sweeps are for studies).
pub const MAX_COUNT: u64 = 100_000;
/// Most substitutions or node patterns in one scenario file.
pub const MAX_RULES: usize = 64;

/// A scenario file, as written (the JSON Schema `schema/scenario.schema.json` is generated from
/// this type). Paths are relative to the scenario file's folder.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFileRaw {
    /// One line saying what the suite checks.
    #[serde(default)]
    pub description: Option<String>,
    /// The tree file (relative to this file's folder).
    pub tree: String,
    /// A scene file that replaces the tree's own `scene:` (relative to this file's folder); its
    /// `random:` ranges are where the scenarios' layouts are drawn.
    #[serde(default)]
    pub scene: Option<String>,
    /// Scenarios to run (1 … 100000): scenario k of seed S is the same everywhere.
    #[schemars(range(min = 1, max = 100000))]
    pub count: u64,
    /// The sweep seed S. Default 0.
    #[serde(default)]
    pub seed: u64,
    /// A fault injected through physics in every scenario (see docs/faults.md).
    #[serde(default)]
    pub fault: Option<FaultName>,
    /// What counts as success: `scene` (default; the tree succeeded and the scene's goal
    /// holds), `bowl`, or `tree`.
    #[serde(default)]
    pub goal: Option<GoalName>,
    /// Per-episode simulated time limit, seconds (0 … 3600]. Default 60.
    #[serde(default)]
    #[schemars(range(min = 0.0, max = crate::episode::MAX_SIM_TIME_S))]
    pub max_sim_time: Option<f64>,
    /// Leaves replaced by scripted outcomes (test doubles), in every scenario.
    #[serde(default)]
    pub substitute: Vec<Substitution>,
    /// What must hold.
    #[serde(default)]
    pub expect: Expect,
}

/// Fault names in scenario files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[allow(missing_docs)]
pub enum FaultName {
    Slip,
    Nudge,
    Bump,
    LateBowl,
}

impl From<FaultName> for FaultKind {
    fn from(f: FaultName) -> FaultKind {
        match f {
            FaultName::Slip => FaultKind::Slip,
            FaultName::Nudge => FaultKind::Nudge,
            FaultName::Bump => FaultKind::Bump,
            FaultName::LateBowl => FaultKind::LateBowl,
        }
    }
}

/// Goal names in scenario files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[allow(missing_docs)]
pub enum GoalName {
    Scene,
    Bowl,
    Tree,
}

impl From<GoalName> for Goal {
    fn from(g: GoalName) -> Goal {
        match g {
            GoalName::Scene => Goal::Scene,
            GoalName::Bowl => Goal::Bowl,
            GoalName::Tree => Goal::Tree,
        }
    }
}

/// A checked scenario file.
#[derive(Debug, Clone, PartialEq)]
pub struct ScenarioFile {
    /// The file, as given (or as found under a folder).
    pub path: PathBuf,
    /// Its `description:`.
    pub description: Option<String>,
    /// The tree file, relative to the working directory.
    pub tree: PathBuf,
    /// The scene file, relative to the working directory.
    pub scene: Option<PathBuf>,
    /// The sweep this suite runs (without jobs and shard).
    pub sweep: SweepConfig,
    /// What must hold.
    pub expect: Expect,
    /// Where each substitution and each node pattern of `expect:` is written (for
    /// [`Self::check_against`]).
    pattern_at: Vec<PatternAt>,
}

/// Where one entry of a list is written: the list (`substitute`, or a pattern list of
/// `expect:` such as `ran` or `counts`), the entry's index there, and its 1-based line and
/// column in the file.
#[derive(Clone, Debug, PartialEq)]
struct PatternAt {
    key: &'static str,
    index: usize,
    line: u32,
    column: u32,
}

/// Every node pattern of `expect:`, by the key it is written under, in the order the file
/// lists them (`failed_node` is one pattern, `counts` entries name theirs under `node:`).
fn pattern_lists(e: &Expect) -> [(&'static str, Vec<&str>); 7] {
    fn strs(l: &[String]) -> Vec<&str> {
        l.iter().map(String::as_str).collect()
    }
    [
        ("ran", strs(&e.ran)),
        ("ran_in_every", strs(&e.ran_in_every)),
        ("failed", strs(&e.failed)),
        ("never_ran", strs(&e.never_ran)),
        ("never_failed", strs(&e.never_failed)),
        ("failed_node", e.failed_node.iter().map(String::as_str).collect()),
        ("counts", e.counts.iter().map(|c| c.node.as_str()).collect()),
    ]
}

/// Where every substitution and every node pattern of `expect` ([`pattern_lists`]) is written
/// in the scenario file `v`.
fn pattern_locations(v: &Value, expect: &Expect) -> Vec<PatternAt> {
    let mut out = Vec::new();
    for (index, x) in v
        .get("substitute")
        .and_then(Value::as_seq)
        .into_iter()
        .flatten()
        .enumerate()
    {
        out.push(PatternAt {
            key: "substitute",
            index,
            line: x.loc.line,
            column: x.loc.col,
        });
    }
    let written = v.get("expect");
    for (key, list) in pattern_lists(expect) {
        let Some(value) = written.and_then(|e| e.get(key)) else {
            continue;
        };
        for index in 0..list.len() {
            let item = match key {
                "failed_node" => Some(value),
                "counts" => value
                    .as_seq()
                    .and_then(|l| l.get(index))
                    .map(|x| x.get("node").unwrap_or(x)),
                _ => value.as_seq().and_then(|l| l.get(index)),
            };
            if let Some(x) = item {
                out.push(PatternAt {
                    key,
                    index,
                    line: x.loc.line,
                    column: x.loc.col,
                });
            }
        }
    }
    out
}

/// Whether the YAML document `v` is meant as a scenario file: a mapping with `tree:`,
/// `count:` or `expect:` (keys no tree or scene file has) and without `main:`.
pub fn is_scenario_file(v: &Value) -> bool {
    v.get("main").is_none() && ["tree", "count", "expect"].iter().any(|k| v.get(k).is_some())
}

/// Whether `v` is a mapping with at least one of the scenario file's keys (else nothing of it
/// is quoted).
fn is_scenario_document(v: &Value) -> bool {
    v.as_map().is_some_and(|entries| {
        entries
            .iter()
            .any(|(k, _)| k.as_str().is_some_and(|k| keys().contains(&k)))
    })
}

/// Keys allowed in a scenario file: the fields of [`ScenarioFileRaw`].
fn keys() -> &'static [&'static str] {
    crate::yaml::field_names::<ScenarioFileRaw>()
}

/// `base/rel` with `.` and `a/..` removed lexically (no file system access), so that reproduce
/// commands read `trees/x.yaml`, not `scenarios/../trees/x.yaml`.
pub fn join_clean(base: &Path, rel: &str) -> PathBuf {
    let joined = base.join(rel);
    let mut out: Vec<Component> = Vec::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out.iter().collect()
}

/// Reads a scenario file (a regular file of at most 1 MiB) with located errors.
pub fn load_scenario_file(path: &Path, custom_kinds: &[&str]) -> Result<ScenarioFile, Vec<Diagnostic>> {
    let name = path.display().to_string();
    let mut sources = Sources::new();
    let bytes = match crate::yaml::read_limited(path) {
        Ok(b) => b,
        Err((msg, help)) => {
            let id = sources.add(name, "");
            return Err(sources.diagnostics(&[Issue::new(Loc::file_start(id), msg).help(help)]));
        }
    };
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let id = sources.add_file(path, text.clone());
    if let Err(issue) = decode_utf8(&bytes, id) {
        return Err(sources.diagnostics(&[issue]));
    }
    let v = match parse_yaml(&text, id) {
        Ok(v) => v,
        Err(issue) => return Err(sources.diagnostics(&[issue])),
    };
    if !is_scenario_document(&v) {
        sources.withhold(id);
    }
    let mut issues = Vec::new();
    let file = read(path, &v, &mut issues, custom_kinds);
    match file {
        Some(f) if issues.is_empty() => Ok(f),
        _ => Err(sources.diagnostics(&issues)),
    }
}

fn read(path: &Path, v: &Value, issues: &mut Vec<Issue>, custom_kinds: &[&str]) -> Option<ScenarioFile> {
    let Some(entries) = v.as_map() else {
        issues.push(
            Issue::new(
                Loc::file_start(v.loc.file),
                format!(
                    "a scenario file must be a mapping, found {}",
                    crate::yaml::value::kind_of(v)
                ),
            )
            .label("expected `tree:`, `count:` and `expect:`")
            .help("see docs/testing_trees.md"),
        );
        return None;
    };
    // Not a scenario file at all: one issue, quoting nothing.
    if !is_scenario_document(v) {
        issues.push(
            Issue::new(
                Loc::file_start(v.loc.file),
                "this is not a scenario file: it has none of its keys (`tree:`, `count:`, `expect:`, …)",
            )
            .label("expected `tree:`, `count:` and `expect:`")
            .help("see docs/testing_trees.md"),
        );
        return None;
    }
    for (k, _) in entries {
        let key = k.as_str().unwrap_or("?");
        if !keys().contains(&key) {
            issues.push(
                Issue::new(k.loc, format!("unknown key `{key}` in a scenario file"))
                    .label(format!("expected {}", crate::yaml::de::list(keys())))
                    .maybe_help(did_you_mean(key, keys().iter().copied())),
            );
        }
    }
    if let Some(e) = v.get("expect").and_then(Value::as_map) {
        let allowed = crate::yaml::field_names::<Expect>();
        for (k, _) in e {
            let key = k.as_str().unwrap_or("?");
            if !allowed.contains(&key) {
                issues.push(
                    Issue::new(k.loc, format!("unknown key `{key}` in `expect:`"))
                        .label(format!("expected {}", crate::yaml::de::list(allowed)))
                        .maybe_help(did_you_mean(key, allowed.iter().copied())),
                );
            }
        }
    }
    if !issues.is_empty() {
        return None;
    }
    let raw: ScenarioFileRaw = match from_value(v) {
        Ok(r) => r,
        Err(e) => {
            issues.push(
                e.into_issue(v.loc, |l| format!("{l:?}"))
                    .help_or("see docs/testing_trees.md and schema/scenario.schema.json"),
            );
            return None;
        }
    };
    let at = |keys: &[&str]| v.loc_at(keys);
    if !(1..=MAX_COUNT).contains(&raw.count) {
        issues.push(
            Issue::new(
                at(&["count"]),
                format!("`count` must be 1 to {MAX_COUNT}, got {}", raw.count),
            )
            .label("number of scenarios"),
        );
    }
    let max_sim_time = raw.max_sim_time.unwrap_or(crate::episode::DEFAULT_MAX_SIM_TIME_S);
    if !(max_sim_time.is_finite() && max_sim_time > 0.0 && max_sim_time <= crate::episode::MAX_SIM_TIME_S) {
        issues.push(
            Issue::new(
                at(&["max_sim_time"]),
                format!(
                    "`max_sim_time` must be more than 0 and at most {} s, got {max_sim_time}",
                    crate::episode::MAX_SIM_TIME_S
                ),
            )
            .label("seconds of simulated time"),
        );
    }
    let e = &raw.expect;
    if let Some(r) = e.min_success_rate
        && !(0.0..=1.0).contains(&r)
    {
        issues.push(
            Issue::new(
                at(&["expect", "min_success_rate"]),
                format!("`min_success_rate` must be 0 … 1, got {r}"),
            )
            .label("a fraction, e.g. 0.9"),
        );
    }
    if e.outcome == Outcome::Failure && e.min_success_rate.is_some() {
        issues.push(
            Issue::new(
                at(&["expect", "min_success_rate"]),
                "`min_success_rate` goes with `outcome: success`",
            )
            .label("with `outcome: failure` every scenario must fail")
            .help("remove one of the two"),
        );
    }
    if e.outcome == Outcome::Success && (e.failure_kind.is_some() || e.failed_node.is_some()) {
        let key = if e.failure_kind.is_some() {
            "failure_kind"
        } else {
            "failed_node"
        };
        issues.push(
            Issue::new(
                at(&["expect", key]),
                format!("`{key}` goes with `outcome: failure`"),
            )
            .label("what every failure must look like")
            .help("add `outcome: failure`, or remove it"),
        );
    }
    if let Some(kind) = &e.failure_kind
        && FailureKind::builtin(kind).is_none()
        && !custom_kinds.contains(&kind.as_str())
    {
        let names: Vec<&str> = FailureKind::BUILTIN
            .iter()
            .map(|k| k.as_str())
            .chain(custom_kinds.iter().copied())
            .collect();
        issues.push(
            Issue::new(at(&["expect", "failure_kind"]), format!("unknown failure kind `{kind}`"))
                .label(format!("expected one of {}", names.join(", ")))
                .maybe_help(did_you_mean(kind, names.iter().copied()))
                .help_or("a node kind of your own program declares its kinds (`Params::failure_kinds`); run the suite with that program"),
        );
    }
    if let Some(t) = e.max_sim_time
        && !(t.is_finite() && t > 0.0 && t <= crate::episode::MAX_SIM_TIME_S)
    {
        issues.push(
            Issue::new(
                at(&["expect", "max_sim_time"]),
                format!(
                    "`max_sim_time` must be more than 0 and at most {} s, got {t}",
                    crate::episode::MAX_SIM_TIME_S
                ),
            )
            .label("seconds of simulated time"),
        );
    }
    for p in pattern_lists(e).into_iter().flat_map(|(_, list)| list) {
        if let Err(reason) = Substitution::check_pattern(p) {
            issues.push(Issue::new(at(&["expect"]), format!("node pattern: {reason}")));
        }
    }
    for (i, c) in e.counts.iter().enumerate() {
        if let Some((key, problem)) = c.problem() {
            let entry = v
                .get("expect")
                .and_then(|x| x.get("counts"))
                .and_then(Value::as_seq)
                .and_then(|l| l.get(i));
            let loc = entry.and_then(|x| x.get(key)).or(entry).map_or(v.loc, |x| x.loc);
            issues.push(
                Issue::new(loc, format!("`expect.counts` entry {}: {problem}", i + 1)).help(
                    "e.g. `- {node: \"main/**/carry\", failed: {exactly: 3}}`; see docs/testing_trees.md",
                ),
            );
        }
    }
    if raw.substitute.len() > MAX_RULES
        || e.ran.len()
            + e.ran_in_every.len()
            + e.failed.len()
            + e.never_ran.len()
            + e.never_failed.len()
            + e.counts.len()
            > MAX_RULES
    {
        issues.push(Issue::new(
            v.loc,
            format!("at most {MAX_RULES} substitutions and {MAX_RULES} node patterns per file"),
        ));
    }
    for (i, s) in raw.substitute.iter().enumerate() {
        if let Err(reason) = Substitution::check_pattern(&s.pattern) {
            let loc = v
                .get("substitute")
                .and_then(Value::as_seq)
                .and_then(|l| l.get(i))
                .map_or(v.loc, |x| x.loc);
            issues.push(Issue::new(loc, format!("substitution pattern: {reason}")));
        }
    }
    if !issues.is_empty() {
        return None;
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    let tree = join_clean(dir, &raw.tree);
    let scene = raw.scene.as_deref().map(|s| join_clean(dir, s));
    let sweep = SweepConfig {
        scenarios: raw.count,
        seed: raw.seed,
        fault: raw.fault.map(FaultKind::from),
        goal: raw.goal.map_or(Goal::default(), Goal::from),
        max_sim_time,
        scene_file: scene.as_ref().map(|p| p.display().to_string()),
        tree: tree.display().to_string(),
        substitutions: raw.substitute.clone(),
        suite: Some(path.display().to_string()),
        ..SweepConfig::default()
    };
    Some(ScenarioFile {
        path: path.to_path_buf(),
        description: raw.description,
        tree,
        scene,
        sweep,
        pattern_at: pattern_locations(v, &raw.expect),
        expect: raw.expect,
    })
}

impl ScenarioFile {
    /// Checks the file against the plan of its tree, as `test` does before running anything:
    /// every substitution resolves, and every node pattern of `expect:` matches some node (a
    /// pattern that matches nothing would pass or fail for the wrong reason). The errors are
    /// located in the scenario file.
    pub fn check_against(&self, plan: &Plan) -> Result<Resolved, Vec<Diagnostic>> {
        let resolved = resolve(plan, &self.sweep.substitutions).map_err(|e| {
            let at = self.written_at("substitute", e.index);
            let mut d = self.diagnostic(at, format!("substitution `{}`: {}", e.rule, e.reason));
            if !e.close.is_empty() {
                d.help = Some(format!("leaves with close paths: {}", e.close.join(", ")));
            }
            vec![d]
        })?;
        let mut diags = Vec::new();
        for (key, list) in pattern_lists(&self.expect) {
            for (i, p) in list.iter().enumerate() {
                if !plan.nodes.iter().any(|n| glob_match(p, &n.path)) {
                    let mut d = self.diagnostic(
                        self.written_at(key, i),
                        format!(
                            "`expect.{key}` pattern {p:?} matches no node of {}",
                            self.tree.display()
                        ),
                    );
                    d.help = Some(format!(
                        "`macrotree run {} --log-format json` lists the paths",
                        self.tree.display()
                    ));
                    diags.push(d);
                }
            }
        }
        if diags.is_empty() {
            Ok(resolved)
        } else {
            Err(diags)
        }
    }

    /// Where entry `index` of the list under `key` (`substitute`, or a pattern list of
    /// `expect:`) is written, if known.
    fn written_at(&self, key: &str, index: usize) -> Option<&PatternAt> {
        self.pattern_at.iter().find(|a| a.key == key && a.index == index)
    }

    /// An error in this file at `at` (the file's start when unknown).
    fn diagnostic(&self, at: Option<&PatternAt>, message: String) -> Diagnostic {
        let (line, column) = at.map_or((1, 1), |a| (a.line, a.column));
        Diagnostic::at(self.path.display().to_string(), line, column, message)
    }
}

/// The JSON Schema of scenario files, pretty, with a final newline (the committed
/// `schema/scenario.schema.json`).
pub fn schema_text() -> String {
    let schema = schemars::generate::SchemaSettings::draft2020_12()
        .for_deserialize()
        .into_generator()
        .into_root_schema_for::<ScenarioFileRaw>();
    let mut v = serde_json::to_value(&schema).expect("a schema serializes");
    v["$id"] = "https://macrotree.invalid/schema/scenario.schema.json".into();
    v["title"] = "macrotree scenario file".into();
    v["description"] = "A scenario suite for `macrotree test`: a tree, a scene, faults, substitutions, a count and a seed, and what must hold. See docs/testing_trees.md. Units: seconds.".into();
    serde_json::to_string_pretty(&v).expect("a serde_json::Value always serializes") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joins_clean() {
        assert_eq!(
            join_clean(Path::new("scenarios"), "../trees/a.yaml"),
            PathBuf::from("trees/a.yaml")
        );
        assert_eq!(
            join_clean(Path::new("x/scenarios"), "./b/../c.yaml"),
            PathBuf::from("x/scenarios/c.yaml")
        );
        assert_eq!(join_clean(Path::new(""), "../a"), PathBuf::from("../a"));
    }
}
