//! [`Tally`]: a sweep's summary built one result at a time, in memory that does not grow with
//! the number of scenarios (so a sweep of 10⁷ scenarios, or `--resume` of its file, never holds
//! its results).
//!
//! What it keeps:
//!
//! - counts (scenarios, successes, grasp attempts by count, node counts by node path);
//! - the simulated times as a histogram of exact values: an episode's simulated time is a whole
//!   number of control periods (4 ms) up to `--max-sim-time` (at most 3600 s), so there are at
//!   most 900 001 distinct values however many scenarios run, and the nearest-rank median and
//!   95th percentile are exact;
//! - the first [`MAX_FAILURES_KEPT`] failing scenarios (with their reproduction commands) and,
//!   per group of failures (node, kind), its count and its first [`MAX_GROUP_INDICES`] indices.
//!   The JSONL keeps every one.

use std::collections::{BTreeMap, HashMap};

use super::summary::{Coverage, Failure, FailureGroup, NodeTotals, PlanningTotals, Summary, wilson_interval};
use super::{ScenarioResult, Shard, SweepConfig};

/// Most failing scenarios a summary lists (its JSON `failures`); `failures_not_listed` counts
/// the rest.
pub const MAX_FAILURES_KEPT: usize = 1000;
/// Most scenario indices a failure group lists (its `count` counts them all).
pub const MAX_GROUP_INDICES: usize = 1000;

/// A summary being built (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct Tally {
    tree: String,
    config: SweepConfig,
    n: u64,
    successes: u64,
    attempts: BTreeMap<u32, u64>,
    /// Simulated times (by an order-preserving key of their bits) → scenarios.
    times: BTreeMap<u64, u64>,
    failures: Vec<Failure>,
    failures_total: u64,
    groups: BTreeMap<(String, String), (u64, Vec<u64>)>,
    nodes: Vec<NodeTotals>,
    node_at: HashMap<String, usize>,
    planning: PlanningTotals,
    collisions: crate::episode::CollisionCounts,
    /// Some result had scene goal predicates.
    scene_goal_seen: bool,
}

/// A key that orders like [`f64::total_cmp`].
fn order_key(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 { !b } else { b | (1 << 63) }
}

fn from_key(k: u64) -> f64 {
    f64::from_bits(if k >> 63 == 1 { k & !(1 << 63) } else { !k })
}

impl Tally {
    /// An empty tally of a sweep of `tree` with `config`.
    pub fn new(tree: &str, config: &SweepConfig) -> Self {
        Self {
            tree: tree.to_string(),
            config: config.clone(),
            n: 0,
            successes: 0,
            attempts: BTreeMap::new(),
            times: BTreeMap::new(),
            failures: Vec::new(),
            failures_total: 0,
            groups: BTreeMap::new(),
            nodes: Vec::new(),
            node_at: HashMap::new(),
            planning: PlanningTotals::default(),
            collisions: Default::default(),
            scene_goal_seen: false,
        }
    }

    /// Scenarios added.
    pub fn len(&self) -> u64 {
        self.n
    }

    /// No scenario added yet.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Adds one result (any order; the failures listed are the first ones added).
    pub fn add(&mut self, r: &ScenarioResult) {
        self.n += 1;
        self.successes += u64::from(r.outcome.success);
        self.planning.add(r);
        self.collisions.add(&r.outcome.collisions);
        self.scene_goal_seen |= !r.outcome.goal.is_empty();
        *self.attempts.entry(r.outcome.grasp_attempts).or_insert(0) += 1;
        *self.times.entry(order_key(r.outcome.sim_time_s)).or_insert(0) += 1;
        for node in &r.outcome.nodes {
            let i = match self.node_at.get(&node.path) {
                Some(&i) => i,
                None => {
                    self.nodes.push(NodeTotals {
                        path: node.path.clone(),
                        scenarios_ran: 0,
                        activations: 0,
                        successes: 0,
                        failures: 0,
                        halts: 0,
                    });
                    self.node_at.insert(node.path.clone(), self.nodes.len() - 1);
                    self.nodes.len() - 1
                }
            };
            let t = &mut self.nodes[i];
            let c = &node.counts;
            t.scenarios_ran += u64::from(c.activations > 0);
            t.activations += u64::from(c.activations);
            t.successes += u64::from(c.successes);
            t.failures += u64::from(c.failures);
            t.halts += u64::from(c.halts);
        }
        if r.outcome.success {
            return;
        }
        self.failures_total += 1;
        let key = (
            r.outcome.failed_node.clone().unwrap_or_else(|| "-".into()),
            r.outcome
                .failure_kind
                .unwrap_or(crate::failure::FailureKind::Other)
                .to_string(),
        );
        let group = self.groups.entry(key).or_default();
        group.0 += 1;
        if group.1.len() < MAX_GROUP_INDICES {
            group.1.push(r.index);
        }
        if self.failures.len() < MAX_FAILURES_KEPT {
            self.failures.push(Failure {
                index: r.index,
                seed: r.seed,
                cube: r.layout.map(|l| l.cube),
                bowl: r.layout.map(|l| l.bowl),
                node: r.outcome.failed_node.clone(),
                kind: r.outcome.failure_kind,
                collisions: r.outcome.collisions.iter().map(|c| c.what.clone()).collect(),
                reason: r
                    .outcome
                    .failure_reason
                    .clone()
                    .unwrap_or_else(|| "failed".into()),
                grasp_attempts: r.outcome.grasp_attempts,
                reproduce: r.reproduce(&self.tree, &self.config),
            });
        }
    }

