//! Scenario suites (`macrotree test`): YAML files that name a tree, a scene, faults,
//! substitutions, a number of scenarios and a seed, and what must hold over them — read with
//! located errors like trees and scenes, checked against a run's results, and reported as text,
//! JSON and JUnit XML. See `docs/testing_trees.md`.
//!
//! ```yaml
//! # yaml-language-server: $schema=../schema/scenario.schema.json
//! description: A missed first grasp is recovered by the re-centring branch.
//! tree: ../trees/recenter_and_grasp.yaml
//! count: 4
//! seed: 1
//! substitute:
//!   - {pattern: "main/**/subtree[taught_pick]/**/grasp", outcome: "failure"}
//! expect:
//!   min_success_rate: 1.0
//!   ran_in_every: ["main/**/subtree[recentre_and_grasp]"]
//! ```

pub mod counts;
pub mod junit;
pub mod names;

use std::path::{Component, Path, PathBuf};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::episode::Goal;
use crate::failure::FailureKind;
use crate::faults::FaultKind;
use crate::plan::Plan;
use crate::runtime::substitute::{Substitution, glob_match};
use crate::sweep::{ScenarioResult, Summary, SweepConfig};
use crate::yaml::de::from_value;
use crate::yaml::diag::{Diagnostic, Issue, Loc, Sources};
use crate::yaml::suggest::did_you_mean;
use crate::yaml::value::{Value, decode_utf8, parse_yaml};

/// Most scenarios in one scenario file (suites are for CI; sweeps are for studies).
pub const MAX_COUNT: u64 = 100_000;
/// Most substitutions or node patterns in one scenario file.
pub const MAX_RULES: usize = 64;

/// The expected outcome of every scenario of a suite.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The episodes succeed (at least `min_success_rate` of them).
    #[default]
    Success,
    /// Every episode fails (a negative test: the tree must not claim success).
    Failure,
}

/// `expect:` — what must hold over the suite's scenarios.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// `success` (default) or `failure` (every scenario must fail).
    #[serde(default)]
    pub outcome: Outcome,
    /// With `outcome: success`: the smallest acceptable success rate, 0 … 1. Default 1 (every
    /// scenario succeeds).
    #[serde(default)]
    #[schemars(range(min = 0.0, max = 1.0))]
    pub min_success_rate: Option<f64>,
    /// With `outcome: failure`: every failure has this kind (`substituted`, `grasp_lost`,
    /// `timeout`, `condition_false`, …).
    #[serde(default)]
    pub failure_kind: Option<String>,
    /// With `outcome: failure`: every failure ends at a node matching this path glob.
    #[serde(default)]
    pub failed_node: Option<String>,
    /// Every scenario takes at most this much simulated time, seconds.
    #[serde(default)]
    #[schemars(range(min = 0.0, max = crate::episode::MAX_SIM_TIME_S))]
    pub max_sim_time: Option<f64>,
    /// Node path globs of which some node ran (was activated) at least once over the suite.
    #[serde(default)]
    pub ran: Vec<String>,
    /// Node path globs of which some node ran in every scenario.
    #[serde(default)]
    pub ran_in_every: Vec<String>,
    /// Node path globs of which some node failed at least once over the suite (e.g. the step a
    /// substitution makes fail, before the recovery runs).
    #[serde(default)]
    pub failed: Vec<String>,
    /// Node path globs whose nodes never ran over the suite.
    #[serde(default)]
    pub never_ran: Vec<String>,
    /// Node path globs whose nodes never failed over the suite.
    #[serde(default)]
    pub never_failed: Vec<String>,
    /// How many times the nodes matching a glob ran or failed: exactly, at least or at most,
    /// over the suite or in every scenario (see [`counts`]).
    #[serde(default)]
    pub counts: Vec<counts::CountExpect>,
}

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
}

