//! The monitor in a real headless Chromium at 1280×800: every shipped tree reads whole, subtrees
//! collapse, search finds nodes; a replay of `clear_table` shows the blackboard and each
//! `for_each` iteration as they change, with markers and transition steps; a live episode
//! pauses at breakpoints (declared and set from the page) and finishes exactly as without
//! them; a failure forced from the page makes the fallback's next child run and the report
//! counts it as forced.
//!
//! Set `MACROTREE_MONITOR_SCREENSHOTS=DIR` to save the screenshots docs/viewer.md shows.

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::support::{browser, flagship};
use browser::*;
use macrotree::episode::{EpisodeConfig, EpisodeReport, Goal, NoObserver, run_episode};
use macrotree::plan::{Loader, Plan};
use macrotree::sim::Scene;
use macrotree::viewer::{
    BreakSpec, BreakWhen, LiveViewer, MonitorCommand, Recorder, TreeNodeView, ViewObserver, ViewerOptions,
    tree_view,
};

const WIDTH: u32 = 1280;
const HEIGHT: u32 = 800;

fn load(tree: &str) -> Arc<Plan> {
    Arc::new(
        Loader::default()
            .load(Path::new(tree))
            .unwrap_or_else(|d| panic!("{tree}: {}", d[0])),
    )
}

fn live() -> LiveViewer {
    LiveViewer::start(
        &flagship::scene().model,
        &ViewerOptions {
            port: 0,
            ..ViewerOptions::default()
        },
    )
    .expect("viewer")
}

fn screenshot(dt: &mut Devtools, name: &str) {
    if let Some(dir) = std::env::var_os("MACROTREE_MONITOR_SCREENSHOTS") {
        let path = Path::new(&dir).join(name);
        std::fs::write(&path, dt.screenshot()).unwrap();
        eprintln!("saved {}", path.display());
    }
}

fn eval_json(dt: &mut Devtools, js: &str) -> serde_json::Value {
    serde_json::from_str(dt.eval(js).as_str().unwrap_or("null")).unwrap_or_default()
}

/// Rows whose name is cut, overflows the panel, or differs from the node's label.
const CUT_ROWS: &str = "JSON.stringify((() => {\
  const panel = document.querySelector('#panel').getBoundingClientRect();\
  return Array.from(document.querySelectorAll('#tree .node')).filter(r => {\
    const n = r.querySelector('.name'); const b = n.getBoundingClientRect();\
    return n.scrollWidth > n.clientWidth + 1 || b.right > panel.right + 0.5 || b.width < 1 ||\
      n.textContent.includes('…');\
  }).map(r => r.querySelector('.name').textContent);\
})())";

/// Sends `nodes` to the page and waits until it shows every label whole, in order (trees of the
/// same size may follow each other).
fn show_tree(viewer: &LiveViewer, dt: &mut Devtools, nodes: &[TreeNodeView]) {
    viewer.set_tree(nodes.to_vec());
    let want: Vec<&str> = nodes.iter().map(|n| n.name.as_str()).collect();
    let want = serde_json::json!(want).to_string();
    dt.wait_until(
        "JSON.stringify(Array.from(document.querySelectorAll('#tree .node .name')).map(n => n.textContent))",
        Duration::from_secs(30),
        |v| v.as_str() == Some(want.as_str()),
    );
}

