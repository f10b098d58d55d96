//! The step-wise environment on real MuJoCo: resets, leaves given as mappings, low-level
//! control, observations, determinism, and invalid input refused with clear errors.

use macrotree::App;
use macrotree::env::{Action, Duration, EnvConfig, MacroEnv, Observation, Primitive, Reset, Status};
use macrotree::sim::TIMESTEP;

use crate::support::flagship;

fn env(config: EnvConfig) -> MacroEnv {
    MacroEnv::new(&App::new(), flagship::scene().clone(), None, config).expect("env")
}

fn leaf(text: &str) -> Action {
    Action::Leaf(text.to_string())
}

/// Every number of an observation, as bits.
fn bits(o: &Observation) -> Vec<u64> {
    let mut v: Vec<f64> = vec![o.time, o.gripper_joint, o.gripper_width, o.gripper_command];
    v.extend(o.joint_pos.iter().chain(&o.joint_vel).chain(&o.joint_target));
    v.extend(
        o.pinch_pos
            .iter()
            .chain(&o.pinch_quat)
            .chain(&o.left_pad_pos)
            .chain(&o.right_pad_pos),
    );
    for b in &o.objects {
        v.extend(b.pos.iter().chain(&b.quat).chain(&b.linvel).chain(&b.angvel));
    }
    v.into_iter().map(f64::to_bits).collect()
}

