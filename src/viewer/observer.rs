//! [`ViewObserver`]: an [`EpisodeObserver`] that streams an episode to a [`LiveViewer`] and/or
//! records it with a [`Recorder`], with the tree's live status beside the scene.
//!
//! This is what `macrotree run TREE --view` / `--record FILE.html` attaches to the episode; tests
//! and other tools attach it the same way:
//!
//! ```no_run
//! # use std::sync::Arc;
//! # use macrotree::episode::{EpisodeConfig, run_episode};
//! # use macrotree::viewer::{LiveViewer, ViewObserver, ViewerOptions};
//! # fn demo(scene: &macrotree::sim::Scene, plan: Arc<macrotree::plan::Plan>) {
//! let live = LiveViewer::start(&scene.model, &ViewerOptions::default()).unwrap();
//! let mut view = ViewObserver::new(&plan, Some(live), None, None);
//! let factory = macrotree::factory::Factory::builtin();
//! let report = run_episode(scene, plan.clone(), &factory, &EpisodeConfig::default(), &mut view);
//! let (live, _recorder) = view.finish();
//! # }
//! ```

use std::time::{Duration, Instant};

use super::{LiveViewer, Recorder, TreeNodeView};
use crate::actions::Cell;
use crate::episode::EpisodeObserver;
use crate::plan::Plan;
use crate::runtime::{Transition, TreeRunner};

/// Body poses are pushed at this rate of simulated time, Hz (every 1/60 s of sim time, not of
/// wall time; the live viewer further limits what each browser gets to 40 Hz wall).
pub const PUBLISH_HZ: f64 = 60.0;

/// The tree's nodes as the viewer's side panel shows them (preorder, as in [`Plan::nodes`]).
pub fn tree_view(plan: &Plan) -> Vec<TreeNodeView> {
    plan.nodes
        .iter()
        .map(|n| TreeNodeView {
            path: n.path.clone(),
            kind: n.kind.to_string(),
            name: n.label.clone(),
            parent: n.parent,
        })
        .collect()
}

fn event_json(t: &Transition) -> serde_json::Value {
    serde_json::json!({
        "t": t.sim_time, "path": t.path, "kind": t.kind, "from": t.from.as_str(), "to": t.to.as_str(),
        "reason": t.reason, "attempt": t.attempt,
    })
}

/// Streams an episode to a live viewer and/or records it into a replay, optionally pacing the
/// simulation to the wall clock.
///
/// After every control period it sends the tree's node statuses, retry attempts and new trace
/// events whenever a node changed status (and at least every 1/[`PUBLISH_HZ`] s of sim time),
/// and the body poses every 1/[`PUBLISH_HZ`] s of sim time. Publishing never blocks on a
/// browser (see [`LiveViewer::publish_poses`]).
pub struct ViewObserver {
    live: Option<LiveViewer>,
    recorder: Option<Recorder>,
    /// Sim time of the next pose publish, seconds.
    next_publish: f64,
    /// Wall-clock pacing: simulated seconds per wall second (1.0 = real time), if any.
    speed: Option<f64>,
    /// Wall-clock origin of the pacing: set at the first tick, so the time spent building the
    /// cell before the episode starts is not taken from the episode's pace.
    start: Option<Instant>,
}

impl ViewObserver {
    /// An observer publishing to `live` and/or recording into `recorder`, paced at `speed`× real
    /// time (simulated seconds per wall second) when given; `None` runs as fast as it can.
    /// Sends the plan's node list to both at once.
    pub fn new(
        plan: &Plan,
        live: Option<LiveViewer>,
        mut recorder: Option<Recorder>,
        speed: Option<f64>,
    ) -> Self {
        let nodes = tree_view(plan);
        if let Some(live) = &live {
            live.set_tree(nodes.clone());
        }
        if let Some(rec) = &mut recorder {
            rec.set_tree(nodes);
        }
        Self {
            live,
            recorder,
            next_publish: 0.0,
            speed,
            start: None,
        }
    }

    /// The live viewer, if any (e.g. to capture an image or read its stats mid-run).
    pub fn live(&self) -> Option<&LiveViewer> {
        self.live.as_ref()
    }

    /// Ends the episode: returns the live viewer (to keep serving) and the recorder (to write).
    pub fn finish(self) -> (Option<LiveViewer>, Option<Recorder>) {
        (self.live, self.recorder)
    }
}

impl EpisodeObserver for ViewObserver {
    fn on_tick(&mut self, cell: &Cell, runner: &mut TreeRunner) {
        let time = cell.world().time;
        let transitions = runner.drain_transitions();
        let writes = runner.drain_blackboard_writes();
        if !transitions.is_empty() || !writes.is_empty() || time >= self.next_publish {
            let statuses: Vec<&'static str> = runner.node_statuses().iter().map(|s| s.as_str()).collect();
            let mut events: Vec<serde_json::Value> = transitions.iter().map(event_json).collect();
            // Blackboard writes (`{block} = "red"`) are events of their own.
            events.extend(writes.iter().map(|w| {
                serde_json::json!({"t": w.sim_time, "path": w.path, "kind": "blackboard", "var": w.var, "value": w.value})
            }));
            if let Some(live) = &self.live {
                let attempts = (0..statuses.len()).map(|i| runner.attempt(i)).collect();
                live.publish_tree_status_with_attempts(statuses.clone(), attempts, events.clone());
            }
            if let Some(rec) = &mut self.recorder {
                rec.tree_status(time, statuses, events);
            }
        }
        if time < self.next_publish {
            return;
        }
        self.next_publish = time + 1.0 / PUBLISH_HZ;
        let data = cell.sim().data();
        if let Some(live) = &self.live {
            live.publish_poses(data, time);
        }
        if let Some(rec) = &mut self.recorder {
            rec.frame(data, time);
        }
        if let Some(speed) = self.speed {
            let due = Duration::from_secs_f64(time / speed);
            let start = *self.start.get_or_insert_with(|| {
                let now = Instant::now();
                now.checked_sub(due).unwrap_or(now)
            });
            if let Some(wait) = due.checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
    }
}
