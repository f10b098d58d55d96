//! [`Summary`]: what a sweep found — success rate with a Wilson interval, attempts, sim-time
//! percentiles, throughput and every failure with the command that reproduces it.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use super::ScenarioResult;
use super::timing::Total;
use crate::episode::Goal;
use crate::faults::FaultKind;

/// Most failing scenarios the text summary shows (like `macrotree test`).
pub const MAX_FAILURES_SHOWN: usize = 20;

fn is_zero(n: &u64) -> bool {
    *n == 0
}

/// z for a two-sided 95% interval.
const Z95: f64 = 1.959_963_984_540_054;

/// One failing scenario.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Failure {
    /// Scenario index.
    pub index: u64,
    /// Episode seed.
    pub seed: u64,
    /// Cube x, y (metres), yaw (degrees): the built-in scene's layout.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cube: Option<[f64; 3]>,
    /// Bowl x, y (metres): the built-in scene's layout.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bowl: Option<[f64; 2]>,
    /// The node whose failure ended the episode.
    pub node: Option<String>,
    /// The kind of failure (`timeout`, `grasp_lost`, …; serialized as its name).
    pub kind: Option<crate::failure::FailureKind>,
    /// Contacts that should not happen, by name (`the fingers hit bin wall`).
    pub collisions: Vec<String>,
    /// Why it failed.
    pub reason: String,
    /// Grasp attempts made.
    pub grasp_attempts: u32,
    /// The `macrotree run …` command that reproduces it.
    pub reproduce: String,
}

/// The summary of a sweep (`--json` prints it as the only thing on stdout).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// The tree file, as given.
    pub tree: String,
    /// Sweep seed S.
    pub seed: u64,
    /// The injected fault.
    pub fault: Option<FaultKind>,
    /// What counted as success.
    pub goal: Goal,
    /// The shard run, `K/M`, if any.
    pub shard: Option<String>,
    /// Worker threads.
    pub jobs: usize,
    /// Scenarios run.
    pub scenarios: u64,
    /// Scenarios that succeeded.
    pub successes: u64,
    /// successes / scenarios (0 when no scenario ran).
    pub success_rate: f64,
    /// 95% Wilson score interval of the success rate, [low, high].
    pub success_rate_ci95: [f64; 2],
    /// Number of scenarios by physical grasp attempts made (JSON keys are the attempt counts):
    /// a grasp answered by a substitution never reaches the arm and is not counted; its node's
    /// `activations` in `nodes` count it.
    pub attempts_histogram: BTreeMap<u32, u64>,
    /// Median simulated time over all scenarios (nearest rank), seconds.
    pub median_sim_time_s: f64,
    /// 95th percentile of the simulated time over all scenarios (nearest rank), seconds.
    pub p95_sim_time_s: f64,
    /// Wall-clock time of the sweep, seconds.
    pub wall_time_s: f64,
    /// Scenarios per minute of wall-clock time.
    pub scenarios_per_minute: f64,
    /// Wall-clock time the workers spent inside `mj_step`, summed over workers, seconds (`None`
    /// until [`Summary::with_timing`] sets it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub physics_time_s: Option<f64>,
    /// Wall-clock time of the whole process up to the end of the sweep (start-up, loading and
    /// compiling the model included), seconds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub process_wall_time_s: Option<f64>,
    /// `physics_time_s / (jobs × process_wall_time_s)`: the share of the workers' time that was
    /// physics (1 would be a sweep that does nothing but `mj_step`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub physics_share: Option<f64>,
    /// Motions checked and planned over the sweep.
    pub planning: PlanningTotals,
    /// Contacts that should not happen over the sweep, by kind (`fingers-container`, …).
    pub collisions: crate::episode::CollisionCounts,
    /// What success was judged by, e.g. `the tree's result only (the scene declares no goal)`
    /// for `--goal scene` on a scene without a goal.
    pub goal_checked: String,
    /// Wall-clock time the workers spent checking and planning motions, summed over workers,
    /// seconds (`None` until [`Summary::with_timing`] sets it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub planning_time_s: Option<f64>,
    /// `planning_time_s / (jobs × process_wall_time_s)`: the share of the workers' time
    /// spent checking and planning motions, beside [`physics_share`](Self::physics_share).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub planning_share: Option<f64>,
    /// The failing scenarios, by index: the first [`super::tally::MAX_FAILURES_KEPT`] (the
    /// JSONL has every one).
    pub failures: Vec<Failure>,
    /// Failing scenarios not listed in `failures` (absent when 0).
    #[serde(skip_serializing_if = "is_zero")]
    pub failures_not_listed: u64,
    /// Failures grouped by (node path, failure kind), most frequent first.
    pub failure_groups: Vec<FailureGroup>,
    /// Substitutions applied in every scenario (`PATTERN=OUTCOME`).
    pub substitutions: Vec<String>,
    /// Every node's counts summed over the scenarios, in plan order.
    pub nodes: Vec<NodeTotals>,
    /// Tree coverage: which nodes never ran, never succeeded, never failed over the sweep.
    pub coverage: Coverage,
}

