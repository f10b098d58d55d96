//! The `policy` leaf on real MuJoCo and a real ONNX Runtime: the small constant models of
//! tests/fixtures/policy (make_models.py) drive the arm, end on their condition, fail typed, and
//! bad models are refused where the tree names them.

use macrotree::actions::CONTROL_PERIOD;
use macrotree::episode::{EpisodeConfig, EpisodeReport, Goal};
use macrotree::{App, FailureKind};

/// Where the fixtures are; trees are compiled as if written in this folder.
const FOLDER: &str = "tests/fixtures/policy";

fn run(yaml: &str) -> EpisodeReport {
    let app = App::new();
    let plan = app
        .compile_str(yaml, &format!("{FOLDER}/t.yaml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let config = EpisodeConfig {
        goal: Goal::Tree,
        ..EpisodeConfig::default()
    };
    app.run_episode(&plan, &config).unwrap()
}

fn load_error(yaml: &str) -> String {
    match App::new().compile_str(yaml, &format!("{FOLDER}/t.yaml")) {
        Ok(_) => panic!("the tree loaded:\n{yaml}"),
        Err(e) => e.to_string(),
    }
}

const AWAY: &str = "move_joints: {joints: [-1.2, -1.3, 1.4, -1.6, -1.57, 0.3]}";

#[test]
fn a_policy_leaf_drives_the_arm_to_its_models_set_points_until_its_condition_holds() {
    for (model, extra) in [
        ("home.onnx", ""),
        ("command_home.onnx", ""),
        ("normalized_home.onnx", ""),
        ("object_home.onnx", ", object: cube"),
    ] {
        let r = run(&format!(
            "main: {{sequence: {{children: [{{{AWAY}}}, {{policy: {{model: {model}{extra}, until: {{at_home: {{}}}}, timeout: 3}}}}]}}}}"
        ));
        assert!(r.outcome.success, "{model}: {:?}", r.outcome.failure_reason);
        // 0.37 rad at most 3 rad/s after a 0.38 s move: home within half a second more.
        assert!(r.outcome.sim_time_s < 1.2, "{model}: {} s", r.outcome.sim_time_s);
    }
}

#[test]
fn a_non_finite_action_fails_the_leaf_as_policy_output_invalid() {
    let r = run("main: {policy: {model: nan.onnx, timeout: 2}}");
    assert!(!r.outcome.success);
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::Custom("policy_output_invalid"))
    );
    assert!(
        r.outcome
            .failure_reason
            .as_deref()
            .unwrap_or("")
            .contains("finite"),
        "{:?}",
        r.outcome.failure_reason
    );
    assert!(
        r.outcome.sim_time_s < 0.1,
        "fails on its first call, not at its timeout: {} s",
        r.outcome.sim_time_s
    );
}

#[test]
fn a_policy_without_its_condition_times_out_and_a_fallback_takes_over() {
    let r = run("main: {policy: {model: still_relative.onnx, until: {at_home: {}}, timeout: 0.4}}");
    // The arm starts at home, so `at_home` holds at once: the relative zero action never moves it.
    assert!(r.outcome.success, "{:?}", r.outcome.failure_reason);
    let r = run(&format!(
        "main: {{sequence: {{children: [{{{AWAY}}}, {{policy: {{model: still_relative.onnx, until: {{at_home: {{}}}}, timeout: 0.4}}}}]}}}}"
    ));
    assert_eq!(
        r.outcome.failure_kind,
        Some(FailureKind::Timeout),
        "{:?}",
        r.outcome.failure_reason
    );
    let r = run(&format!(
        "main: {{sequence: {{children: [{{{AWAY}}}, {{fallback: {{children: [{{policy: {{model: still_relative.onnx, until: {{at_home: {{}}}}, timeout: 0.4}}}}, {{home: {{}}}}]}}}}]}}}}"
    ));
    assert!(
        r.outcome.success,
        "the scripted fallback brings the arm home: {:?}",
        r.outcome.failure_reason
    );
    assert_eq!(r.outcome.halts, 0);
}