#[test]
fn every_shipped_tree_reads_whole_at_1280x800_and_its_subtrees_collapse_and_search() {
    if !browser_available() {
        return;
    }
    let viewer = live();
    let browser = Chromium::open(&viewer.url(), WIDTH, HEIGHT);
    assert!(
        viewer.wait_for_clients(1, Duration::from_secs(60)),
        "the page did not connect"
    );
    let mut dt = browser.devtools();
    let mut trees: Vec<_> = std::fs::read_dir("trees")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    trees.sort();
    assert!(trees.len() >= 10, "{trees:?}");
    for tree in &trees {
        let plan = load(tree.to_str().unwrap());
        let nodes = tree_view(&plan);
        show_tree(&viewer, &mut dt, &nodes);
        let cut = eval_json(&mut dt, CUT_ROWS);
        assert_eq!(
            cut,
            serde_json::json!([]),
            "{}: names cut at {WIDTH}×{HEIGHT}",
            tree.display()
        );
    }

    // clear_table: collapse its for_each, then search.
    let plan = load("trees/clear_table.yaml");
    let nodes = tree_view(&plan);
    show_tree(&viewer, &mut dt, &nodes);
    let each = nodes.iter().position(|n| n.kind == "for_each").unwrap();
    let below = nodes
        .iter()
        .enumerate()
        .filter(|(i, _)| {
            let mut p = nodes[*i].parent;
            while let Some(q) = p {
                if q == each {
                    return true;
                }
                p = nodes[q].parent;
            }
            false
        })
        .count();
    let path = &nodes[each].path;
    let collapse = format!(
        "(() => {{ const r = document.querySelector('#tree .node[data-path={path:?}]'); r.querySelector('.toggle').click();\
          const li = r.parentElement; const hidden = Array.from(li.querySelectorAll(':scope > ul .node')).filter(n => n.offsetParent !== null).length;\
          return JSON.stringify({{visible_below: hidden, count: r.querySelector('.hidden-count').textContent,\
            toggle: r.querySelector('.toggle').textContent, rows: document.querySelectorAll('#tree .node').length}}); }})()"
    );
    let c: serde_json::Value = serde_json::from_str(dt.eval(&collapse).as_str().unwrap()).unwrap();
    assert_eq!(c["visible_below"], 0, "{c}");
    assert_eq!(c["count"], format!("+{below}"), "{c}");
    assert_eq!(c["toggle"], "▸", "{c}");
    screenshot(&mut dt, "monitor_collapsed.png");

    // Search: only the matches and their ancestors stay, the collapsed loop opens to show them.
    let search = "(() => { const s = document.querySelector('#search'); s.value = 'release';\
        s.dispatchEvent(new Event('input'));\
        const rows = Array.from(document.querySelectorAll('#tree .node')).filter(r => r.offsetParent !== null);\
        return JSON.stringify({visible: rows.map(r => r.dataset.path), matches: rows.filter(r => r.classList.contains('match')).map(r => r.dataset.path),\
          count: document.querySelector('#search-count').textContent}); })()";
    let s: serde_json::Value = serde_json::from_str(dt.eval(search).as_str().unwrap()).unwrap();
    let want: Vec<&str> = nodes
        .iter()
        .filter(|n| {
            format!("{}\n{}\n{}", n.name, n.kind, n.path)
                .to_lowercase()
                .contains("release")
        })
        .map(|n| n.path.as_str())
        .collect();
    assert!(!want.is_empty());
    assert_eq!(s["matches"], serde_json::json!(want), "{s}");
    assert_eq!(s["count"], format!("{} matches", want.len()), "{s}");
    let visible: Vec<String> = serde_json::from_value(s["visible"].clone()).unwrap();
    for v in &visible {
        assert!(
            want.iter().any(|m| m.starts_with(v.as_str())),
            "{v} is neither a match nor an ancestor of one: {s}"
        );
    }
    assert!(visible.len() < nodes.len(), "{s}");
    screenshot(&mut dt, "monitor_search.png");
}

