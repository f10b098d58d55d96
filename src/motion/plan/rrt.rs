//! RRT-Connect (Kuffner & LaValle 2000) from one start to a set of goals: two trees, one rooted
//! at the start and one at every free goal, grown towards seeded uniform samples and towards each
//! other. Decisions use only the seeded stream and counts; nearest neighbours by a linear scan
//! (ties to the older node), so the same inputs give the same tree on every machine.

use std::time::Instant;

use super::checker::{CollisionChecker, Counting, FastChecks};
use super::config::PlannerConfig;
use super::edge::{Resolution, check_segment};
use super::rng::Stream;
use super::stats::{distance, distance2};

/// Most blocked configurations kept to name the obstacles of an exhausted search.
pub(crate) const BLOCKED_SAMPLES: usize = 48;

/// No parent (a root).
const ROOT: u32 = u32::MAX;

/// One search tree.
struct Tree {
    nodes: Vec<[f64; 6]>,
    parent: Vec<u32>,
    /// Index of the root each node descends from (its goal, in the goal tree).
    root: Vec<u32>,
}

impl Tree {
    fn new() -> Self {
        Self {
            nodes: Vec::new(),
            parent: Vec::new(),
            root: Vec::new(),
        }
    }

    fn add(&mut self, q: [f64; 6], parent: u32, root: u32) -> u32 {
        self.nodes.push(q);
        self.parent.push(parent);
        self.root.push(root);
        (self.nodes.len() - 1) as u32
    }

    fn nearest(&self, q: &[f64; 6]) -> u32 {
        let mut best = (f64::INFINITY, 0u32);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = distance2(n, q);
            if d < best.0 {
                best = (d, i as u32);
            }
        }
        best.1
    }

    /// Configurations from node `i` up to its root, `i` first.
    fn branch(&self, mut i: u32) -> Vec<[f64; 6]> {
        let mut out = Vec::new();
        loop {
            out.push(self.nodes[i as usize]);
            let p = self.parent[i as usize];
            if p == ROOT {
                return out;
            }
            i = p;
        }
    }
}

/// The result of one extension.
enum Step {
    /// The tree reached the target: the node at it.
    Reached(u32),
    /// The tree grew one step towards it: the new node.
    Advanced(u32),
    /// Blocked.
    Trapped,
}

/// How the search ended.
pub(crate) enum Search {
    /// A path from the start to goal number `goal` (index into the goals given).
    Found { path: Vec<[f64; 6]>, goal: usize },
    /// The iteration or node cap was used up.
    Exhausted,
    /// The wall-clock cap hit.
    TimeCap,
}

/// What the search reports besides its outcome.
pub(crate) struct SearchLog {
    pub(crate) iterations: usize,
    pub(crate) nodes: usize,
    /// Blocked configurations met while growing (the first [`BLOCKED_SAMPLES`], then every
    /// 16th), to name the obstacles if the search fails.
    pub(crate) blocked: Vec<[f64; 6]>,
    blocked_seen: usize,
}

impl SearchLog {
    fn note_blocked(&mut self, q: [f64; 6]) {
        self.blocked_seen += 1;
        if self.blocked.len() < BLOCKED_SAMPLES {
            self.blocked.push(q);
        } else if self.blocked_seen.is_multiple_of(16) {
            let k = (self.blocked_seen / 16) % BLOCKED_SAMPLES;
            self.blocked[k] = q;
        }
    }
}

struct Grower<'a, 'b, C: FastChecks + ?Sized> {
    checker: &'a mut Counting<'b, C>,
    config: &'a PlannerConfig,
    res: Resolution,
    log: SearchLog,
}

impl<C: FastChecks + ?Sized> Grower<'_, '_, C> {
    /// True when the query has used its collision-check budget.
    fn spent(&self) -> bool {
        self.checker.spent()
    }