const KEYS: &[&str] = &[
    "description",
    "tree",
    "scene",
    "count",
    "seed",
    "fault",
    "goal",
    "max_sim_time",
    "substitute",
    "expect",
];

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
    let id = sources.add(name, text.clone());
    if let Err(issue) = decode_utf8(&bytes, id) {
        return Err(sources.diagnostics(&[issue]));
    }
    let v = match parse_yaml(&text, id) {
        Ok(v) => v,
        Err(issue) => return Err(sources.diagnostics(&[issue])),
    };
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
                v.loc,
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
    // Not a scenario file at all: one issue, quoting one line.
    if !entries
        .iter()
        .any(|(k, _)| k.as_str().is_some_and(|k| KEYS.contains(&k)))
    {
        issues.push(
            Issue::new(
                v.loc,
                "this is not a scenario file: it has none of its keys (`tree:`, `count:`, `expect:`, …)",
            )
            .label("expected `tree:`, `count:` and `expect:`")
            .help("see docs/testing_trees.md"),
        );
        return None;
    }
    for (k, _) in entries {
        let key = k.as_str().unwrap_or("?");
        if !KEYS.contains(&key) {
            issues.push(
                Issue::new(k.loc, format!("unknown key `{key}` in a scenario file"))
                    .label(format!("expected one of {}", KEYS.join(", ")))
                    .maybe_help(did_you_mean(key, KEYS.iter().copied())),
            );
        }
    }
    if let Some(e) = v.get("expect").and_then(Value::as_map) {
        let allowed = [
            "outcome",
            "min_success_rate",
            "failure_kind",
            "failed_node",
            "max_sim_time",
            "ran",
            "ran_in_every",
            "failed",
            "never_ran",
            "never_failed",
            "counts",
        ];
        for (k, _) in e {
            let key = k.as_str().unwrap_or("?");
            if !allowed.contains(&key) {
                issues.push(
                    Issue::new(k.loc, format!("unknown key `{key}` in `expect:`"))
                        .label(format!("expected one of {}", allowed.join(", ")))
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
    let at = |keys: &[&str]| -> Loc {
        let mut cur = v;
        for k in keys {
            match cur.get(k) {
                Some(x) => cur = x,
                None => break,
            }
        }
        cur.loc
    };
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
    let patterns = e
        .ran
        .iter()
        .chain(&e.ran_in_every)
        .chain(&e.failed)
        .chain(&e.never_ran)
        .chain(&e.never_failed)
        .chain(&e.failed_node)
        .chain(e.counts.iter().map(|c| &c.node));
    for p in patterns {
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
        expect: raw.expect,
    })
}

impl ScenarioFile {
    /// Checks that every node pattern of `expect:` matches some node of `plan` (a pattern that
    /// matches nothing would pass or fail for the wrong reason).
    pub fn check_patterns(&self, plan: &Plan) -> Result<(), String> {
        let e = &self.expect;
        let lists: [(&str, &Vec<String>); 5] = [
            ("ran", &e.ran),
            ("ran_in_every", &e.ran_in_every),
            ("failed", &e.failed),
            ("never_ran", &e.never_ran),
            ("never_failed", &e.never_failed),
        ];
        let failed_node: Vec<String> = e.failed_node.iter().cloned().collect();
        let counted: Vec<String> = e.counts.iter().map(|c| c.node.clone()).collect();
        for (key, list) in lists
            .into_iter()
            .chain([("failed_node", &failed_node), ("counts", &counted)])
        {
            for p in list {
                if !plan.nodes.iter().any(|n| glob_match(p, &n.path)) {
                    return Err(format!(
                        "{}: `expect.{key}` pattern {p:?} matches no node of {}; `macrotree run {} --log-format json` lists the paths",
                        self.path.display(),
                        self.tree.display(),
                        self.tree.display()
                    ));
                }
            }
        }
        Ok(())
    }
}

/// One expectation, checked.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Checked {
    /// What was expected (`success rate ≥ 0.9`).
    pub expectation: String,
    /// It holds.
    pub ok: bool,
    /// What was measured.
    pub measured: String,
}

/// The outcome of one scenario file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SuiteOutcome {
    /// The scenario file.
    pub file: String,
    /// Its description.
    pub description: Option<String>,
    /// Every expectation holds.
    pub passed: bool,
    /// Each expectation with what was measured.
    pub checks: Vec<Checked>,
    /// The results' summary (as a sweep's).
    pub summary: Summary,
}

impl SuiteOutcome {
    /// Checks `file`'s expectations against `results` (all of its scenarios, or one shard's).
    pub fn new(file: &ScenarioFile, results: &[ScenarioResult], wall_time_s: f64, jobs: usize) -> Self {
        let summary = Summary::new(&file.sweep.tree, &file.sweep, results, wall_time_s, jobs);
        let checks = check(&file.expect, results, &summary);
        Self {
            file: file.path.display().to_string(),
            description: file.description.clone(),
            passed: checks.iter().all(|c| c.ok),
            checks,
            summary,
        }
    }
}

