//! Count expectations of scenario files (`expect: counts:`): how many times the nodes matching a
//! path glob ran or failed — exactly, at least or at most — over the whole suite or in every
//! scenario.
//!
//! ```yaml
//! expect:
//!   counts:
//!     - {node: "main/**/carry", failed: {exactly: 3}}                # 3 failures over the suite
//!     - {node: "main/**/grasp", ran: {exactly: 2}, per: scenario}    # twice in every scenario
//!     - {node: "main/**/release", ran: {at_least: 1, at_most: 4}, per: scenario}
//! ```

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::runtime::substitute::glob_match;
use crate::sweep::{ScenarioResult, Summary};

/// The largest count an expectation may name.
pub const MAX_BOUND: u64 = 1_000_000_000;

/// Bounds on a count: `exactly`, or `at_least` and/or `at_most`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Bounds {
    /// The count is exactly this (0 … 1e9).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0, max = 1_000_000_000))]
    pub exactly: Option<u64>,
    /// The count is at least this (0 … 1e9).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0, max = 1_000_000_000))]
    pub at_least: Option<u64>,
    /// The count is at most this (0 … 1e9).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0, max = 1_000_000_000))]
    pub at_most: Option<u64>,
}

impl Bounds {
    /// `n` is within the bounds.
    pub fn holds(&self, n: u64) -> bool {
        self.exactly.is_none_or(|e| n == e)
            && self.at_least.is_none_or(|l| n >= l)
            && self.at_most.is_none_or(|m| n <= m)
    }

    /// What is wrong with the bounds themselves, if anything.
    pub fn problem(&self) -> Option<String> {
        let all = [self.exactly, self.at_least, self.at_most];
        if all.iter().all(Option::is_none) {
            return Some("give `exactly`, `at_least` or `at_most`".into());
        }
        if self.exactly.is_some() && (self.at_least.is_some() || self.at_most.is_some()) {
            return Some("`exactly` goes alone, without `at_least` or `at_most`".into());
        }
        if let Some(big) = all.iter().flatten().find(|&&n| n > MAX_BOUND) {
            return Some(format!("a count must be at most {MAX_BOUND}, got {big}"));
        }
        if let (Some(l), Some(m)) = (self.at_least, self.at_most)
            && l > m
        {
            return Some(format!("`at_least` ({l}) is more than `at_most` ({m})"));
        }
        None
    }

    fn describe(&self) -> String {
        match (self.exactly, self.at_least, self.at_most) {
            (Some(e), _, _) => format!("exactly {e}"),
            (None, Some(l), Some(m)) => format!("{l} to {m}"),
            (None, Some(l), None) => format!("at least {l}"),
            (None, None, Some(m)) => format!("at most {m}"),
            (None, None, None) => "any number of".into(),
        }
    }
}

/// Over what a count is taken.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Per {
    /// The total over all the suite's scenarios (a shard judges nothing: its merged report does).
    #[default]
    Suite,
    /// The count in each scenario; the bounds must hold in every one.
    Scenario,
}

/// One count expectation: the nodes matching `node` ran (or failed) a number of times within the
/// bounds. Give exactly one of `ran` and `failed`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CountExpect {
    /// A node path glob (as in `ran:`); the count adds up every node it matches.
    pub node: String,
    /// Bounds on the activations (starts) of the matching nodes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ran: Option<Bounds>,
    /// Bounds on the failures of the matching nodes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failed: Option<Bounds>,
    /// `suite` (default): the total over all scenarios; `scenario`: in every scenario.
    #[serde(default)]
    pub per: Per,
}

impl CountExpect {
    /// What is wrong with the expectation itself (which bounds, or both or neither of `ran` and
    /// `failed`), with the key it is about.
    pub fn problem(&self) -> Option<(&'static str, String)> {
        match (&self.ran, &self.failed) {
            (Some(_), Some(_)) => Some((
                "failed",
                "give one of `ran` and `failed` per entry (add a second entry for the other)".into(),
            )),
            (None, None) => Some(("node", "give `ran: {…}` or `failed: {…}` with the node".into())),
            (Some(b), None) => b.problem().map(|p| ("ran", p)),
            (None, Some(b)) => b.problem().map(|p| ("failed", p)),
        }
    }

