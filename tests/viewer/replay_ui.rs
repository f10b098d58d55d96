//! The replay page in a real headless Chromium, on the replay of a real episode with a slipped
//! grasp (so a retry restarts its child): long node names wrap inside the panel and show whole
//! on hover, a legend explains the colours, nodes of the failed attempt are reset to idle
//! with the previous outcome as a badge, trace events are readable lines, the URL opens the
//! replay paused at an instant (`#t=2.6&paused`), the arrow keys step it and the URL follows, and
//! the default camera shows the objects.

use std::sync::Arc;
use std::time::Duration;

use crate::support::browser;
use browser::*;
use macrotree::episode::{EpisodeConfig, run_episode};
use macrotree::faults::FaultKind;
use macrotree::sim::Scene;
use macrotree::viewer::{Recorder, ViewObserver};

const LONG_NAME: &str = "carry the cube while it is held all the way over to the bowl and onto it";

/// What the panel shows, as JSON.
const STATE: &str = "JSON.stringify((() => {\
  const rows = Array.from(document.querySelectorAll('#tree .node'));\
  const row = (name) => rows.find(r => r.querySelector('.name').textContent.includes(name));\
  const info = (r) => r && ({status: r.dataset.status, badge: r.querySelector('.badge').textContent,\
     title: r.title, cut: r.querySelector('.name').scrollWidth > r.querySelector('.name').clientWidth,\
     right: r.querySelector('.name').getBoundingClientRect().right});\
  return {\
    time: document.querySelector('#replay-time').textContent,\
    playing: document.querySelector('#play').textContent !== '▶',\
    hash: location.hash,\
    guard: info(row(LONG)),\
    carry: info(rows.find(r => r.querySelector('.kind').textContent === 'carry')),\
    preshape: info(row('pre-shape')),\
    panel: document.querySelector('#panel').getBoundingClientRect().right,\
    legend: Array.from(document.querySelectorAll('#legend li')).map(l => l.textContent),\
    events: Array.from(document.querySelectorAll('#events li')).map(l => l.textContent),\
  };\
})())";

fn state(dt: &mut Devtools) -> serde_json::Value {
    let js = STATE.replace("LONG", &format!("{LONG_NAME:?}"));
    serde_json::from_str(dt.eval(&js).as_str().unwrap_or("null")).unwrap_or_default()
}

/// Records the flagship with a slip (seed 3: the grasp slips during the carry at 2.39 s and the
/// retry's second attempt starts at 2.41 s), the guard renamed to a long name.
fn record(path: &std::path::Path) {
    let yaml = std::fs::read_to_string("trees/cube_to_bowl.yaml")
        .unwrap()
        .replace("name: carry while held", &format!("name: {LONG_NAME}"));
    assert!(yaml.contains(LONG_NAME));
    let plan = Arc::new(
        macrotree::plan::Loader::default()
            .compile_str(&yaml, "trees/long_names.yaml")
            .expect("tree"),
    );
    let scene = Scene::load().unwrap();
    let config = EpisodeConfig {
        fault: Some(FaultKind::Slip),
        seed: 3,
        ..EpisodeConfig::default()
    };
    let mut view = ViewObserver::new(&plan, None, Some(Recorder::new(&scene.model)), None);
    let report = run_episode(
        &scene,
        plan.clone(),
        &macrotree::factory::Factory::builtin(),
        &config,
        &mut view,
    );
    assert!(
        report.outcome.success && report.outcome.grasp_attempts == 2,
        "{report:?}"
    );
    let (_, rec) = view.finish();
    rec.unwrap().write(path).unwrap();
}