#[test]
fn a_200_node_tree_reads_whole_and_an_update_rewrites_only_the_rows_that_changed() {
    if !browser_available() {
        return;
    }
    // 1 root, 40 sequences, each with 4 leaves with long names, plus 39 more leaves: 200 nodes.
    let mut nodes = vec![TreeNodeView {
        path: "main".into(),
        kind: "sequence".into(),
        name: "sequence \"two hundred nodes\"".into(),
        ..TreeNodeView::default()
    }];
    for s in 0..40 {
        let parent = nodes.len();
        nodes.push(TreeNodeView {
            path: format!("main/sequence#{s}"),
            kind: "sequence".into(),
            name: format!("sequence \"stage {s} of the long task\""),
            parent: Some(0),
            ..TreeNodeView::default()
        });
        for l in 0..4 {
            nodes.push(TreeNodeView {
                path: format!("main/sequence#{s}/reach#{l}"),
                kind: "reach".into(),
                name: format!("reach {{block}} +[0, 0, 0.12] \"above the block of stage {s}, step {l}\""),
                parent: Some(parent),
                leaf: true,
                ..TreeNodeView::default()
            });
        }
    }
    while nodes.len() < 200 {
        let k = nodes.len();
        nodes.push(TreeNodeView {
            path: format!("main/wait#{k}"),
            kind: "wait".into(),
            name: format!("wait 0.5 s \"settle {k}\""),
            parent: Some(0),
            leaf: true,
            ..TreeNodeView::default()
        });
    }
    let viewer = live();
    let browser = Chromium::open(&viewer.url(), WIDTH, HEIGHT);
    assert!(viewer.wait_for_clients(1, Duration::from_secs(60)));
    let mut dt = browser.devtools();
    show_tree(&viewer, &mut dt, &nodes);
    assert_eq!(eval_json(&mut dt, CUT_ROWS), serde_json::json!([]));
    let mut statuses = vec!["idle"; nodes.len()];
    statuses[0] = "running";
    statuses[1] = "running";
    statuses[2] = "running";
    viewer.publish_tree_status(statuses.clone(), vec![]);
    dt.wait_until(
        "document.querySelectorAll('#tree .node.running').length",
        Duration::from_secs(20),
        |v| v.as_u64() == Some(3),
    );
    let before = eval_json(&mut dt, "JSON.stringify(macrotree.stats)");
    // One leaf finishes and the next starts: two rows change.
    statuses[2] = "success";
    statuses[3] = "running";
    viewer.publish_tree_status(statuses, vec![]);
    dt.wait_until(
        "document.querySelectorAll('#tree .node.success').length",
        Duration::from_secs(20),
        |v| v.as_u64() == Some(1),
    );
    let after = eval_json(&mut dt, "JSON.stringify(macrotree.stats)");
    let writes = after["rowWrites"].as_u64().unwrap() - before["rowWrites"].as_u64().unwrap();
    eprintln!(
        "200 nodes: {writes} row(s) rewritten; the update took {} ms",
        after["lastUpdateMs"]
    );
    assert_eq!(writes, 2, "{before} → {after}");
}

/// Records `clear_table` (default layout) into `path`; returns the report.
fn record_clear_table(path: &Path) -> EpisodeReport {
    let plan = load("trees/clear_table.yaml");
    let scene = Scene::load_spec(&plan.scene).expect("scene");
    let mut view = ViewObserver::new(&plan, None, Some(Recorder::new(&scene.model)), None);
    let report = run_episode(
        &scene,
        plan.clone(),
        &macrotree::factory::Factory::builtin(),
        &EpisodeConfig::default(),
        &mut view,
    );
    assert!(report.outcome.success, "{:?}", report.outcome.failure_reason);
    let (_, rec) = view.finish();
    rec.unwrap().write(path).unwrap();
    report
}

/// What the panel shows about the blackboard and the loop.
const BOARD: &str = "JSON.stringify({\
  time: document.querySelector('#replay-time').textContent,\
  rows: Array.from(document.querySelectorAll('#blackboard tbody tr')).map(tr => Array.from(tr.cells).map(c => c.textContent)),\
  loop: document.querySelector('#tree .node[data-path=LOOP] .attempts').textContent,\
  running: Array.from(document.querySelectorAll('#running li')).map(l => l.textContent),\
  labels: Array.from(document.querySelectorAll('#tree .node .name')).map(n => n.textContent),\
})";