#[test]
fn a_full_command_is_held_over_the_models_period_with_its_velocity_feedforward() {
    // command_drift.onnx answers, every 0.02 s: the set points where they are (relative zero),
    // shoulder_pan at 0.2 rad/s. Only the velocity it carries can move the arm.
    let app = App::new();
    let plan = app
        .compile_str(
            "main: {policy: {model: command_drift.onnx, timeout: 1}}",
            &format!("{FOLDER}/t.yaml"),
        )
        .unwrap_or_else(|e| panic!("{e}"));
    let config = EpisodeConfig {
        goal: Goal::Tree,
        ..EpisodeConfig::default()
    };
    let mut rec = PanJoint::default();
    let report = macrotree::episode::run_episode(
        &app.simulator(&plan).unwrap(),
        std::sync::Arc::new(plan),
        app.factory(),
        &config,
        &mut rec,
    );
    assert_eq!(
        report.outcome.failure_kind,
        Some(FailureKind::Timeout),
        "{:?}",
        report.outcome.failure_reason
    );
    let pan: Vec<(f64, f64)> = rec.commanded.clone();
    assert!(pan.len() > 200, "{} control periods", pan.len());
    let moving = &pan[1..pan.len() - 1];
    for &(_, qd) in moving {
        assert!((qd - 0.2).abs() < 1e-6, "the velocity is the model's: {qd}");
    }
    // Every control period the set point advances by the velocity times the period (4 ms),
    // inside a model period (the command's second-order hold) and across calls (relative).
    for w in moving.windows(2) {
        let advance = w[1].0 - w[0].0;
        assert!((advance - 0.2 * CONTROL_PERIOD).abs() < 1e-6, "{advance}");
    }
    let travelled = moving.last().unwrap().0 - moving[0].0;
    assert!((0.19..0.21).contains(&travelled), "{travelled} rad in about 1 s");
    // The joint follows its set point.
    let lag = moving.last().unwrap().0 - rec.measured;
    assert!(lag.abs() < 0.01, "shoulder_pan {lag} rad behind its set point");
}

/// Records shoulder_pan's command (set point, velocity) each control period and its last
/// measured angle, radians.
#[derive(Default)]
struct PanJoint {
    commanded: Vec<(f64, f64)>,
    measured: f64,
}

impl macrotree::episode::EpisodeObserver for PanJoint {
    fn on_period_start(
        &mut self,
        _cell: &macrotree::actions::Cell,
        command: &macrotree::motion::CellCommand,
        _runner: &mut macrotree::runtime::TreeRunner,
    ) {
        self.commanded.push((command.arm.q[0], command.arm.qd[0]));
    }
    fn on_tick(&mut self, cell: &macrotree::actions::Cell, _runner: &mut macrotree::runtime::TreeRunner) {
        self.measured = cell.world().arm_q[0];
    }
}

/// The model calls in a `timeout` failure's reason ("… after N model calls").
fn calls(r: &EpisodeReport) -> u32 {
    let reason = r.outcome.failure_reason.as_deref().unwrap_or("");
    let n = reason
        .split("after ")
        .last()
        .and_then(|s| s.split(' ').next())
        .and_then(|n| n.parse().ok());
    n.unwrap_or_else(|| panic!("no call count in {reason:?}"))
}

#[test]
fn a_chunk_runs_its_steps_before_the_model_runs_again() {
    let tree = |steps: &str| {
        format!(
            "main: {{sequence: {{children: [{{{AWAY}}}, {{policy: {{model: chunk.onnx, until: {{at_home: {{}}}}, timeout: 0.4{steps}}}}}]}}}}"
        )
    };
    // 0.4 s at 0.02 s per action: 20 actions, in chunks of 4 or one by one.
    let whole = calls(&run(&tree("")));
    let single = calls(&run(&tree(", n_action_steps: 1")));
    assert!((5..=6).contains(&whole), "{whole}");
    assert!((20..=21).contains(&single), "{single}");
    let r = run(&tree(", n_action_steps: 5"));
    assert!(
        r.outcome
            .failure_reason
            .unwrap_or_default()
            .contains("chunk of 4")
    );
}

#[test]
fn the_same_tree_and_model_give_the_same_episode() {
    let yaml = format!(
        "main: {{sequence: {{children: [{{{AWAY}}}, {{policy: {{model: object_home.onnx, object: cube, until: {{at_home: {{}}}}, period: 0.02}}}}]}}}}"
    );
    let a = run(&yaml);
    let b = run(&yaml);
    assert!(a.outcome.success);
    assert_eq!(a.outcome.sim_time_s.to_bits(), b.outcome.sim_time_s.to_bits());
    assert_eq!(a.outcome.physics_steps, b.outcome.physics_steps);
    assert_eq!(
        serde_json::to_string(&a.outcome.objects).unwrap(),
        serde_json::to_string(&b.outcome.objects).unwrap()
    );
}

#[test]
fn a_model_that_does_not_fit_is_refused_at_its_model_value() {
    for (model, says) in [
        ("unknown_input.onnx", "input `obs` is not a feature"),
        (
            "short_action.onnx",
            "expected the action, [1, n] or a chunk [1, k, n], with n = 7",
        ),
        ("missing.onnx", "cannot read `missing.onnx`"),
        ("../trees/pick_place.yaml", "outside the tree's folder"),
        ("make_models.py", "ONNX Runtime cannot load the model"),
    ] {
        let e = load_error(&format!("main:\n  policy: {{model: {model}, timeout: 2}}\n"));
        assert!(e.contains(says), "{model}: {e}");
        assert!(e.contains("t.yaml:2:19"), "{model}: located at the value: {e}");
    }
}

