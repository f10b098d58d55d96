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

use serde_json::{Value, json};

use super::monitor::{BreakSpec, ForcedRecord, Monitor, MonitorCommand};
use super::{LiveViewer, Recorder, TreeNodeView};
use crate::actions::Cell;
use crate::episode::{EpisodeEvent, EpisodeObserver};
use crate::motion::CellCommand;
use crate::plan::{Internal, Plan};
use crate::runtime::{BlackboardWrite, Transition, TreeRunner};

/// Body poses are pushed at this rate of simulated time, Hz (every 1/60 s of sim time, not of
/// wall time; the live viewer further limits what each browser gets to 40 Hz wall).
pub const PUBLISH_HZ: f64 = 60.0;

/// How long a paused episode waits for each command before it looks again, wall time.
const PAUSE_POLL: Duration = Duration::from_millis(200);

/// The tree's nodes as the viewer's side panel shows it (preorder, as in [`Plan::nodes`]), with
/// each loop's limit and each `for_each`'s variable.
pub fn tree_view(plan: &Plan) -> Vec<TreeNodeView> {
    let mut nodes: Vec<TreeNodeView> = plan
        .nodes
        .iter()
        .map(|n| TreeNodeView {
            path: n.path.clone(),
            kind: n.kind.to_string(),
            name: n.label.clone(),
            parent: n.parent,
            leaf: n.leaf.is_some(),
            source: n.source.clone(),
            ..TreeNodeView::default()
        })
        .collect();
    for internal in &plan.internal {
        match internal {
            Internal::Next { node, limit } => nodes[*node].limit = Some(*limit),
            Internal::Pick { node, select, limit } => {
                nodes[*node].limit = Some(*limit);
                nodes[*node].var = Some(select.var.clone());
            }
            Internal::Probe { .. } | Internal::Exit { .. } => {}
        }
    }
    nodes
}

fn event_json(t: &Transition) -> Value {
    json!({
        "t": t.sim_time, "path": t.path, "kind": t.kind, "from": t.from.as_str(), "to": t.to.as_str(),
        "reason": t.reason, "attempt": t.attempt,
    })
}

fn write_json(w: &BlackboardWrite) -> Value {
    json!({"t": w.sim_time, "path": w.path, "kind": "blackboard", "var": w.var, "value": w.value})
}

