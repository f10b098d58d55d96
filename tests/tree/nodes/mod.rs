//! The runtime semantics of every control node family, one file per family, driven by the
//! scripted driver; the helpers the files share.

use std::sync::Arc;

use macrotree::FailureKind;
use macrotree::plan::{Loader, Plan};
use macrotree::runtime::scripted::{Call, ScriptedDriver};
use macrotree::runtime::{LeafOutcome, NodeStatus, TreeRunner, TreeStatus};

use LeafOutcome::{Running, Success};

/// A scripted failure (of kind `grasp_failed`, so tests can see the kind carried up the tree).
pub fn fail(why: &str) -> LeafOutcome {
    LeafOutcome::failure(FailureKind::GraspFailed, why)
}

/// The message of node `i`'s last failure or halt.
pub fn reason_of(r: &TreeRunner, i: usize) -> Option<&str> {
    r.node_reasons()[i].as_ref().map(|f| f.message.as_str())
}

pub fn plan(yaml: &str) -> Arc<Plan> {
    match Loader::default().compile_str(yaml, "test.yaml") {
        Ok(p) => Arc::new(p),
        Err(diags) => {
            for d in &diags {
                eprintln!("{d}");
            }
            panic!("test tree does not compile");
        }
    }
}

pub const DT: f64 = 0.1;

/// Tick until the tree finishes (or `max` ticks); returns the status and the number of ticks.
pub fn run(runner: &mut TreeRunner, d: &mut ScriptedDriver, max: usize) -> (TreeStatus, usize) {
    for i in 0..max {
        let s = runner.tick(i as f64 * DT, DT, d);
        if s != TreeStatus::Running {
            return (s, i + 1);
        }
    }
    (TreeStatus::Running, max)
}

pub fn ticked_paths(d: &ScriptedDriver) -> Vec<String> {
    d.log
        .iter()
        .filter_map(|c| match c {
            Call::Tick { path, .. } => Some(path.rsplit('/').next().unwrap_or("").to_string()),
            Call::Halt { .. } => None,
        })
        .collect()
}

mod fallback;
mod guard;
mod inverter_and_force;
mod lifecycle;
mod parallel;
mod reactive;
mod repeat;
mod retry;
mod sequence;
mod subtree;
mod timeout;
mod wait;
