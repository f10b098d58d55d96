//! What a newcomer trips on, and the diagnostics that catch it: angles written in degrees
//! without `deg(..)`, a range error in a subtree argument (shown at the call), an indentation
//! mistake (in our words, at the wrong line), a condition given an action's parameter.

use std::path::Path;

use crate::support::cli;

use macrotree::kinds::{Reach, Yaw};
use macrotree::plan::Loader;
use macrotree::spec::Diagnostic;

fn errors(yaml: &str) -> Vec<Diagnostic> {
    match Loader::default().compile_str(yaml, "bad.yaml") {
        Ok(_) => panic!("expected errors for:\n{yaml}"),
        Err(d) => d,
    }
}

fn show(diags: &[Diagnostic]) -> String {
    diags.iter().map(|d| d.to_string()).collect::<Vec<_>>().join("\n")
}

#[test]
fn a_bare_angle_beyond_a_full_turn_is_an_error_that_suggests_degrees() {
    for (yaml, col) in [
        ("main: {reach: {target: cube, yaw: 90}}\n", 35),
        ("main: {at: {object: cube, point: [0.3, 0.2], yaw: -90}}\n", 51),
        (
            "main: {at: {object: cube, point: [0.3, 0.2], yaw: 0, yaw_tolerance: 7.5}}\n",
            69,
        ),
        (
            "main: {move_joints: {joints: [0, -1.57, 1.57, -1.57, -1.57, 180]}}\n",
            61,
        ),
    ] {
        let d = errors(yaml);
        assert_eq!(d.len(), 1, "{}", show(&d));
        assert_eq!((d[0].line, d[0].column), (1, col), "{}", show(&d));
        assert!(d[0].message.contains("more than a full turn"), "{}", d[0]);
        let help = d[0].help.as_deref().unwrap_or("");
        assert!(help.starts_with("write deg("), "{}", d[0]);
        assert!(!d[0].warning);
    }
    // Radians within a turn, and degrees written as such, are fine.
    for yaml in [
        "main: {reach: {target: cube, yaw: 1.57}}\n",
        "main: {reach: {target: cube, yaw: deg(90)}}\n",
        "main: {reach: {target: cube, yaw: -6.2}}\n",
        "main: {reach: {target: cube, yaw: rad(10)}}\n",
    ] {
        let plan = Loader::default()
            .compile_str(yaml, "ok.yaml")
            .unwrap_or_else(|d| panic!("{yaml}: {}", show(&d)));
        assert!(plan.warnings.is_empty(), "{yaml}: {}", show(&plan.warnings));
    }
}

#[test]
fn a_whole_number_of_two_or_more_radians_is_a_warning() {
    let plan = Loader::default()
        .compile_str("main: {reach: {target: cube, yaw: 5}}\n", "w.yaml")
        .expect("accepted");
    let Some(r) = plan.leaves[0].kind.params::<Reach>() else {
        panic!("not a reach")
    };
    assert_eq!(r.yaw, Yaw::Angle(5.0), "still read as radians");
    assert_eq!(plan.warnings.len(), 1);
    let w = &plan.warnings[0];
    assert!(w.warning);
    assert_eq!((w.line, w.column), (1, 35));
    assert!(
        w.to_string()
            .starts_with("warning: `5` is read as 5 rad (286.5°)"),
        "{w}"
    );
    assert!(w.help.as_deref().unwrap().starts_with("write deg(5)"), "{w}");
    // `yaw: 3` (171.9°) is almost certainly 3° too.
    let plan = Loader::default()
        .compile_str("main: {reach: {target: cube, yaw: 3}}\n", "w.yaml")
        .unwrap();
    assert_eq!(plan.warnings.len(), 1, "{:?}", plan.warnings);
    assert!(
        plan.warnings[0].to_string().contains("171.9°"),
        "{}",
        plan.warnings[0]
    );
    // 1 rad is a plausible angle; 5.0 is written as a real number on purpose.
    for yaml in [
        "main: {reach: {target: cube, yaw: 1}}\n",
        "main: {reach: {target: cube, yaw: 5.0}}\n",
        "main: {reach: {target: cube, yaw: deg(90)}}\n",
    ] {
        assert!(
            Loader::default()
                .compile_str(yaml, "w.yaml")
                .unwrap()
                .warnings
                .is_empty(),
            "{yaml}"
        );
    }
}

#[test]
fn degrees_written_as_radians_are_a_located_warning_with_both_readings() {
    let plan = Loader::default()
        .compile_str("main: {reach: {target: cube, yaw: deg(1.5708)}}\n", "w.yaml")
        .expect("accepted");
    assert_eq!(plan.warnings.len(), 1, "{:?}", plan.warnings);
    let w = &plan.warnings[0];
    assert_eq!((w.line, w.column), (1, 35), "{w}");
    assert!(w.to_string().contains("looks like radians (90°)"), "{w}");
    assert!(w.help.as_deref().unwrap().contains("deg(90)"), "{w}");
}

#[test]
fn validate_prints_warnings_and_still_accepts_the_tree() {
    let dir = cli::scratch("newcomer-warning");
    let tree = dir.join("yaw.yaml");
    std::fs::write(&tree, "main: {reach: {target: cube, yaw: 4}}\n").unwrap();
    let out = cli::macrotree(&["validate", cli::s(&tree)]);
    assert_eq!(out.status.code(), Some(0));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("warning: `4` is read as 4 rad (229.2°)"), "{err}");
    assert!(err.contains("yaw.yaml:1:35"), "{err}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("ok with 1 warning(s)"));
    let json = cli::macrotree(&["validate", "--format", "json", cli::s(&tree)]);
    let v: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(v["valid"], true);
    assert_eq!(v["diagnostics"][0]["severity"], "warning");
}

