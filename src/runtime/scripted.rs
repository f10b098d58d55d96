//! [`ScriptedDriver`]: a test double that answers leaf ticks from per-leaf scripts (like
//! py_trees' `StatusQueue`) and counts ticks, starts and halts.
//!
//! Leaves are selected by *selector*: a full node path (`main/sequence/retry/sequence[pick]/grasp`),
//! or any path suffix after a `/` (`grasp`, `sequence[pick]/grasp`, `reach#2`). A selector may
//! match several leaves; scripts and counters then apply to each of them.
//!
//! ```
//! use macrotree::plan::Loader;
//! use macrotree::FailureKind;
//! use macrotree::runtime::{LeafOutcome, scripted::ScriptedDriver};
//!
//! let plan = Loader::default().compile_str("main: {sequence: {children: [{grasp: {}}, {cube_grasped: {}}]}}", "t.yaml").unwrap();
//! let mut d = ScriptedDriver::new(&plan);
//! d.script("grasp", [LeafOutcome::Running, LeafOutcome::Success]); // 2 ticks, then done
//! d.set("cube_grasped", LeafOutcome::failure(FailureKind::GraspLost, "slipped")); // every tick from now on
//! ```

use std::collections::{HashMap, VecDeque};

use super::{LeafDriver, LeafOutcome, Selection};
use crate::kinds::Leaf;
use crate::plan::{LeafId, Plan};

/// One call the driver received.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Call {
    /// `tick(id, first)` and what was answered.
    Tick {
        /// Leaf path.
        path: String,
        /// The `first` flag.
        first: bool,
        /// The answer.
        outcome: LeafOutcome,
    },
    /// `halt(id)`.
    Halt {
        /// Leaf path.
        path: String,
    },
}

#[derive(Clone, Debug, Default)]
struct Script {
    queue: VecDeque<LeafOutcome>,
    eventually: Option<LeafOutcome>,
    ticks: usize,
    starts: usize,
    halts: usize,
}

/// A scripted [`LeafDriver`] for tests. Unscripted leaves (and exhausted scripts without an
/// `eventually`) answer the default outcome (Success unless changed with
/// [`set_default`](Self::set_default)).
#[derive(Clone, Debug)]
pub struct ScriptedDriver {
    /// Answers to `select` queries, in order; when empty, nothing matches.
    pub selections: VecDeque<Selection>,
    paths: Vec<String>,
    scripts: HashMap<u32, Script>,
    default: LeafOutcome,
    /// Every call, in order.
    pub log: Vec<Call>,
}

impl ScriptedDriver {
    /// A driver for `plan`'s leaves, every leaf answering Success.
    pub fn new(plan: &Plan) -> Self {
        Self {
            selections: VecDeque::new(),
            paths: plan.leaves.iter().map(|l| l.path.clone()).collect(),
            scripts: HashMap::new(),
            default: LeafOutcome::Success,
            log: Vec::new(),
        }
    }

    /// Leaf ids matched by `selector` (full path, or a suffix after `/`).
    ///
    /// # Panics
    /// If nothing matches (a typo in a test).
    pub fn select(&self, selector: &str) -> Vec<LeafId> {
        let suffix = format!("/{selector}");
        let ids: Vec<LeafId> = self
            .paths
            .iter()
            .enumerate()
            .filter(|(_, p)| *p == selector || p.ends_with(&suffix))
            .map(|(i, _)| LeafId(i as u32))
            .collect();
        assert!(
            !ids.is_empty(),
            "ScriptedDriver: no leaf matches `{selector}`; leaves are: {:?}",
            self.paths
        );
        ids
    }

    /// Outcome for leaves nobody scripted (default Success).
    pub fn set_default(&mut self, outcome: LeafOutcome) -> &mut Self {
        self.default = outcome;
        self
    }

    /// Append `outcomes` to the queue of the selected leaves: each tick of such a leaf pops one.
    /// When the queue is empty, the leaf answers its `eventually` outcome (see
    /// [`set`](Self::set)), or the default.
    pub fn script(&mut self, selector: &str, outcomes: impl IntoIterator<Item = LeafOutcome>) -> &mut Self {
        let outcomes: Vec<LeafOutcome> = outcomes.into_iter().collect();
        for id in self.select(selector) {
            self.scripts
                .entry(id.0)
                .or_default()
                .queue
                .extend(outcomes.iter().cloned());
        }
        self
    }

    /// From now on the selected leaves answer `outcome` on every tick (clears their queues).
    /// Handy for conditions: `d.set("cube_grasped", LeafOutcome::Success)`.
    pub fn set(&mut self, selector: &str, outcome: LeafOutcome) -> &mut Self {
        for id in self.select(selector) {
            let s = self.scripts.entry(id.0).or_default();
            s.queue.clear();
            s.eventually = Some(outcome.clone());
        }
        self
    }

    /// After the queue is exhausted, answer `outcome` (the queue is kept).
    pub fn eventually(&mut self, selector: &str, outcome: LeafOutcome) -> &mut Self {
        for id in self.select(selector) {
            self.scripts.entry(id.0).or_default().eventually = Some(outcome.clone());
        }
        self
    }

    fn sum(&self, selector: &str, f: impl Fn(&Script) -> usize) -> usize {
        self.select(selector)
            .iter()
            .map(|id| self.scripts.get(&id.0).map_or(0, &f))
            .sum()
    }

    /// Total ticks received by the selected leaves.
    pub fn ticks(&self, selector: &str) -> usize {
        self.sum(selector, |s| s.ticks)
    }

    /// Ticks with `first == true` (executions started) of the selected leaves.
    pub fn starts(&self, selector: &str) -> usize {
        self.sum(selector, |s| s.starts)
    }

    /// Halts received by the selected leaves.
    pub fn halts(&self, selector: &str) -> usize {
        self.sum(selector, |s| s.halts)
    }

    /// Paths of the halted leaves, in order.
    pub fn halted_paths(&self) -> Vec<&str> {
        self.log
            .iter()
            .filter_map(|c| match c {
                Call::Halt { path } => Some(path.as_str()),
                Call::Tick { .. } => None,
            })
            .collect()
    }

    fn path(&self, id: LeafId) -> String {
        self.paths
            .get(id.index())
            .cloned()
            .unwrap_or_else(|| format!("#{}", id.0))
    }
}

impl LeafDriver for ScriptedDriver {
    fn tick(&mut self, id: LeafId, _leaf: &Leaf, first: bool) -> LeafOutcome {
        let default = self.default.clone();
        let s = self.scripts.entry(id.0).or_default();
        s.ticks += 1;
        if first {
            s.starts += 1;
        }
        let outcome = s
            .queue
            .pop_front()
            .or_else(|| s.eventually.clone())
            .unwrap_or(default);
        let path = self.path(id);
        self.log.push(Call::Tick {
            path,
            first,
            outcome: outcome.clone(),
        });
        outcome
    }

    fn halt(&mut self, id: LeafId, _leaf: &Leaf) {
        self.scripts.entry(id.0).or_default().halts += 1;
        let path = self.path(id);
        self.log.push(Call::Halt { path });
    }

    /// Pops the next scripted answer of [`selections`](Self::selections) (none left: nothing
    /// matches).
    fn select_object(
        &mut self,
        _query: &crate::world::query::Query,
    ) -> Result<Option<Selection>, crate::failure::Failure> {
        Ok(self.selections.pop_front())
    }
}