#[test]
fn the_model_file_is_an_input_of_the_tree() {
    let plan = App::new()
        .compile_str("main: {policy: {model: home.onnx}}", &format!("{FOLDER}/t.yaml"))
        .unwrap();
    let model = std::fs::canonicalize(format!("{FOLDER}/home.onnx")).unwrap();
    assert!(plan.inputs.contains(&model), "{:?}", plan.inputs);
}

#[test]
fn an_unknown_object_in_until_is_refused_where_it_is_written() {
    let e = load_error("main:\n  policy: {model: home.onnx, until: {grasped: {object: cub}}}\n");
    assert!(e.contains("`cub`") && e.contains("cube"), "{e}");
    assert!(e.contains("t.yaml:2:56"), "{e}");
    let e = load_error("main:\n  policy: {model: home.onnx, until: {in: {object: cube, container: cube}}}\n");
    assert!(e.contains("container"), "a block where a container belongs: {e}");
}

#[test]
fn a_policy_tree_records_a_dataset_whose_actions_replay_to_the_same_outcome() {
    use macrotree::dataset::{DEFAULT_FRAME_RATE, EpisodeRecorder};
    use macrotree::env::{Action, EnvConfig, MacroEnv, Reset};
    use macrotree::sweep::SweepConfig;

    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/trees/learned_cube_to_bowl.yaml");
    let plan = std::sync::Arc::new(
        macrotree::plan::Loader::default()
            .load(std::path::Path::new(path))
            .expect("the learned tree is valid"),
    );
    let scene = crate::support::flagship::scene();
    let sweep = SweepConfig {
        seed: 7,
        ..Default::default()
    };
    let fps = DEFAULT_FRAME_RATE;
    let mut env = MacroEnv::new(
        &App::new(),
        scene.clone(),
        None,
        EnvConfig {
            control_period: 1.0 / f64::from(fps),
            ..EnvConfig::default()
        },
    )
    .unwrap();
    for index in 0..3 {
        let s = sweep.scenario(scene, index).unwrap();
        let mut rec = EpisodeRecorder::new(plan.clone(), fps);
        let report = macrotree::episode::run_episode(
            scene,
            plan.clone(),
            &macrotree::factory::Factory::builtin(),
            &sweep.episode_config(&s),
            &mut rec,
        );
        assert!(
            report.outcome.success,
            "scenario {index}: {:?}",
            report.outcome.failure_reason
        );
        let frames = rec.finish().unwrap().frames;
        let learned = frames.iter().filter(|f| f.active_kind == "policy").count();
        assert!(
            learned * 5 > frames.len(),
            "scenario {index}: {learned} of {} frames are labelled with the policy leaf",
            frames.len()
        );
        env.reset(&Reset::Scenario {
            index,
            sweep_seed: sweep.seed,
        })
        .unwrap();
        for f in &frames {
            env.step(&Action::Ctrl(f.action.map(f64::from))).unwrap();
        }
        let in_bowl = env.step(&Action::Leaf("goal_met: {}".into())).unwrap().success();
        assert!(
            in_bowl,
            "scenario {index}: the dataset's actions replay the learned episode"
        );
    }
}

/// The shipped learned tree with `closing_chunk.onnx` in place of its model: the policy closes
/// the gripper at home and never holds the cube, so the scripted pick takes over. It must open
/// the gripper before it descends, or the closed fingers stop on the cube in every attempt.
#[test]
fn the_learned_trees_scripted_pick_opens_a_gripper_the_policy_closed() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = crate::support::cli::scratch("learned-tree-closing-policy").join("trees");
    for sub in ["lib", "policies"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    for file in ["learned_cube_to_bowl.yaml", "lib/learned_pick.yaml"] {
        std::fs::copy(root.join("trees").join(file), dir.join(file)).unwrap();
    }
    std::fs::copy(
        root.join(FOLDER).join("closing_chunk.onnx"),
        dir.join("policies/cube_pick.onnx"),
    )
    .unwrap();
    let path = dir.join("learned_cube_to_bowl.yaml");
    let app = App::new();
    let plan = app
        .compile_str(&std::fs::read_to_string(&path).unwrap(), path.to_str().unwrap())
        .unwrap_or_else(|e| panic!("{e}"));
    let report = app.run_episode(&plan, &EpisodeConfig::default()).unwrap();
    assert!(report.outcome.success, "{:?}", report.outcome.failure_reason);
    let node = |tail: &str| {
        report
            .outcome
            .nodes
            .iter()
            .find(|n| n.path.ends_with(tail))
            .unwrap_or_else(|| panic!("no node {tail}"))
    };
    let policy = node("policy[approach and grasp]");
    assert_eq!(
        (policy.counts.activations, policy.counts.failures),
        (1, 1),
        "the policy ran once and gave up"
    );
    let fallback = node("subtree[scripted_pick]");
    assert_eq!(
        (fallback.counts.activations, fallback.counts.successes),
        (1, 1),
        "the scripted pick held the cube at its first try"
    );
    assert!(
        report.outcome.collisions.is_empty(),
        "{:?}",
        report.outcome.collisions
    );
}