    fn metric(&self) -> (&'static str, Bounds) {
        match (self.ran, self.failed) {
            (_, Some(b)) => ("failed", b),
            (Some(b), None) => ("ran", b),
            (None, None) => ("ran", Bounds::default()),
        }
    }

    /// Checks the expectation against a suite's `results` and their `summary`: `(expectation,
    /// holds, measured)`.
    pub fn check(&self, results: &[ScenarioResult], summary: &Summary) -> (String, bool, String) {
        let (metric, bounds) = self.metric();
        let verb = if metric == "failed" { "failed" } else { "ran" };
        let pick = |c: &crate::runtime::NodeCounts| {
            u64::from(if metric == "failed" {
                c.failures
            } else {
                c.activations
            })
        };
        match self.per {
            Per::Suite => {
                let expectation = format!(
                    "`{}` {verb} {} time(s) over the suite",
                    self.node,
                    bounds.describe()
                );
                let total: u64 = summary
                    .nodes
                    .iter()
                    .filter(|t| glob_match(&self.node, &t.path))
                    .map(|t| {
                        if metric == "failed" {
                            t.failures
                        } else {
                            t.activations
                        }
                    })
                    .sum();
                if summary.shard.is_some() {
                    return (
                        expectation,
                        true,
                        format!("{total} in this shard (the merged report judges the total)"),
                    );
                }
                (expectation, bounds.holds(total), format!("{total}"))
            }
            Per::Scenario => {
                let expectation = format!(
                    "`{}` {verb} {} time(s) in every scenario",
                    self.node,
                    bounds.describe()
                );
                let counts: Vec<(u64, u64)> = results
                    .iter()
                    .map(|r| {
                        let n = r
                            .outcome
                            .nodes
                            .iter()
                            .filter(|nd| glob_match(&self.node, &nd.path))
                            .map(|nd| pick(&nd.counts))
                            .sum();
                        (r.index, n)
                    })
                    .collect();
                let off: Vec<String> = counts
                    .iter()
                    .filter(|(_, n)| !bounds.holds(*n))
                    .map(|(i, n)| format!("#{i}: {n}"))
                    .collect();
                let (lo, hi) = counts
                    .iter()
                    .fold((u64::MAX, 0), |(lo, hi), (_, n)| (lo.min(*n), hi.max(*n)));
                let measured = if off.is_empty() {
                    if lo == hi {
                        format!("{lo} in each of {}", counts.len())
                    } else {
                        format!("{lo} to {hi}")
                    }
                } else {
                    let shown: Vec<&str> = off.iter().take(10).map(String::as_str).collect();
                    format!(
                        "{} scenario(s) outside: {}{}",
                        off.len(),
                        shown.join(", "),
                        if off.len() > 10 { ", …" } else { "" }
                    )
                };
                (expectation, off.is_empty() && !counts.is_empty(), measured)
            }
        }
    }

    /// Whether scenario `r` breaks this expectation (for its reproduce command); suite totals
    /// are not any one scenario's.
    pub fn broken_by(&self, r: &ScenarioResult) -> bool {
        if self.per != Per::Scenario {
            return false;
        }
        let (metric, bounds) = self.metric();
        let n: u64 = r
            .outcome
            .nodes
            .iter()
            .filter(|nd| glob_match(&self.node, &nd.path))
            .map(|nd| {
                u64::from(if metric == "failed" {
                    nd.counts.failures
                } else {
                    nd.counts.activations
                })
            })
            .sum();
        !bounds.holds(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_hold_and_refuse_contradictions() {
        let b = |e, l, m| Bounds {
            exactly: e,
            at_least: l,
            at_most: m,
        };
        assert!(b(Some(3), None, None).holds(3));
        assert!(!b(Some(3), None, None).holds(2));
        assert!(b(None, Some(1), Some(4)).holds(4) && !b(None, Some(1), Some(4)).holds(5));
        assert!(!b(None, Some(1), None).holds(0));
        assert!(b(None, None, None).problem().is_some());
        assert!(b(Some(1), Some(1), None).problem().is_some());
        assert!(b(None, Some(5), Some(4)).problem().unwrap().contains("more than"));
        assert!(b(None, None, Some(MAX_BOUND + 1)).problem().is_some());
        assert!(b(None, Some(0), Some(0)).problem().is_none());
    }
}