#[test]
fn the_replay_opens_at_an_instant_explains_its_colours_and_resets_a_retried_attempt() {
    if !browser_available() {
        return;
    }
    let dir = temp_dir("replay-ui");
    let html = dir.join("replay.html");
    record(&html);
    let browser = Chromium::open(&format!("file://{}#t=2.6&paused", html.display()), 1000, 640);
    let mut dt = browser.devtools();
    let s = dt.wait_until(
        &STATE.replace("LONG", &format!("{LONG_NAME:?}")),
        Duration::from_secs(90),
        |v| {
            serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null"))
                .is_ok_and(|s| s["time"].as_str().is_some_and(|t| t.starts_with("2.60 / ")))
        },
    );
    let _ = s;
    std::thread::sleep(Duration::from_millis(1500));
    let s = state(&mut dt);
    eprintln!("{s:#}");
    // Paused where the URL says, and it stays there.
    assert!(s["time"].as_str().unwrap().starts_with("2.60 / "), "{s}");
    assert_eq!(s["playing"], false, "{s}");

    // The guard and the carry of attempt 1 are idle again, their outcome kept as a badge; the
    // pre-shape of attempt 2 runs.
    assert_eq!(s["guard"]["status"], "idle", "{s}");
    assert_eq!(s["guard"]["badge"], "failure", "{s}");
    assert_eq!(s["carry"]["status"], "idle", "{s}");
    assert_eq!(s["carry"]["badge"], "halted", "{s}");
    assert_eq!(s["preshape"]["status"], "running", "{s}");
    assert_eq!(s["preshape"]["badge"], "success", "{s}");

    // The long name wraps inside the panel, whole (never cut), and is whole on hover too.
    assert_eq!(s["guard"]["cut"], false, "{s}");
    assert!(
        s["guard"]["right"].as_f64().unwrap() <= s["panel"].as_f64().unwrap(),
        "{s}"
    );
    assert!(s["guard"]["title"].as_str().unwrap().contains(LONG_NAME), "{s}");

    // A legend names every colour, orange (halted) included.
    let legend: Vec<String> = serde_json::from_value(s["legend"].clone()).unwrap();
    for word in [
        "idle",
        "running",
        "success",
        "failure",
        "halted",
        "previous attempt",
    ] {
        assert!(legend.iter().any(|l| l.contains(word)), "{word}: {legend:?}");
    }

    // Events are lines for people: times to the millisecond, names, arrows; no raw JSON.
    let events: Vec<String> = serde_json::from_value(s["events"].clone()).unwrap();
    assert!(!events.is_empty());
    let long_digits = regex_like_digits(&events);
    assert!(
        long_digits.is_none(),
        "a number with many digits: {long_digits:?}"
    );
    assert!(events.iter().all(|e| !e.contains("{\"")), "{events:?}");
    assert!(
        events
            .iter()
            .any(|e| e.contains(&format!("{LONG_NAME}\": running → failure"))
                && e.contains("attempt 1")
                && e.contains("cube_grasped: not satisfied")),
        "{events:?}"
    );
    assert!(
        events
            .iter()
            .any(|e| e.contains("→ idle (reset for the next attempt)")),
        "{events:?}"
    );

    // The arrow keys step 0.1 s (paused), and the URL follows the instant shown.
    for _ in 0..2 {
        for kind in ["keyDown", "keyUp"] {
            dt.call(
                "Input.dispatchKeyEvent",
                serde_json::json!({"type": kind, "code": "ArrowRight", "key": "ArrowRight", "windowsVirtualKeyCode": 39}),
            );
        }
    }
    let s = dt.wait_until(
        &STATE.replace("LONG", &format!("{LONG_NAME:?}")),
        Duration::from_secs(10),
        |v| {
            serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null"))
                .is_ok_and(|s| s["time"].as_str().is_some_and(|t| t.starts_with("2.80 / ")))
        },
    );
    let s: serde_json::Value = serde_json::from_str(s.as_str().unwrap()).unwrap();
    assert_eq!(s["hash"], "#t=2.8&paused", "{s}");
    assert_eq!(s["playing"], false, "{s}");
    // Space plays.
    for kind in ["keyDown", "keyUp"] {
        dt.call(
            "Input.dispatchKeyEvent",
            serde_json::json!({"type": kind, "code": "Space", "key": " ", "windowsVirtualKeyCode": 32}),
        );
    }
    dt.wait_until(
        &STATE.replace("LONG", &format!("{LONG_NAME:?}")),
        Duration::from_secs(10),
        |v| {
            serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null"))
                .is_ok_and(|s| s["playing"] == true)
        },
    );

    // The default camera at the start: cube, bowl and robot all in view.
    dt.call(
        "Page.navigate",
        serde_json::json!({ "url": format!("file://{}#t=0&paused", html.display()) }),
    );
    dt.wait_until(
        &STATE.replace("LONG", &format!("{LONG_NAME:?}")),
        Duration::from_secs(90),
        |v| {
            serde_json::from_str::<serde_json::Value>(v.as_str().unwrap_or("null"))
                .is_ok_and(|s| s["time"].as_str().is_some_and(|t| t.starts_with("0.00 / ")))
        },
    );
    std::thread::sleep(Duration::from_millis(1500));
    let shot = decode_png(&dt.screenshot());
    let c = classify(&shot);
    eprintln!("camera at t = 0: {c:?}");
    assert_scene_visible(c, "replay at t = 0");
    drop(browser);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The first run of 7 or more digits in the events (a float printed with all its digits).
fn regex_like_digits(events: &[String]) -> Option<String> {
    events.iter().find_map(|e| {
        let mut run = String::new();
        for c in e.chars() {
            if c.is_ascii_digit() {
                run.push(c);
                if run.len() >= 7 {
                    return Some(e.clone());
                }
            } else {
                run.clear();
            }
        }
        None
    })
}