#[test]
fn a_clear_table_replay_shows_the_blackboard_and_each_iteration_as_they_change() {
    if !browser_available() {
        return;
    }
    let dir = temp_dir("monitor-replay");
    let html = dir.join("clear_table.html");
    record_clear_table(&html);
    let size = std::fs::metadata(&html).unwrap().len();
    eprintln!("clear_table replay: {size} bytes");
    let plan = load("trees/clear_table.yaml");
    let each = plan
        .nodes
        .iter()
        .find(|n| n.kind == "for_each")
        .unwrap()
        .path
        .clone();
    let browser = Chromium::open(&format!("file://{}#t=0&paused", html.display()), WIDTH, HEIGHT);
    let mut dt = browser.devtools();
    dt.wait_until("typeof macrotree.timeline", Duration::from_secs(90), |v| {
        v == "function"
    });
    // The blackboard writes, from the recorded timeline.
    let writes = eval_json(
        &mut dt,
        "JSON.stringify([].concat(...macrotree.timeline().map(e => (e.events || []).filter(v => v && v.kind === 'blackboard'))))",
    );
    let writes = writes.as_array().unwrap().clone();
    let blocks: Vec<&serde_json::Value> = writes.iter().filter(|w| w["var"] == "block").collect();
    assert!(blocks.len() >= 2, "{writes:?}");
    assert_ne!(blocks[0]["value"], blocks[1]["value"], "{writes:?}");
    let start = eval_json(&mut dt, "JSON.stringify(macrotree.replayStart())")
        .as_f64()
        .unwrap();
    let js = BOARD.replace("LOOP", &format!("{each:?}"));
    for (k, w) in blocks.iter().take(2).enumerate() {
        let t = w["t"].as_f64().unwrap();
        dt.eval(&format!("macrotree.seek({})", t - start + 1e-4));
        let label = format!("{:.2} / ", t - start + 1e-4);
        dt.wait_until(&js, Duration::from_secs(20), |v| {
            serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null"))
                .is_ok_and(|s| s["time"].as_str().is_some_and(|x| x.starts_with(&label)))
        });
        std::thread::sleep(Duration::from_millis(300));
        let s = eval_json(&mut dt, &js);
        eprintln!("iteration {}: {s}", k + 1);
        let rows: Vec<Vec<String>> = serde_json::from_value(s["rows"].clone()).unwrap();
        let value = serde_json::to_string(&w["value"]).unwrap();
        let block = rows
            .iter()
            .find(|r| r[0] == "{block}")
            .unwrap_or_else(|| panic!("no {{block}} row: {s}"));
        assert_eq!(block[2], value, "{s}");
        assert_eq!(block[1], "string", "{s}");
        assert!(!block[3].is_empty(), "the writer is named: {s}");
        assert!(rows.iter().any(|r| r[0] == "{dest}"), "{s}");
        // The loop says which iteration runs and on what.
        let lp = s["loop"].as_str().unwrap();
        assert!(
            lp.starts_with(&format!("iteration {}", k + 1)) && lp.contains(&format!("{{block}}={value}")),
            "{s}"
        );
        // Labels show the values: `{block}="…"`.
        let labels = s["labels"].to_string();
        assert!(
            labels.contains(&format!("{{block}}={}", value.replace('"', "\\\""))),
            "{s}"
        );
        if k == 1 {
            // The retry's subtree collapsed, so the blackboard shows beside the loop.
            let retry = plan
                .nodes
                .iter()
                .find(|n| n.kind == "retry")
                .unwrap()
                .path
                .clone();
            dt.eval(&format!("macrotree.setCollapsed({retry:?}, true)"));
            screenshot(&mut dt, "monitor_blackboard.png");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn replay_markers_and_transition_steps_seek_to_failures_retries_and_trace_lines() {
    if !browser_available() {
        return;
    }
    // The flagship with a slipped grasp (seed 3): a failure, a halt and a retry.
    let dir = temp_dir("monitor-markers");
    let html = dir.join("slip.html");
    let plan = flagship::plan();
    let scene = flagship::scene();
    let mut view = ViewObserver::new(&plan, None, Some(Recorder::new(&scene.model)), None);
    let config = EpisodeConfig {
        fault: Some(macrotree::faults::FaultKind::Slip),
        seed: 3,
        ..EpisodeConfig::default()
    };
    let report = run_episode(
        scene,
        plan.clone(),
        &macrotree::factory::Factory::builtin(),
        &config,
        &mut view,
    );
    assert!(
        report.outcome.success && report.outcome.grasp_attempts == 2,
        "{report:?}"
    );
    view.finish().1.unwrap().write(&html).unwrap();
    let browser = Chromium::open(&format!("file://{}#t=0&paused", html.display()), WIDTH, HEIGHT);
    let mut dt = browser.devtools();
    dt.wait_until("typeof macrotree.timeline", Duration::from_secs(90), |v| {
        v == "function"
    });
    let markers = dt.wait_until(
        "JSON.stringify(Array.from(document.querySelectorAll('#markers .marker')).map(m => [m.className, Number(m.dataset.t), m.title]))",
        Duration::from_secs(30),
        |v| v.as_str().is_some_and(|s| s.len() > 2),
    );
    let markers: Vec<(String, f64, String)> = serde_json::from_str(markers.as_str().unwrap()).unwrap();
    eprintln!("{markers:?}");
    for cls in ["failure", "halted", "retry", "fault"] {
        assert!(
            markers.iter().any(|m| m.0.contains(cls)),
            "no {cls} marker: {markers:?}"
        );
    }
    let start = eval_json(&mut dt, "JSON.stringify(macrotree.replayStart())")
        .as_f64()
        .unwrap();
    // Clicking the retry marker seeks to it.
    let retry = markers.iter().find(|m| m.0.contains("retry")).unwrap();
    dt.eval("document.querySelector('#markers .marker.retry').click()");
    wait_replay_time(&mut dt, retry.1 - start);
    // ▶| goes to the next transition: the next timeline entry after the marker.
    let next = eval_json(
        &mut dt,
        &format!(
            "JSON.stringify(macrotree.timeline().map(e => e.t).find(t => t > {} + 1e-6))",
            retry.1
        ),
    )
    .as_f64()
    .unwrap();
    dt.eval("document.querySelector('#next').click()");
    wait_replay_time(&mut dt, next - start);
    // |◀ comes back.
    dt.eval("document.querySelector('#prev').click()");
    wait_replay_time(&mut dt, retry.1 - start);
    // Clicking a trace line seeks to its time.
    let line_t = eval_json(
        &mut dt,
        "JSON.stringify(Number(document.querySelectorAll('#events li[data-t]')[3].dataset.t))",
    )
    .as_f64()
    .unwrap();
    dt.eval("document.querySelectorAll('#events li[data-t]')[3].click()");
    wait_replay_time(&mut dt, line_t - start);
    screenshot(&mut dt, "monitor_markers.png");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Waits until the replay shows `seconds` since its start (to the hundredth).
fn wait_replay_time(dt: &mut Devtools, seconds: f64) {
    let want = format!("{seconds:.2} / ");
    dt.wait_until(
        "document.querySelector('#replay-time').textContent",
        Duration::from_secs(10),
        |v| v.as_str().is_some_and(|t| t.starts_with(&want)),
    );
}

/// Runs `plan` on the flagship scene with a live viewer on its own thread.
fn run_live(
    plan: Arc<Plan>,
    viewer: LiveViewer,
    breaks: &[BreakSpec],
    goal: Goal,
) -> std::thread::JoinHandle<(EpisodeReport, Vec<macrotree::viewer::ForcedRecord>)> {
    let breaks = breaks.to_vec();
    std::thread::spawn(move || {
        let mut view = ViewObserver::new(&plan, Some(viewer), None, None);
        view.set_breakpoints(&plan, &breaks).expect("breakpoints");
        let report = run_episode(
            flagship::scene(),
            plan.clone(),
            &macrotree::factory::Factory::builtin(),
            &EpisodeConfig {
                goal,
                ..EpisodeConfig::default()
            },
            &mut view,
        );
        let forced = view.forced().to_vec();
        (report, forced)
    })
}

/// What the page's monitor shows.
const MONITOR: &str = "JSON.stringify({\
  state: document.querySelector('#mon-state').textContent,\
  clock: document.querySelector('#clock').textContent,\
  here: Array.from(document.querySelectorAll('#tree .node.paused-here')).map(r => r.dataset.path),\
  events: Array.from(document.querySelectorAll('#events li')).map(l => l.textContent),\
})";

/// The simulated time, in seconds, at which the monitor's state says the episode is paused
/// ("… at 0.248 s").
fn paused_time(state: &serde_json::Value) -> Option<f64> {
    let text = state["state"].as_str()?;
    text.rsplit(" at ").next()?.strip_suffix(" s")?.parse().ok()
}

/// The page's clock, in seconds ("t = 0.25 s"); `None` ("t = –") before its first scene frame.
fn clock_time(state: &serde_json::Value) -> Option<f64> {
    let text = state["clock"].as_str()?;
    text.strip_prefix("t = ")?.strip_suffix(" s")?.parse().ok()
}

/// The monitor's state once the page shows the episode paused at node `at`, its clock at the
/// paused instant (to its two decimals: the scene frame of that instant may come after the
/// pause is shown).
fn wait_paused(dt: &mut Devtools, at: &str) -> serde_json::Value {
    let v = dt.wait_until(MONITOR, Duration::from_secs(120), |v| {
        serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null")).is_ok_and(|s| {
            s["state"].as_str().is_some_and(|t| t.starts_with("paused"))
                && s["here"][0] == at
                && paused_time(&s)
                    .zip(clock_time(&s))
                    .is_some_and(|(p, c)| (c - p).abs() <= 0.0051)
        })
    });
    serde_json::from_str(v.as_str().unwrap()).unwrap()
}

/// A report without its wall-clock fields (what must be bit-identical).
fn physics_of(report: &EpisodeReport) -> serde_json::Value {
    let mut v = serde_json::to_value(report).unwrap();
    let map = v.as_object_mut().unwrap();
    map.remove("wall_time_s");
    map.remove("planning");
    v
}

#[test]
fn breakpoints_pause_a_live_episode_which_then_ends_exactly_as_without_them() {
    if !browser_available() {
        return;
    }
    let plan = flagship::plan();
    let reference = run_episode(
        flagship::scene(),
        plan.clone(),
        &macrotree::factory::Factory::builtin(),
        &EpisodeConfig::default(),
        &mut NoObserver,
    );
    assert!(reference.outcome.success);
    let first_reach = plan
        .nodes
        .iter()
        .find(|n| n.kind == "reach")
        .unwrap()
        .path
        .clone();
    let carry = plan
        .nodes
        .iter()
        .find(|n| n.kind == "carry")
        .unwrap()
        .path
        .clone();
    let viewer = live();
    let url = viewer.url();
    let browser = Chromium::open(&url, WIDTH, HEIGHT);
    let declared: BreakSpec = first_reach.parse().unwrap();
    let episode = run_live(plan.clone(), viewer, &[declared], Goal::Scene);
    let mut dt = browser.devtools();
    // The declared breakpoint holds the episode before the first reach starts.
    let s = wait_paused(&mut dt, &first_reach);
    assert!(s["state"].as_str().unwrap().contains("before"), "{s}");
    // Simulated time stands still while paused.
    std::thread::sleep(Duration::from_millis(1500));
    let again = eval_json(&mut dt, MONITOR);
    assert_eq!(
        again["clock"], s["clock"],
        "time moved while paused: {s} → {again}"
    );
    screenshot(&mut dt, "monitor_paused.png");
    // From the page: a breakpoint after the carry (two clicks on its marker), then resume.
    for _ in 0..2 {
        dt.eval(&format!(
            "document.querySelector('#tree .node[data-path={carry:?}] .bp').click()"
        ));
        std::thread::sleep(Duration::from_millis(300));
    }
    dt.wait_until(
        &format!("document.querySelector('#tree .node[data-path={carry:?}] .bp').className"),
        Duration::from_secs(10),
        |v| v == "bp after",
    );
    dt.eval("document.querySelector('#mon-step').click()");
    // A step advances one control period and pauses again.
    let stepped = dt.wait_until(MONITOR, Duration::from_secs(30), |v| {
        serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null"))
            .is_ok_and(|x| x["state"].as_str().is_some_and(|t| t.contains("after a step")))
    });
    let stepped: serde_json::Value = serde_json::from_str(stepped.as_str().unwrap()).unwrap();
    let period = macrotree::actions::CONTROL_PERIOD;
    assert!(
        (paused_time(&stepped).unwrap() - paused_time(&s).unwrap() - period).abs() < 1e-9,
        "one control period later: {s} → {stepped}"
    );
    dt.eval("document.querySelector('#mon-resume').click()");
    let s = wait_paused(&mut dt, &carry);
    assert!(s["state"].as_str().unwrap().contains("after"), "{s}");
    dt.eval("document.querySelector('#mon-resume').click()");
    let (report, forced) = episode.join().unwrap();
    assert!(forced.is_empty());
    assert_eq!(
        physics_of(&report),
        physics_of(&reference),
        "pausing changed the episode"
    );
}

#[test]
fn a_failure_forced_from_the_page_runs_the_fallbacks_next_child_and_is_reported() {
    if !browser_available() {
        return;
    }
    let plan = Arc::new(
        Loader::default()
            .compile_str(
                "main:\n  fallback:\n    children:\n      - wait: {name: slow first choice, seconds: 5}\n      - home: {name: the fallback's next child}\n",
                "forced.yaml",
            )
            .unwrap(),
    );
    let wait = plan.nodes.iter().find(|n| n.kind == "wait").unwrap().path.clone();
    let home = plan.nodes.iter().find(|n| n.kind == "home").unwrap().path.clone();
    let viewer = live();
    let browser = Chromium::open(&viewer.url(), WIDTH, HEIGHT);
    let episode = run_live(
        plan.clone(),
        viewer,
        &[format!("{wait}@before").parse().unwrap()],
        Goal::Tree,
    );
    let mut dt = browser.devtools();
    wait_paused(&mut dt, &wait);
    dt.eval(&format!(
        "document.querySelector('#tree .node[data-path={wait:?}] button.force[data-result=failure]').click()"
    ));
    dt.wait_until(MONITOR, Duration::from_secs(20), |v| {
        v.as_str()
            .is_some_and(|s| s.contains("failure forced from the monitor"))
    });
    screenshot(&mut dt, "monitor_forced.png");
    dt.eval("document.querySelector('#mon-resume').click()");
    let (report, forced) = episode.join().unwrap();
    assert!(report.outcome.success, "{report:?}");
    assert!(
        report.outcome.sim_time_s < 5.0,
        "the wait did not run its 5 s: {}",
        report.outcome.sim_time_s
    );
    assert_eq!(forced.len(), 1);
    assert_eq!(forced[0].path, wait);
    let counts = |path: &str| {
        report
            .outcome
            .nodes
            .iter()
            .find(|n| n.path == path)
            .unwrap()
            .counts
    };
    assert_eq!(counts(&wait).overridden, 1);
    assert_eq!(counts(&wait).failures, 1);
    assert_eq!(counts(&home).successes, 1);
    let json = serde_json::to_value(&report).unwrap();
    let waits: Vec<&serde_json::Value> = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| n["path"] == wait.as_str())
        .collect();
    assert_eq!(
        waits[0]["overridden"], 1,
        "the report says the result was forced: {json}"
    );
    let other = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["path"] == home.as_str())
        .unwrap();
    assert!(
        other.get("overridden").is_none(),
        "only forced results are marked: {other}"
    );
}