    /// The nearest-rank `q`-quantile of the simulated times (0 when empty).
    fn quantile(&self, q: f64) -> f64 {
        if self.n == 0 {
            return 0.0;
        }
        let rank = ((q * self.n as f64).ceil() as u64).clamp(1, self.n);
        let mut seen = 0;
        for (&k, &c) in &self.times {
            seen += c;
            if seen >= rank {
                return from_key(k);
            }
        }
        0.0
    }

    /// The summary of the results added, for a sweep that took `wall_time_s` on `jobs` workers.
    pub fn finish(mut self, wall_time_s: f64, jobs: usize) -> Summary {
        let n = self.n;
        self.failures.sort_by_key(|f| f.index);
        let mut failure_groups: Vec<FailureGroup> = std::mem::take(&mut self.groups)
            .into_iter()
            .map(|((node, kind), (count, mut indices))| {
                indices.sort_unstable();
                FailureGroup {
                    node,
                    kind,
                    count,
                    indices,
                }
            })
            .collect();
        failure_groups.sort_by_key(|g| std::cmp::Reverse(g.count));
        let totals = &self.nodes;
        let paths = |f: &dyn Fn(&NodeTotals) -> bool| -> Vec<String> {
            totals.iter().filter(|t| f(t)).map(|t| t.path.clone()).collect()
        };
        let coverage = Coverage {
            nodes: totals.len() as u64,
            ran: totals.iter().filter(|t| t.activations > 0).count() as u64,
            never_ran: paths(&|t| t.activations == 0),
            never_succeeded: paths(&|t| t.activations > 0 && t.successes == 0),
            never_failed: paths(&|t| t.activations > 0 && t.failures == 0),
        };
        let failures_not_listed = self.failures_total - self.failures.len() as u64;
        Summary {
            median_sim_time_s: self.quantile(0.5),
            p95_sim_time_s: self.quantile(0.95),
            tree: self.tree,
            seed: self.config.seed,
            fault: self.config.fault,
            goal: self.config.goal,
            shard: self.config.shard.as_ref().map(Shard::to_string),
            jobs,
            scenarios: n,
            successes: self.successes,
            success_rate: if n == 0 {
                0.0
            } else {
                self.successes as f64 / n as f64
            },
            success_rate_ci95: wilson_interval(self.successes, n),
            attempts_histogram: self.attempts,
            wall_time_s,
            scenarios_per_minute: if wall_time_s > 0.0 {
                n as f64 * 60.0 / wall_time_s
            } else {
                0.0
            },
            failures: self.failures,
            failures_not_listed,
            failure_groups,
            substitutions: self.config.substitutions.iter().map(|s| s.to_string()).collect(),
            nodes: self.nodes,
            coverage,
            physics_time_s: None,
            process_wall_time_s: None,
            physics_share: None,
            planning: self.planning,
            collisions: self.collisions,
            goal_checked: if self.config.goal == crate::episode::Goal::Scene && n > 0 && !self.scene_goal_seen
            {
                crate::episode::Goal::Scene.checked(&Default::default())
            } else {
                match self.config.goal {
                    crate::episode::Goal::Scene => "the tree's result and the scene's goal".into(),
                    g => g.checked(&Default::default()),
                }
            },
            planning_time_s: None,
            planning_share: None,
        }
    }
}

impl Summary {
    /// Summarizes `results` of a sweep of `tree` with `config` that took `wall_time_s` on `jobs` workers.
    pub fn new(
        tree: &str,
        config: &SweepConfig,
        results: &[ScenarioResult],
        wall_time_s: f64,
        jobs: usize,
    ) -> Self {
        let mut tally = Tally::new(tree, config);
        for r in results {
            tally.add(r);
        }
        tally.finish(wall_time_s, jobs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_keys_sort_like_total_cmp_and_round_trip() {
        let xs = [-3.5, -0.0, 0.0, 1e-300, 0.004, 6.128, 3600.0, f64::INFINITY];
        for w in xs.windows(2) {
            assert!(order_key(w[0]) < order_key(w[1]), "{w:?}");
        }
        for x in xs {
            assert_eq!(from_key(order_key(x)).to_bits(), x.to_bits());
        }
    }
}