fn episode(env: &mut MacroEnv) -> Vec<Vec<u64>> {
    let mut trace = vec![bits(&env.reset(&Reset::Seed(3)).unwrap())];
    let actions = [
        leaf(r#"{"reach": {"target": "cube", "offset": [0, 0, 0.12]}}"#),
        leaf("reach: {target: cube, path: cartesian}"),
        leaf("grasp: {}"),
        Action::Setpoint({
            let o = env.observe();
            let q = o.joint_pos;
            [q[0], q[1], q[2] - 0.05, q[3], q[4], q[5], 255.0]
        }),
        Action::Primitive(Primitive::Wait {
            duration: Duration::Seconds(0.1),
            gripper: None,
        }),
    ];
    for a in &actions {
        let r = env.step(a).unwrap();
        trace.push(bits(&r.observation));
        trace.push(env.cell().sim().state_fingerprint());
    }
    trace
}

#[test]
fn the_same_reset_and_actions_give_bit_identical_observations() {
    let mut a = env(EnvConfig::default());
    let mut b = env(EnvConfig::default());
    let first = episode(&mut a);
    assert_eq!(first, episode(&mut b), "two environments");
    assert_eq!(first, episode(&mut a), "the same environment after a reset");
    // Another seed places the cube elsewhere.
    let other = b.reset(&Reset::Seed(4)).unwrap();
    assert_ne!(bits(&other), first[0]);
}

#[test]
fn a_leaf_mapping_runs_to_completion_on_physics_and_reports_time_and_steps() {
    let mut env = env(EnvConfig::default());
    let start = env.reset(&Reset::Default).unwrap();
    assert_eq!(start.time, 0.0);
    let cube = start.object("cube").unwrap().pos;
    let r = env
        .step(&leaf(r#"{"reach": {"target": "cube", "offset": [0, 0, 0.12]}}"#))
        .unwrap();
    assert_eq!(r.status, Status::Success, "{:?}", r.failure);
    assert!(r.failure.is_none());
    let p = r.observation.pinch_pos;
    let err = ((p[0] - cube[0]).powi(2) + (p[1] - cube[1]).powi(2) + (p[2] - cube[2] - 0.12).powi(2)).sqrt();
    assert!(err < 0.003, "pinch {p:?} is {err} m from above the cube");
    assert!(r.sim_time > 0.2, "{}", r.sim_time);
    assert_eq!(r.physics_steps, (r.sim_time / TIMESTEP).round() as u64);
    assert_eq!(r.physics_steps % 2, 0, "whole control periods of 2 physics steps");
    assert_eq!((r.reward, r.terminated, r.truncated), (0.0, false, false));
    assert_eq!(r.goal.len(), 1);
    assert!(!r.goal[0].holds);
    // A condition answers at once, without physics, with a typed failure and the node path.
    let r = env.step(&leaf("cube_grasped: {}")).unwrap();
    assert_eq!(r.status, Status::Failure);
    assert_eq!(r.physics_steps, 0);
    let f = r.failure.unwrap();
    assert_eq!(f.kind.as_str(), "condition_false");
    assert_eq!(f.node.as_deref(), Some("main/cube_grasped"));
}

#[test]
fn one_setpoint_is_one_control_period_of_physics_and_the_arm_tracks_its_target_at_the_speed_limit() {
    for (period, steps) in [(0.004, 2), (0.01, 5)] {
        let mut env = env(EnvConfig {
            control_period: period,
            ..EnvConfig::default()
        });
        let q = env.observe().joint_target;
        let target = [q[0] + 0.1, q[1], q[2], q[3], q[4], q[5], 80.0];
        let r = env.step(&Action::Setpoint(target)).unwrap();
        assert_eq!(r.status, Status::Success);
        assert_eq!(r.physics_steps, steps, "control period {period}");
        assert_eq!(env.cell().sim().steps(), steps);
        assert!((r.sim_time - period).abs() < 1e-12);
        // 0.1 rad in one period is faster than the largest joint speed: the set point moves by
        // that speed's worth, and the step says so.
        assert_eq!(r.ctrl_clamped, 1);
        let reach = macrotree::env::CTRL_LIMITS.max_joint_speed * period;
        assert!((r.observation.joint_target[0] - (q[0] + reach)).abs() < 1e-9);
        assert_eq!(r.observation.gripper_command, 80.0);
        assert_eq!(r.observation.command()[18], 80.0);
        let mut last = r;
        for _ in 0..(1.0 / period) as usize {
            last = env.step(&Action::Setpoint(target)).unwrap();
        }
        assert_eq!(last.ctrl_clamped, 0, "the set point has arrived");
        assert_eq!(last.observation.joint_target[0], target[0]);
        let e = (last.observation.joint_pos[0] - target[0]).abs();
        assert!(e < 0.005, "joint 0 is {e} rad from its target after 1 s");
        assert!(
            last.observation.gripper_width < 0.07,
            "{}",
            last.observation.gripper_width
        );
    }
}

#[test]
fn the_flat_vectors_have_the_datasets_layout() {
    let mut env = env(EnvConfig::default());
    let o = env.reset(&Reset::Seed(5)).unwrap();
    let s = o.state();
    assert_eq!(s.len(), macrotree::env::STATE_NAMES.len());
    let expected = o
        .joint_pos
        .iter()
        .chain([&o.gripper_joint])
        .chain(&o.joint_vel)
        .chain(&o.pinch_pos)
        .chain(&o.pinch_quat);
    for ((v, e), name) in s.iter().zip(expected).zip(macrotree::env::STATE_NAMES) {
        assert_eq!(*v, *e as f32, "{name}");
    }
    let stepped = env
        .step(&Action::Leaf(
            r#"{"reach": {"target": "cube", "offset": [0, 0, 0.2]}}"#.into(),
        ))
        .unwrap()
        .observation;
    assert_eq!(stepped.state()[7..13], stepped.joint_vel.map(|v| v as f32));
    assert_ne!(stepped.state()[13..16], s[13..16], "the pinch point moved");
    let e = o.environment_state();
    assert_eq!(e.len(), 7 * o.objects.len());
    let cube = &o.objects[0];
    assert_eq!(
        &e[0..7],
        &[
            cube.pos[0],
            cube.pos[1],
            cube.pos[2],
            cube.quat[0],
            cube.quat[1],
            cube.quat[2],
            cube.quat[3]
        ]
        .map(|v| v as f32)
    );
    assert_eq!(o.objects[0].name, "cube");
    assert_eq!(o.objects[1].kind, "container");
    // The pinch orientation is the FK of the commanded joints (tool pointing down at home).
    let q = o.pinch_quat;
    assert!((q.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-9);
    // Serialized, the objects are keyed by name.
    let json = serde_json::to_value(&o).unwrap();
    assert!(json["objects"]["cube"]["grasped"].is_boolean());
    assert_eq!(json["objects"]["cube"]["half_extents"][2], cube.half_extents[2]);
}

#[test]
fn resets_place_objects_as_run_scenario_does_and_refuse_bad_placements() {
    let mut env = env(EnvConfig::default());
    let scene = flagship::scene();
    let sweep = macrotree::sweep::SweepConfig {
        seed: 9,
        ..Default::default()
    };
    let s = sweep.scenario(scene, 4).unwrap();
    env.reset(&Reset::Scenario {
        index: 4,
        sweep_seed: 9,
    })
    .unwrap();
    assert_eq!(env.placement(), &s.placement);
    assert_eq!(env.episode_seed(), s.seed);
    env.reset(&Reset::Seed(9)).unwrap();
    assert_eq!(env.placement(), &sweep.scenario(scene, 0).unwrap().placement);
    let mut p = scene.default_placement();
    p.poses[0].x = f64::NAN;
    let e = env.reset(&Reset::Placement(p)).unwrap_err();
    assert_eq!(e.kind(), "invalid_action");
    assert!(e.to_string().contains("not allowed"), "{e}");
    let mut p = scene.default_placement();
    p.poses.pop();
    assert!(
        env.reset(&Reset::Placement(p))
            .unwrap_err()
            .to_string()
            .contains("one pose per object")
    );
    let mut p = scene.default_placement();
    p.poses[0].x = 0.5;
    p.poses[0].y = -0.1;
    let o = env.reset(&Reset::Placement(p)).unwrap();
    assert!((o.object("cube").unwrap().pos[0] - 0.5).abs() < 1e-12);
}

#[test]
fn invalid_input_is_an_error_that_says_where_and_nothing_is_simulated() {
    let mut env = env(EnvConfig::default());
    let before = env.cell().sim().state_fingerprint();
    let e = env.step(&leaf(r#"{"reach": {"targt": "cube"}}"#)).unwrap_err();
    assert_eq!(e.kind(), "invalid_tree");
    let text = e.to_string();
    assert!(text.contains("action:1:12"), "{text}");
    assert!(text.contains("did you mean `target`?"), "{text}");
    let e = env.step(&leaf("reach: {target: cub}")).unwrap_err();
    let d = &e.diagnostics()[0];
    assert_eq!((d.line, d.column), (1, 17), "{e}");
    assert!(e.to_string().contains("did you mean `cube`?"), "{e}");
    let bad = [
        Action::Setpoint([f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        Action::Setpoint([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1e9]),
        Action::Setpoint([0.0, 0.0, 9.0, 0.0, 0.0, 0.0, 0.0]),
        Action::Ctrl({
            let mut u = [0.0; macrotree::motion::COMMAND_LEN];
            u[7] = f64::NAN;
            u
        }),
        Action::Primitive(Primitive::Wait {
            duration: Duration::Seconds(-0.5),
            gripper: None,
        }),
        Action::Primitive(Primitive::ReachJoints {
            joints: [0.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0],
            duration: Duration::Auto,
            gripper: None,
        }),
        Action::Subtree("pick".into()),
    ];
    for a in &bad {
        let e = env.step(a).unwrap_err();
        assert_eq!(e.kind(), "invalid_action", "{a:?}: {e}");
    }
    assert_eq!(
        env.cell().sim().state_fingerprint(),
        before,
        "nothing was simulated"
    );
    assert!(env.step(&leaf("home: {}")).unwrap().success());
}

#[test]
fn the_time_limit_truncates_a_step_and_halts_its_action() {
    let mut env = env(EnvConfig {
        max_sim_time: 0.1,
        ..EnvConfig::default()
    });
    let r = env
        .step(&leaf("reach: {target: cube, offset: [0, 0, 0.12]}"))
        .unwrap();
    assert!(r.truncated);
    assert!(!r.terminated);
    assert_eq!(r.failure.as_ref().unwrap().kind.as_str(), "time_limit");
    assert!((r.observation.time - 0.1).abs() < 1e-9, "{}", r.observation.time);
    let r = env.step(&leaf("home: {}")).unwrap();
    assert!(r.truncated && r.physics_steps == 0);
}

#[test]
fn render_gives_an_hwc_rgb_image_of_a_named_camera_and_leaves_the_physics_alone() {
    let mut env = env(EnvConfig::default());
    env.step(&leaf("reach: {target: cube, offset: [0, 0, 0.12]}"))
        .unwrap();
    let before = env.cell().sim().state_fingerprint();
    let cameras = env.scene().camera_names();
    assert!(cameras.iter().any(|c| c == "wrist"), "{cameras:?}");
    for camera in &cameras {
        let img = env.render(camera, 64, 48).unwrap();
        assert_eq!((img.width, img.height, img.pixels.len()), (64, 48, 64 * 48 * 3));
        let first = &img.pixels[..3];
        assert!(
            img.pixels.chunks(3).any(|p| p != first),
            "{camera}: not a blank image"
        );
    }
    assert_eq!(env.cell().sim().state_fingerprint(), before);
    let e = env.render("nope", 64, 48).unwrap_err();
    assert!(e.to_string().contains("wrist"), "{e}");
    assert!(env.render("wrist", 63, 48).is_err());
    assert!(env.render("wrist", 0, 0).is_err());
}

#[test]
fn a_configured_fault_fires_on_the_leaves_it_watches_and_is_reported_once() {
    let mut env = env(EnvConfig {
        fault: Some(macrotree::faults::FaultKind::Bump),
        ..EnvConfig::default()
    });
    let mut fired = Vec::new();
    for text in [
        "home: {}",
        "reach: {target: cube, offset: [0, 0, 0.12]}",
        "home: {}",
    ] {
        let r = env.step(&leaf(text)).unwrap();
        fired.push(r.faults_fired);
    }
    assert!(fired[0].is_empty());
    assert_eq!(fired[1].len(), 1, "{fired:?}");
    assert!(fired[1][0].starts_with("bump: "), "{fired:?}");
    assert!(fired[2].is_empty(), "reported once");
    // A reset re-arms it.
    env.reset(&Reset::Default).unwrap();
    let r = env
        .step(&leaf("reach: {target: cube, offset: [0, 0, 0.12]}"))
        .unwrap();
    assert_eq!(r.faults_fired.len(), 1);
}

#[test]
fn an_interrupted_step_halts_at_a_control_period_and_needs_a_reset() {
    let mut env = env(EnvConfig::default());
    env.reset(&Reset::Seed(3)).unwrap();
    let long = Action::Primitive(Primitive::Wait {
        duration: Duration::Seconds(10.0),
        gripper: None,
    });
    let mut periods = 0;
    let e = env
        .step_with(&long, &mut || {
            periods += 1;
            periods > 50
        })
        .unwrap_err();
    assert_eq!(e.kind(), "interrupted");
    // Asked before every period after the first: the 51st answer stops it, after 51 periods.
    let t = env.cell().world().time;
    assert!((t - 51.0 * 0.004).abs() < 1e-9, "stopped at {t} s");
    let again = env.step(&long).unwrap_err();
    assert!(again.to_string().contains("interrupted; reset"), "{again}");
    env.reset(&Reset::Seed(3)).unwrap();
    assert!(
        env.step(&Action::Leaf("wait: {seconds: 0.1}".into()))
            .unwrap()
            .success()
    );
}