/// Checks `expect` against the results of a suite.
pub fn check(expect: &Expect, results: &[ScenarioResult], summary: &Summary) -> Vec<Checked> {
    let n = results.len() as u64;
    let mut out = Vec::new();
    if n == 0 {
        // An empty shard of a small suite: nothing to judge; the merged report judges the suite.
        out.push(Checked {
            expectation: "scenarios in this shard".into(),
            ok: true,
            measured: "none (the merged report judges the suite)".into(),
        });
        return out;
    }
    let ok_rate = summary.successes as f64 / (n.max(1)) as f64;
    match expect.outcome {
        Outcome::Success => {
            let min = expect.min_success_rate.unwrap_or(1.0);
            out.push(Checked {
                expectation: format!("success rate ≥ {min}"),
                ok: n > 0 && ok_rate >= min,
                measured: format!("{} of {n} succeeded ({:.3})", summary.successes, ok_rate),
            });
        }
        Outcome::Failure => {
            out.push(Checked {
                expectation: "every scenario fails".into(),
                ok: n > 0 && summary.successes == 0,
                measured: format!("{} of {n} succeeded", summary.successes),
            });
            if let Some(kind) = &expect.failure_kind {
                let other: Vec<String> = results
                    .iter()
                    .filter(|r| !r.success && r.failure_kind.map(FailureKind::as_str) != Some(kind.as_str()))
                    .map(|r| format!("#{} {}", r.index, r.failure_kind.unwrap_or(FailureKind::Other)))
                    .collect();
                out.push(Checked {
                    expectation: format!("every failure is of kind `{kind}`"),
                    ok: other.is_empty(),
                    measured: if other.is_empty() {
                        "yes".into()
                    } else {
                        format!("other kinds: {}", other.join(", "))
                    },
                });
            }
            if let Some(p) = &expect.failed_node {
                let other: Vec<String> = results
                    .iter()
                    .filter(|r| !r.success && !r.failed_node.as_deref().is_some_and(|n| glob_match(p, n)))
                    .map(|r| format!("#{} at {}", r.index, r.failed_node.as_deref().unwrap_or("-")))
                    .collect();
                out.push(Checked {
                    expectation: format!("every failure ends at `{p}`"),
                    ok: other.is_empty(),
                    measured: if other.is_empty() {
                        "yes".into()
                    } else {
                        other.join(", ")
                    },
                });
            }
        }
    }
    if let Some(t) = expect.max_sim_time {
        let worst = results.iter().map(|r| r.sim_time_s).fold(0.0, f64::max);
        out.push(Checked {
            expectation: format!("sim time ≤ {t} s"),
            ok: worst <= t,
            measured: format!("longest {worst:.2} s"),
        });
    }
    let sum = |p: &str, f: fn(&crate::sweep::NodeTotals) -> u64| -> u64 {
        summary
            .nodes
            .iter()
            .filter(|t| glob_match(p, &t.path))
            .map(f)
            .sum()
    };
    for p in &expect.ran {
        let a = sum(p, |t| t.activations);
        out.push(Checked {
            expectation: format!("`{p}` ran"),
            ok: a > 0,
            measured: format!("{a} activation(s)"),
        });
    }
    for p in &expect.ran_in_every {
        let missing: Vec<u64> = results
            .iter()
            .filter(|r| {
                !r.nodes
                    .iter()
                    .any(|nd| nd.counts.activations > 0 && glob_match(p, &nd.path))
            })
            .map(|r| r.index)
            .collect();
        out.push(Checked {
            expectation: format!("`{p}` ran in every scenario"),
            ok: missing.is_empty() && n > 0,
            measured: if missing.is_empty() {
                format!("ran in all {n}")
            } else {
                format!("not in scenario(s) {missing:?}")
            },
        });
    }
    for p in &expect.failed {
        let f = sum(p, |t| t.failures);
        out.push(Checked {
            expectation: format!("`{p}` failed at least once"),
            ok: f > 0,
            measured: format!("{f} failure(s)"),
        });
    }
    for p in &expect.never_ran {
        let a = sum(p, |t| t.activations);
        out.push(Checked {
            expectation: format!("`{p}` never ran"),
            ok: a == 0,
            measured: format!("{a} activation(s)"),
        });
    }
    for p in &expect.never_failed {
        let f = sum(p, |t| t.failures);
        out.push(Checked {
            expectation: format!("`{p}` never failed"),
            ok: f == 0,
            measured: format!("{f} failure(s)"),
        });
    }
    for c in &expect.counts {
        let (expectation, ok, measured) = c.check(results, summary);
        out.push(Checked {
            expectation,
            ok,
            measured,
        });
    }
    out
}

/// The reproduce commands of the scenarios that broke the expected outcome.
pub fn offending_commands(expect: &Expect, results: &[ScenarioResult], config: &SweepConfig) -> Vec<String> {
    results
        .iter()
        .filter(|r| {
            expect.counts.iter().any(|c| c.broken_by(r))
                || match expect.outcome {
                    Outcome::Success => !r.success,
                    Outcome::Failure => {
                        r.success
                            || expect
                                .failure_kind
                                .as_deref()
                                .is_some_and(|k| r.failure_kind.map(FailureKind::as_str) != Some(k))
                            || expect
                                .failed_node
                                .as_deref()
                                .is_some_and(|p| !r.failed_node.as_deref().is_some_and(|n| glob_match(p, n)))
                    }
                }
        })
        .map(|r| r.reproduce(&config.tree, config))
        .collect()
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

/// The scenario files named by `paths`: files as given, folders searched (recursively) for
/// `*.yaml` / `*.yml`, sorted by path; an empty list when a folder has none.
pub fn find_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    for p in paths {
        let meta = std::fs::metadata(p).map_err(|e| format!("{}: {e}", p.display()))?;
        if meta.is_dir() {
            walk(p, &mut out, 0)?;
        } else {
            out.push(p.clone());
        }
    }
    out.sort();
    out.dedup();
    Ok(out)
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>, depth: usize) -> Result<(), String> {
    if depth > 8 {
        return Err(format!(
            "{}: folders nested too deep (more than 8)",
            dir.display()
        ));
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for p in entries {
        let ft = std::fs::symlink_metadata(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        if ft.is_dir() {
            walk(&p, out, depth + 1)?;
        } else if matches!(p.extension().and_then(|e| e.to_str()), Some("yaml" | "yml")) {
            out.push(p);
        }
    }
    Ok(())
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