/// Motion checking and planning summed over a sweep's scenarios.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct PlanningTotals {
    /// Leaf motions checked along their length.
    pub motions_checked: u64,
    /// Motions that went to the planner (their direct motion would have collided).
    pub plans: u64,
    /// Plans that failed.
    pub plan_failures: u64,
    /// Scenarios in which the planner ran at least once.
    pub scenarios_planned: u64,
    /// Wall-clock time the workers spent checking and planning, summed, seconds (written as the
    /// summary's `planning_time_s`, a measurement beside `physics_time_s`, not a result).
    #[serde(skip)]
    pub wall_time_s: f64,
}

impl PlanningTotals {
    /// Adds one scenario's counts and time.
    pub fn add(&mut self, r: &ScenarioResult) {
        self.motions_checked += u64::from(r.planning.motions_checked);
        self.plans += u64::from(r.planning.plans);
        self.plan_failures += u64::from(r.planning.plan_failures);
        self.scenarios_planned += u64::from(r.planning.plans > 0);
        self.wall_time_s += r.planning_wall_s;
    }
}

/// One node's counts summed over a sweep.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct NodeTotals {
    /// The node path.
    pub path: String,
    /// Scenarios in which the node was activated at least once.
    pub scenarios_ran: u64,
    /// Activations over all scenarios.
    pub activations: u64,
    /// Successes over all scenarios.
    pub successes: u64,
    /// Failures over all scenarios.
    pub failures: u64,
    /// Halts over all scenarios.
    pub halts: u64,
}

/// Tree coverage over a sweep ("which branches never ran").
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Default)]
pub struct Coverage {
    /// Nodes in the tree.
    pub nodes: u64,
    /// Nodes activated in at least one scenario.
    pub ran: u64,
    /// Paths of the nodes never activated, plan order.
    pub never_ran: Vec<String>,
    /// Paths of the nodes that ran but never succeeded.
    pub never_succeeded: Vec<String>,
    /// Paths of the nodes that ran but never failed.
    pub never_failed: Vec<String>,
}

/// Failures that share the node that failed and the kind of failure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailureGroup {
    /// The node path (`-` when no node failed, e.g. the time limit or a missed goal).
    pub node: String,
    /// The kind of failure.
    pub kind: String,
    /// How many scenarios.
    pub count: u64,
    /// The scenario indices, ascending: the first [`super::tally::MAX_GROUP_INDICES`] of
    /// `count`.
    pub indices: Vec<u64>,
}

impl Summary {
    /// Adds how long the sweep took, from its run's (or merged runs') [`Total`]: wall time
    /// and jobs, scenarios per minute, and how much of the workers' time (jobs × the whole
    /// process's wall time) was physics (`mj_step`) and motion planning.
    #[must_use]
    pub fn with_timing(mut self, t: &Total) -> Self {
        self.jobs = t.jobs;
        self.wall_time_s = t.wall_time_s;
        self.scenarios_per_minute = if t.wall_time_s > 0.0 {
            self.scenarios as f64 * 60.0 / t.wall_time_s
        } else {
            0.0
        };
        let share = |x: f64| {
            if t.worker_time_s > 0.0 {
                x / t.worker_time_s
            } else {
                0.0
            }
        };
        self.physics_time_s = Some(t.physics_time_s);
        self.process_wall_time_s = Some(if t.jobs > 0 {
            t.worker_time_s / t.jobs as f64
        } else {
            0.0
        });
        self.physics_share = Some(share(t.physics_time_s));
        self.planning_time_s = Some(t.planning_time_s);
        self.planning_share = Some(share(t.planning_time_s));
        self
    }

    /// Every scenario run succeeded (true for an empty shard).
    pub fn all_succeeded(&self) -> bool {
        self.successes == self.scenarios
    }

