//! Exactly one `tracing` event per node status transition, with the documented fields.

use std::sync::Arc;

use macrotree::plan::Loader;
use macrotree::runtime::scripted::ScriptedDriver;
use macrotree::runtime::{LeafOutcome, NodeStatus, TreeRunner, TreeStatus};
use tracing::field::{Field, Visit};
use tracing_subscriber::layer::{Context, SubscriberExt};
use tracing_subscriber::{Layer, Registry};

#[derive(Default, Clone, Debug)]
struct Recorded {
    fields: Vec<(String, String)>,
    level: String,
}

impl Visit for Recorded {
    fn record_debug(&mut self, field: &Field, value: &dyn std::fmt::Debug) {
        self.fields.push((field.name().to_string(), format!("{value:?}")));
    }
    fn record_str(&mut self, field: &Field, value: &str) {
        self.fields.push((field.name().to_string(), value.to_string()));
    }
}

thread_local! {
    /// The tree events this thread recorded, while inside [`recorded`].
    static EVENTS: std::cell::RefCell<Option<Vec<Recorded>>> = const { std::cell::RefCell::new(None) };
}

/// Records `macrotree::tree` events into the emitting thread's [`EVENTS`].
struct Collect;

impl<S: tracing::Subscriber> Layer<S> for Collect {
    fn on_event(&self, event: &tracing::Event<'_>, _ctx: Context<'_, S>) {
        if event.metadata().target() != "macrotree::tree" {
            return;
        }
        EVENTS.with(|events| {
            if let Some(events) = events.borrow_mut().as_mut() {
                let mut r = Recorded {
                    level: event.metadata().level().to_string(),
                    ..Default::default()
                };
                event.record(&mut r);
                events.push(r);
            }
        });
    }
}

/// Runs `f` and returns what it returned and the tree events this thread emitted meanwhile.
/// One global subscriber serves the whole test binary: a scoped one (`with_default`) races
/// with the tests running beside it on tracing's shared callsite-interest cache and can miss
/// events.
fn recorded<R>(f: impl FnOnce() -> R) -> (R, Vec<Recorded>) {
    static INSTALL: std::sync::Once = std::sync::Once::new();
    INSTALL.call_once(|| {
        tracing::subscriber::set_global_default(Registry::default().with(Collect))
            .expect("no other global subscriber in this test binary");
    });
    EVENTS.with(|e| *e.borrow_mut() = Some(Vec::new()));
    let result = f();
    let events = EVENTS.with(|e| e.borrow_mut().take()).unwrap_or_default();
    (result, events)
}

impl Recorded {
    fn get(&self, name: &str) -> Option<&str> {
        self.fields
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

#[test]
fn one_event_per_transition_with_fields() {
    let plan = Arc::new(
        Loader::default().compile_str(
            "main:\n  retry:\n    attempts: 2\n    child:\n      guard:\n        condition: {cube_grasped: {}}\n        child: {carry: {}}\n",
            "t.yaml",
        )
        .unwrap(),
    );
    let mut d = ScriptedDriver::new(&plan);
    d.script(
        "cube_grasped",
        [
            LeafOutcome::Success,
            LeafOutcome::Success,
            LeafOutcome::failure(macrotree::FailureKind::GraspLost, "slipped"),
        ],
    );
    d.eventually("cube_grasped", LeafOutcome::Success);
    d.script(
        "carry",
        [
            LeafOutcome::Running,
            LeafOutcome::Running,
            LeafOutcome::Running,
            LeafOutcome::Success,
        ],
    );

    let mut runner = TreeRunner::new(plan.clone());
    let mut transitions = Vec::new();
    let ((), events) = recorded(|| {
        for i in 0..20 {
            let s = runner.tick(i as f64 * 0.1, 0.1, &mut d);
            transitions.extend(runner.drain_transitions());
            if s != TreeStatus::Running {
                assert_eq!(s, TreeStatus::Success);
                break;
            }
        }
    });
    let status_events: Vec<&Recorded> = events.iter().filter(|e| e.get("to").is_some()).collect();
    assert_eq!(status_events.len(), transitions.len(), "one event per transition");
    for (e, t) in status_events.iter().zip(&transitions) {
        assert_eq!(e.get("path"), Some(t.path.as_str()));
        assert_eq!(e.get("to"), Some(t.to.as_str()));
        assert_eq!(e.get("from"), Some(t.from.as_str()));
        assert_eq!(e.get("tick"), Some(t.tick.to_string().as_str()));
        assert!(e.get("sim_time").is_some() && e.get("kind").is_some());
    }
    // The failing condition carries its reason and attempt; the carry is halted.
    let cond_fail = status_events
        .iter()
        .find(|e| e.get("path") == Some("main/retry/guard/cube_grasped") && e.get("to") == Some("failure"))
        .unwrap();
    assert_eq!(cond_fail.get("reason"), Some("cube_grasped: slipped"));
    assert_eq!(cond_fail.get("attempt"), Some("1"));
    assert_eq!(cond_fail.level, "INFO");
    assert!(
        status_events
            .iter()
            .any(|e| e.get("path") == Some("main/retry/guard/carry") && e.get("to") == Some("halted"))
    );
    // The carry halted when attempt 1 failed belongs to attempt 1.
    let halt = status_events
        .iter()
        .find(|e| e.get("path") == Some("main/retry/guard/carry") && e.get("to") == Some("halted"))
        .unwrap();
    assert_eq!(
        halt.get("attempt"),
        Some("1"),
        "the halt is labelled with its own attempt"
    );
    // The retry announces its second attempt with an explicit reset of the finished nodes.
    let announce = events
        .iter()
        .find(|e| {
            e.get("path") == Some("main/retry") && e.get("attempt") == Some("2") && e.get("to").is_none()
        })
        .expect("the retry announces attempt 2");
    assert!(
        announce.get("reset").is_some_and(|n| n != "0"),
        "{:?}",
        announce.fields
    );
    // Nothing re-enters `running` from a finished status: it is reset to idle first.
    for t in &transitions {
        assert!(
            t.to != NodeStatus::Running || t.from == NodeStatus::Idle,
            "{} {} → {}",
            t.path,
            t.from,
            t.to
        );
    }
    let carry: Vec<(&str, &str)> = status_events
        .iter()
        .filter(|e| e.get("path") == Some("main/retry/guard/carry"))
        .map(|e| (e.get("from").unwrap(), e.get("to").unwrap()))
        .collect();
    assert_eq!(
        carry,
        [
            ("idle", "running"),
            ("running", "halted"),
            ("halted", "idle"),
            ("idle", "running"),
            ("running", "success")
        ],
        "halted with attempt 1, reset to idle at once (attempt 2 was announced), re-entered from idle"
    );
    let reset_tick = transitions
        .iter()
        .find(|t| t.path == "main/retry/guard/carry" && t.to == NodeStatus::Idle)
        .map(|t| t.tick);
    let halt_tick = transitions
        .iter()
        .find(|t| t.path == "main/retry/guard/carry" && t.to == NodeStatus::Halted)
        .map(|t| t.tick);
    assert_eq!(reset_tick, halt_tick);
    // The guard condition holding tick after tick produces no events of its own.
    let cond_events: Vec<&str> = status_events
        .iter()
        .filter(|e| e.get("path") == Some("main/retry/guard/cube_grasped"))
        .map(|e| e.get("to").unwrap())
        .collect();
    assert_eq!(
        cond_events,
        ["success", "failure", "idle", "success"],
        "success, failure, reset for attempt 2, success again"
    );
}