#[test]
fn monitor_commands_are_parsed_strictly_and_breakpoints_by_pattern() {
    let ok = |v: serde_json::Value| MonitorCommand::parse(&v).unwrap();
    assert_eq!(
        ok(serde_json::json!({"type": "monitor", "op": "pause"})),
        MonitorCommand::Pause
    );
    assert_eq!(
        ok(serde_json::json!({"type": "monitor", "op": "break", "path": "main/x", "when": "after"})),
        MonitorCommand::Break {
            path: "main/x".into(),
            when: Some(BreakWhen::After)
        }
    );
    assert_eq!(
        ok(serde_json::json!({"type": "monitor", "op": "break", "path": "main/x", "when": null})),
        MonitorCommand::Break {
            path: "main/x".into(),
            when: None
        }
    );
    for bad in [
        serde_json::json!({"type": "img"}),
        serde_json::json!({"type": "monitor"}),
        serde_json::json!({"type": "monitor", "op": "explode"}),
        serde_json::json!({"type": "monitor", "op": "force", "path": "main/x", "result": "maybe"}),
        serde_json::json!({"type": "monitor", "op": "force", "result": "failure"}),
        serde_json::json!({"type": "monitor", "op": "break", "path": "", "when": "before"}),
        serde_json::json!({"type": "monitor", "op": "break", "path": "x".repeat(1001), "when": "before"}),
        serde_json::json!({"type": "monitor", "op": "break", "path": "main/x", "when": "during"}),
    ] {
        assert!(MonitorCommand::parse(&bad).is_err(), "{bad}");
    }
    let spec: BreakSpec = "main/**/grasp*@after".parse().unwrap();
    assert_eq!(
        (spec.pattern.as_str(), spec.when),
        ("main/**/grasp*", BreakWhen::After)
    );
    let spec: BreakSpec = "main/**/grasp".parse().unwrap();
    assert_eq!(spec.when, BreakWhen::Before);
    let plan = flagship::plan();
    let err = macrotree::viewer::Monitor::new(&plan, &["main/**/grsap".parse().unwrap()]).unwrap_err();
    assert!(err.contains("matches no node") && err.contains("grasp"), "{err}");
}

#[test]
fn a_paused_episode_waits_for_a_command_and_resumes_on_one() {
    // Without a browser: the episode pauses at the declared breakpoint and stays there; a
    // monitor command sent as the page sends it resumes it.
    let plan = flagship::plan();
    let viewer = live();
    let addr = viewer.local_addr();
    let first = plan
        .nodes
        .iter()
        .find(|n| n.kind == "reach")
        .unwrap()
        .path
        .clone();
    let started = Instant::now();
    let episode = run_live(plan.clone(), viewer, &[first.parse().unwrap()], Goal::Scene);
    std::thread::sleep(Duration::from_millis(800));
    assert!(
        !episode.is_finished(),
        "the episode did not wait at its breakpoint"
    );
    // Resume through a websocket client, as the page does.
    let mut ws = crate::websocket::connect(addr);
    ws.send(tungstenite::Message::text(r#"{"type":"monitor","op":"resume"}"#))
        .unwrap();
    // Read what the server sends (the snapshot, then the episode) until the episode is over.
    while !episode.is_finished() {
        if ws.read().is_err() {
            break;
        }
    }
    let (report, _) = episode.join().unwrap();
    assert!(report.outcome.success);
    assert!(started.elapsed() >= Duration::from_millis(800));
}