    /// The summary for people, several lines.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let [lo, hi] = self.success_rate_ci95;
        let _ = writeln!(
            s,
            "{} of {} scenarios succeeded: {:.2}% (95% CI {:.2}–{:.2}%), seed {}{}{}{}",
            self.successes,
            self.scenarios,
            self.success_rate * 100.0,
            lo * 100.0,
            hi * 100.0,
            self.seed,
            self.fault.map_or(String::new(), |f| format!(", fault {f}")),
            if self.goal == Goal::default() {
                String::new()
            } else {
                format!(", goal {}", self.goal.name())
            },
            self.shard
                .as_ref()
                .map_or(String::new(), |k| format!(", shard {k}")),
        );
        let hist: Vec<String> = self
            .attempts_histogram
            .iter()
            .map(|(a, c)| format!("{a}: {c}"))
            .collect();
        // Substituted leaves never reach the arm: the histogram counts physical grasps only.
        let label = if self.substitutions.is_empty() {
            "grasp attempts"
        } else {
            "grasp attempts (physical only; grasps answered by a substitution are not counted)"
        };
        let _ = writeln!(s, "  {label}: {}", hist.join(", "));
        let _ = writeln!(
            s,
            "  sim time: median {:.2} s, p95 {:.2} s",
            self.median_sim_time_s, self.p95_sim_time_s
        );
        if self.jobs == 0 {
            // `macrotree report` without timing files: the lines carry results only (they are
            // the same bytes for any machine and `--jobs`), not the time they took.
            let _ = writeln!(
                s,
                "  wall time, physics and planning shares: unknown (not every file has its FILE.timing.json, written by `sweep --out`, beside it)"
            );
        } else {
            let _ = writeln!(
                s,
                "  wall time {:.1} s on {} job(s): {:.0} scenarios/minute",
                self.wall_time_s, self.jobs, self.scenarios_per_minute
            );
        }
        if !self.substitutions.is_empty() {
            let _ = writeln!(s, "  substitutions: {}", self.substitutions.join(", "));
        }
        let c = &self.coverage;
        if c.nodes > 0 {
            let _ = writeln!(
                s,
                "  tree coverage: {} of {} nodes ran; {} never succeeded, {} never failed",
                c.ran,
                c.nodes,
                c.never_succeeded.len(),
                c.never_failed.len()
            );
            for p in c.never_ran.iter().take(20) {
                let _ = writeln!(s, "    never ran: {p}");
            }
            if c.never_ran.len() > 20 {
                let _ = writeln!(s, "    … and {} more (see --json)", c.never_ran.len() - 20);
            }
        }
        if let (Some(share), Some(physics), Some(process)) =
            (self.physics_share, self.physics_time_s, self.process_wall_time_s)
        {
            let _ = writeln!(
                s,
                "  physics share {:.3}: {physics:.2} s inside mj_step over {} job(s) × {process:.2} s of the whole process",
                share, self.jobs
            );
        }
        if let (Some(share), Some(time)) = (self.planning_share, self.planning_time_s) {
            let p = &self.planning;
            let _ = writeln!(
                s,
                "  planning share {share:.4}: {time:.3} s checking {} motions and planning {} ({} failed, in {} scenario(s))",
                p.motions_checked, p.plans, p.plan_failures, p.scenarios_planned
            );
        }
        if self.goal_checked.contains("no goal") {
            let _ = writeln!(s, "  success judged by {}", self.goal_checked);
        }
        let _ = writeln!(s, "  collisions: {}", self.collisions.line());
        if !self.failure_groups.is_empty() {
            let _ = writeln!(s, "  failures by node and kind:");
            for g in &self.failure_groups {
                let _ = writeln!(s, "    {:>5}  {}  {}", g.count, g.kind, g.node);
            }
        }
        if !self.failures.is_empty() {
            let total = self.failures.len() as u64 + self.failures_not_listed;
            let _ = writeln!(s, "  failures ({total}):");
            for f in self.failures.iter().take(MAX_FAILURES_SHOWN) {
                let _ = writeln!(s, "    #{}: {}", f.index, f.reason);
                if !f.collisions.is_empty() {
                    let _ = writeln!(s, "      collisions: {}", f.collisions.join("; "));
                }
                let _ = writeln!(s, "      {}", f.reproduce);
            }
            let more = total.saturating_sub(MAX_FAILURES_SHOWN as u64);
            if more > 0 {
                let _ = writeln!(s, "    … and {more} more (see --out or --json)");
            }
        }
        s
    }
}

/// The 95% Wilson score interval of `successes` out of `n`, [low, high] ([0, 1] when `n` is 0).
pub fn wilson_interval(successes: u64, n: u64) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let n = n as f64;
    let p = successes as f64 / n;
    let z2 = Z95 * Z95;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = Z95 * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / denom;
    // At 0 or n successes the bound is exactly 0 or 1 (rounding would leave 1 − ε).
    let lo = if successes == 0 {
        0.0
    } else {
        (centre - half).max(0.0)
    };
    let hi = if successes as f64 == n {
        1.0
    } else {
        (centre + half).min(1.0)
    };
    [lo, hi]
}

/// The nearest-rank `q`-quantile (0 < q ≤ 1) of `sorted` (ascending); 0 when empty.
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = (q * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_matches_known_values() {
        // 95 of 100: the textbook interval is [0.8883, 0.9785].
        let [lo, hi] = wilson_interval(95, 100);
        assert!(
            (lo - 0.8883).abs() < 1e-4 && (hi - 0.9785).abs() < 1e-4,
            "{lo} {hi}"
        );
        let [lo, hi] = wilson_interval(10, 10);
        assert!((lo - 0.7225).abs() < 1e-4 && hi == 1.0, "{lo} {hi}");
        assert_eq!(wilson_interval(0, 0), [0.0, 1.0]);
    }

    #[test]
    fn nearest_rank_percentiles() {
        let v: Vec<f64> = (1..=20).map(f64::from).collect();
        assert_eq!(percentile(&v, 0.5), 10.0);
        assert_eq!(percentile(&v, 0.95), 19.0);
        assert_eq!(percentile(&[3.0], 0.95), 3.0);
        assert_eq!(percentile(&[], 0.5), 0.0);
    }
}