    /// Grows `tree` one step (at most `range`) towards `target`.
    fn extend(&mut self, tree: &mut Tree, target: &[f64; 6]) -> Step {
        let near = tree.nearest(target);
        let from = tree.nodes[near as usize];
        let d = distance(&from, target);
        if d == 0.0 {
            return Step::Reached(near);
        }
        let reach = d <= self.config.range;
        let q = if reach {
            *target
        } else {
            let s = self.config.range / d;
            let mut q = [0.0; 6];
            for j in 0..6 {
                q[j] = from[j] + (target[j] - from[j]) * s;
            }
            q
        };
        if !self.checker.is_free(&q) {
            if !self.spent() {
                self.log.note_blocked(q);
            }
            return Step::Trapped;
        }
        if let Err(hit) = check_segment(self.checker, &from, &q, &self.res) {
            if !self.spent() {
                self.log.note_blocked(hit);
            }
            return Step::Trapped;
        }
        let root = tree.root[near as usize];
        let i = tree.add(q, near, root);
        if reach {
            Step::Reached(i)
        } else {
            Step::Advanced(i)
        }
    }

    /// Grows `tree` towards `target` until it reaches it or is blocked.
    fn connect(&mut self, tree: &mut Tree, target: &[f64; 6], nodes_left: usize) -> Step {
        let mut last = Step::Trapped;
        for _ in 0..nodes_left.max(1) {
            if self.spent() {
                return last;
            }
            match self.extend(tree, target) {
                Step::Advanced(i) => last = Step::Advanced(i),
                other => {
                    return match other {
                        Step::Trapped => last,
                        reached => reached,
                    };
                }
            }
        }
        last
    }
}

/// Searches for a path from `start` to any of `goals` (all already known free and in bounds;
/// at least one), until it connects them or uses `config.max_iterations`, `config.max_nodes` or
/// `config.max_checks` (collision checks of the whole query, counted by `checker`). `Found` paths run start → goal and contain only checked configurations and
/// segments checked at the configured resolution.
pub(crate) fn rrt_connect<C: FastChecks + ?Sized>(
    checker: &mut Counting<'_, C>,
    start: &[f64; 6],
    goals: &[[f64; 6]],
    config: &PlannerConfig,
    started: Instant,
) -> (Search, SearchLog) {
    let mut rng = Stream::new(config.seed, 1);
    let mut a = Tree::new();
    let mut b = Tree::new();
    a.add(*start, ROOT, 0);
    for (i, g) in goals.iter().enumerate() {
        b.add(*g, ROOT, i as u32);
    }
    checker.budget = config.max_checks;
    let mut grower = Grower {
        checker,
        config,
        res: config.edge_resolution(),
        log: SearchLog {
            iterations: 0,
            nodes: 0,
            blocked: Vec::new(),
            blocked_seen: 0,
        },
    };
    // `a` is the tree that extends this iteration; `a_is_start` says which one it is.
    let mut a_is_start = true;
    let outcome = loop {
        if grower.log.iterations >= config.max_iterations {
            break Search::Exhausted;
        }
        let nodes = a.nodes.len() + b.nodes.len();
        if nodes >= config.max_nodes || grower.spent() {
            break Search::Exhausted;
        }
        if let Some(cap) = config.time_cap
            && started.elapsed() >= cap
        {
            break Search::TimeCap;
        }
        grower.log.iterations += 1;
        let sample = rng.config(&config.bounds);
        let new = match grower.extend(&mut a, &sample) {
            Step::Trapped => None,
            Step::Advanced(i) | Step::Reached(i) => Some(i),
        };
        if let Some(i) = new {
            let q = a.nodes[i as usize];
            let left = config.max_nodes.saturating_sub(a.nodes.len() + b.nodes.len());
            if let Step::Reached(j) = grower.connect(&mut b, &q, left) {
                let (s, si, g, gi) = if a_is_start {
                    (&a, i, &b, j)
                } else {
                    (&b, j, &a, i)
                };
                let mut path = s.branch(si);
                path.reverse();
                let tail = g.branch(gi);
                // The meeting configuration is in both branches: keep it once.
                path.extend(tail.into_iter().skip(1));
                let goal = g.root[gi as usize] as usize;
                break Search::Found { path, goal };
            }
        }
        std::mem::swap(&mut a, &mut b);
        a_is_start = !a_is_start;
    };
    grower.log.nodes = a.nodes.len() + b.nodes.len();
    grower.checker.budget = u64::MAX;
    (outcome, grower.log)
}
