//! Expectations (`expect:`) and checking them over a suite's results.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{ScenarioFile, counts};
use crate::failure::FailureKind;
use crate::runtime::substitute::glob_match;
use crate::sweep::{ScenarioResult, Summary, SweepConfig};

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
    /// At most this many contacts that should not happen over the suite (each counted once per
    /// scenario, see `docs/sweep.md`); `0`: none at all.
    #[serde(default)]
    #[schemars(range(min = 0, max = 1_000_000_000))]
    pub max_collisions: Option<u64>,
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
    /// over the suite or in every scenario.
    #[serde(default)]
    pub counts: Vec<counts::CountExpect>,
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
                    .filter(|r| {
                        !r.outcome.success
                            && r.outcome.failure_kind.map(FailureKind::as_str) != Some(kind.as_str())
                    })
                    .map(|r| {
                        format!(
                            "#{} {}",
                            r.index,
                            r.outcome.failure_kind.unwrap_or(FailureKind::Other)
                        )
                    })
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
                    .filter(|r| {
                        !r.outcome.success
                            && !r.outcome.failed_node.as_deref().is_some_and(|n| glob_match(p, n))
                    })
                    .map(|r| {
                        format!(
                            "#{} at {}",
                            r.index,
                            r.outcome.failed_node.as_deref().unwrap_or("-")
                        )
                    })
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
        let worst = results.iter().map(|r| r.outcome.sim_time_s).fold(0.0, f64::max);
        out.push(Checked {
            expectation: format!("sim time ≤ {t} s"),
            ok: worst <= t,
            measured: format!("longest {worst:.2} s"),
        });
    }
    if let Some(max) = expect.max_collisions {
        let c = &summary.collisions;
        out.push(Checked {
            expectation: format!("at most {max} collision(s)"),
            ok: c.total <= max,
            measured: c.line(),
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
                !r.outcome
                    .nodes
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
                || expect
                    .max_collisions
                    .is_some_and(|max| !r.outcome.collisions.is_empty() && too_many_collisions(max, results))
                || match expect.outcome {
                    Outcome::Success => !r.outcome.success,
                    Outcome::Failure => {
                        r.outcome.success
                            || expect
                                .failure_kind
                                .as_deref()
                                .is_some_and(|k| r.outcome.failure_kind.map(FailureKind::as_str) != Some(k))
                            || expect.failed_node.as_deref().is_some_and(|p| {
                                !r.outcome.failed_node.as_deref().is_some_and(|n| glob_match(p, n))
                            })
                    }
                }
        })
        .map(|r| r.reproduce(&config.tree, config))
        .collect()
}

/// More than `max` collisions over `results`.
fn too_many_collisions(max: u64, results: &[ScenarioResult]) -> bool {
    results
        .iter()
        .map(|r| r.outcome.collisions.len() as u64)
        .sum::<u64>()
        > max
}