#[test]
fn a_range_error_in_a_subtree_argument_points_at_the_call() {
    let d = match Loader::default().load(Path::new("tests/fixtures/trees/newcomer/handover.yaml")) {
        Ok(_) => panic!("x: 55 must be refused"),
        Err(d) => d,
    };
    assert_eq!(d.len(), 1, "one error, at the argument:\n{}", show(&d));
    assert!(d[0].file.ends_with("handover.yaml"), "{}", d[0]);
    assert_eq!((d[0].line, d[0].column), (7, 44), "{}", d[0]);
    assert!(
        d[0].message.contains("55 m is beyond the arm's full reach"),
        "{}",
        d[0]
    );
    let note = d[0].note.as_deref().unwrap_or("");
    assert!(
        note.contains("subtree argument, used at") && note.contains("cell_skills.yaml:8:30"),
        "{}",
        d[0]
    );
    // An out-of-reach point whose coordinates are each in range: still at the argument.
    let yaml = "subtrees:\n  go:\n    params: {p: 0.9}\n    root: {reach: {target: [$p, $p, 0.9]}}\nmain:\n  subtree: {ref: go, args: {p: 1.2}}\n";
    let d = errors(yaml);
    assert_eq!(d.len(), 1, "{}", show(&d));
    assert_eq!((d[0].line, d[0].column), (6, 32), "{}", d[0]);
    assert!(d[0].message.contains("exceeds the arm's full reach"), "{}", d[0]);
    assert!(
        d[0].note.as_deref().unwrap_or("").contains("bad.yaml:4:29"),
        "{}",
        d[0]
    );
}

#[test]
fn an_indentation_mistake_is_named_at_its_line() {
    let yaml = "main:\n  sequence:\n    children:\n      - home: {}\n     - reach: {target: cube}\n";
    let d = errors(yaml);
    assert_eq!(d.len(), 1, "{}", show(&d));
    assert_eq!(d[0].message, "this line is indented shallower than its siblings");
    assert_eq!((d[0].line, d[0].column), (5, 6));
    assert!(
        d[0].help
            .as_deref()
            .unwrap()
            .contains("indent it by 6 spaces like line 4"),
        "{}",
        d[0]
    );
    let yaml = "main:\n  sequence:\n     name: x\n    children:\n      - home: {}\n";
    let d = errors(yaml);
    assert_eq!(d[0].message, "this line is indented deeper than its siblings");
    assert_eq!(d[0].line, 3, "the first key set the indentation: {}", d[0]);
    let yaml = "main:\n  sequence:\n    children:\n      - home: {}\n      reach: {target: cube}\n";
    let d = errors(yaml);
    assert_eq!(d[0].message, "a list item needs \"- \"");
    assert_eq!(d[0].help.as_deref(), Some("write `- reach: {target: cube}`"));
    assert!(!d[0].to_string().contains("did not find expected"), "{}", d[0]);
}

#[test]
fn a_condition_given_a_timeout_explains_that_conditions_are_instantaneous() {
    let d = errors("main: {cube_in_bowl: {timeout: 2}}\n");
    assert_eq!(d.len(), 1, "{}", show(&d));
    assert_eq!((d[0].line, d[0].column), (1, 23));
    let help = d[0].help.as_deref().unwrap();
    assert!(help.starts_with("conditions are instantaneous"), "{help}");
    assert!(help.contains("timeout: {seconds: 2, child: {retry:"), "{help}");
    assert!(help.contains("guard: {condition: {cube_in_bowl: {}}"), "{help}");
    // The suggested wrapping is itself a valid tree.
    Loader::default()
        .compile_str(
            "main: {timeout: {seconds: 2, child: {retry: {attempts: 1000, child: {cube_in_bowl: {}}}}}}\n",
            "ok.yaml",
        )
        .unwrap_or_else(|d| panic!("{}", show(&d)));
    // An action keeps the ordinary help.
    let d = errors("main: {home: {timeot: 2}}\n");
    assert!(!d[0].help.as_deref().unwrap_or("").contains("instantaneous"));
}

#[test]
fn cube_at_checks_the_yaw_of_a_placement() {
    use macrotree::episode::{EpisodeConfig, Goal, NoObserver, run_episode};
    use macrotree::sim::{Layout, Scene};
    let scene = Scene::load().expect("scene");
    let check = |yaw: &str, cube_yaw_deg: f64| {
        let yaml = format!(
            "main: {{cube_at: {{point: [0.45, -0.18], tolerance: 0.01, yaw: {yaw}, yaw_tolerance: deg(3)}}}}\n"
        );
        let plan = std::sync::Arc::new(
            Loader::default()
                .compile_str(&yaml, "at.yaml")
                .unwrap_or_else(|d| panic!("{}", show(&d))),
        );
        let config = EpisodeConfig {
            placement: Some(scene.placement_from_layout(&Layout {
                cube_yaw: cube_yaw_deg.to_radians(),
                ..Layout::default()
            })),
            goal: Goal::Tree,
            ..EpisodeConfig::default()
        };
        run_episode(
            &scene,
            plan,
            &macrotree::factory::Factory::builtin(),
            &config,
            &mut NoObserver,
        )
        .outcome
        .success
    };
    assert!(check("deg(30)", 30.0), "a cube turned 30° is at 30°");
    assert!(
        check("deg(120)", 30.0),
        "…and at 120° (a quarter turn looks the same)"
    );
    assert!(!check("deg(30)", 0.0), "a square cube is not at 30°");
    assert!(!check("deg(30)", 35.0), "5° off is outside 3°");
}