/// Streams an episode to a live viewer and/or records it into a replay, optionally pacing the
/// simulation to the wall clock, and runs the monitor's breakpoints and forced results.
///
/// Once the tree has been ticked (before the physics advances) it sends the tree's node
/// statuses, loop counters, blackboard writes and new trace events whenever something changed;
/// after every control period it sends the body poses every 1/[`PUBLISH_HZ`] s of sim time.
/// Publishing never blocks on a browser (see [`LiveViewer::publish_poses`]). With a live
/// viewer, a breakpoint or the page's pause button holds the episode between the tree's tick
/// and the physics until the page resumes or steps it.
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
    monitor: Monitor,
    /// Trace events made by the monitor (forced results), sent with the next statuses.
    pending: Vec<Value>,
    /// Loop counters last sent to the recorder.
    last_attempts: Vec<u32>,
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
            monitor: Monitor::default(),
            pending: Vec::new(),
            last_attempts: Vec::new(),
        }
    }

    /// Sets breakpoints on every node a pattern matches (`run --view --break …`); they pause
    /// only a live episode.
    ///
    /// # Errors
    /// A pattern that matches no node.
    pub fn set_breakpoints(&mut self, plan: &Plan, specs: &[BreakSpec]) -> Result<(), String> {
        self.monitor = Monitor::new(plan, specs)?;
        if let Some(live) = &self.live {
            live.publish_monitor(self.monitor.to_json(plan));
        }
        Ok(())
    }

    /// The live viewer, if any (e.g. to capture an image or read its stats mid-run).
    pub fn live(&self) -> Option<&LiveViewer> {
        self.live.as_ref()
    }

    /// Results forced from the page so far, in order.
    pub fn forced(&self) -> &[ForcedRecord] {
        self.monitor.forced()
    }

    /// Ends the episode: returns the live viewer (to keep serving) and the recorder (to write).
    pub fn finish(self) -> (Option<LiveViewer>, Option<Recorder>) {
        (self.live, self.recorder)
    }

    /// Applies one command from the page and publishes the monitor's new state.
    fn apply(&mut self, cmd: MonitorCommand, runner: &mut TreeRunner, t: f64) {
        let plan = runner.plan().clone();
        match cmd {
            MonitorCommand::Pause => self.monitor.request_pause(),
            MonitorCommand::Resume => self.monitor.resume(false),
            MonitorCommand::Step => self.monitor.resume(true),
            MonitorCommand::Break { path, when } => match plan.node_by_path(&path) {
                Some(node) => self.monitor.set_breakpoint(node, when),
                None => tracing::info!(target: "macrotree::monitor", "no node `{path}` to break at"),
            },
            MonitorCommand::Force { path, result } => {
                let forced = plan
                    .node_by_path(&path)
                    .ok_or_else(|| format!("the tree has no node `{path}`"))
                    .and_then(|node| runner.force(node, result).map_err(|e| e.to_string()));
                match forced {
                    Ok(()) => {
                        tracing::info!(target: "macrotree::monitor", path, "{result} forced from the monitor");
                        self.pending
                            .push(json!({"t": t, "path": path, "kind": "forced", "result": result.as_str()}));
                        self.monitor.record_forced(ForcedRecord { path, result, t });
                    }
                    Err(why) => {
                        tracing::warn!(target: "macrotree::monitor", "cannot force a result: {why}");
                        self.pending
                            .push(json!({"t": t, "kind": "note", "text": format!("cannot force: {why}")}));
                    }
                }
            }
        }
        if let Some(live) = &self.live {
            live.publish_monitor(self.monitor.to_json(&plan));
        }
    }

    /// Sends statuses, loop counters and events (transitions, blackboard writes, the monitor's).
    fn publish_status(
        &mut self,
        time: f64,
        runner: &TreeRunner,
        transitions: &[Transition],
        writes: &[BlackboardWrite],
    ) {
        if transitions.is_empty() && writes.is_empty() && self.pending.is_empty() && time < self.next_publish
        {
            return;
        }
        let statuses: Vec<&'static str> = runner.node_statuses().iter().map(|s| s.as_str()).collect();
        let mut events: Vec<Value> = transitions.iter().map(event_json).collect();
        // Blackboard writes (`{block} = "red"`) are events of their own.
        events.extend(writes.iter().map(write_json));
        events.append(&mut self.pending);
        let attempts: Vec<u32> = (0..statuses.len()).map(|i| runner.attempt(i)).collect();
        if let Some(live) = &self.live {
            live.publish_tree_status_with_attempts(statuses.clone(), attempts.clone(), events.clone());
        }
        if let Some(rec) = &mut self.recorder {
            let changed = (attempts != self.last_attempts).then(|| attempts.clone());
            rec.tree_status_with_attempts(time, statuses, changed, events);
        }
        self.last_attempts = attempts;
    }

    /// Holds the episode until the page resumes or steps it; simulated time stands still.
    fn hold(&mut self, cell: &Cell, runner: &mut TreeRunner, time: f64) {
        let Some(live) = &self.live else {
            self.monitor.resume(false);
            return;
        };
        let plan = runner.plan().clone();
        live.publish_poses(cell.sim().data(), time);
        live.publish_monitor(self.monitor.to_json(&plan));
        if let Some(p) = self.monitor.paused() {
            tracing::info!(target: "macrotree::monitor", t = time, "paused ({}{}): resume or step from the page", p.reason, p.path.as_deref().map(|p| format!(" {p}")).unwrap_or_default());
        }
        let held = Instant::now();
        while self.monitor.paused().is_some() {
            let Some(cmd) = self.live.as_ref().and_then(|l| l.next_command(PAUSE_POLL)) else {
                continue;
            };
            self.apply(cmd, runner, time);
            if !self.pending.is_empty() {
                self.publish_status(time, runner, &[], &[]);
            }
        }
        // The pace restarts from here: paused wall time is not caught up at full speed.
        if let Some(start) = &mut self.start {
            *start += held.elapsed();
        }
    }
}

impl EpisodeObserver for ViewObserver {
    fn on_period_start(&mut self, cell: &Cell, _command: &CellCommand, runner: &mut TreeRunner) {
        let time = cell.world().time;
        if let Some(live) = &self.live {
            let commands: Vec<MonitorCommand> = std::iter::from_fn(|| live.next_command(Duration::ZERO))
                .take(64)
                .collect();
            for cmd in commands {
                self.apply(cmd, runner, time);
            }
        }
        let transitions = runner.drain_transitions();
        let writes = runner.drain_blackboard_writes();
        self.publish_status(time, runner, &transitions, &writes);
        if self.live.is_some() && self.monitor.check(runner.plan(), &transitions, time) {
            self.hold(cell, runner, time);
        }
    }

    fn on_event(&mut self, event: EpisodeEvent<'_>) {
        // Sent with the next statuses; the replay marks them on its timeline.
        self.pending.push(match event {
            EpisodeEvent::Fault(f) => {
                json!({"t": f.time, "kind": "fault", "fault": f.kind.name(), "detail": f.detail})
            }
            EpisodeEvent::Collision(c) => {
                json!({"t": c.time, "kind": "collision", "what": c.what, "path": c.node})
            }
        });
    }

    fn on_tick(&mut self, cell: &Cell, _runner: &mut TreeRunner) {
        let time = cell.world().time;
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
