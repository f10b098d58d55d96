//! `run --view` and `run --record`: an [`EpisodeObserver`] that streams the episode to the live
//! MeshCat page and/or records it into a self-contained HTML replay, with the tree's live status.

use std::time::{Duration, Instant};

use crate::actions::Cell;
use crate::episode::EpisodeObserver;
use crate::plan::Plan;
use crate::runtime::{Transition, TreeRunner};
use crate::viewer::{LiveViewer, Recorder, TreeNodeView};

/// Body poses are pushed at this rate of simulated time, Hz.
pub const PUBLISH_HZ: f64 = 60.0;

/// The tree's nodes as the viewer's side panel shows them.
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

/// Streams and/or records an episode.
pub struct ViewObserver {
    live: Option<LiveViewer>,
    recorder: Option<Recorder>,
    next_publish: f64,
    /// Wall-clock pacing: simulated seconds per wall second (1.0 = real time), if any.
    speed: Option<f64>,
    start: Instant,
}

impl ViewObserver {
    /// An observer publishing to `live` and/or recording into `recorder`, paced at `speed`× real
    /// time when given.
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
            start: Instant::now(),
        }
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
        if !transitions.is_empty() || time >= self.next_publish {
            let statuses: Vec<&'static str> = runner.node_statuses().iter().map(|s| s.as_str()).collect();
            let events: Vec<serde_json::Value> = transitions.iter().map(event_json).collect();
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
            if let Some(wait) = due.checked_sub(self.start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
    }
}
