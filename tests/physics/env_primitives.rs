//! The reference tutorial's primitives on real physics: reach a pose (joint and Cartesian
//! paths, with and without an orientation), reach joints, open and close the gripper (to a
//! command or a width), wait, reset to home — with the reference's steps/settle counts, seconds,
//! or macrotree's own arrival.

use macrotree::App;
use macrotree::env::{Action, Duration, EnvConfig, MacroEnv, Primitive, Reset, Status, StepResult};
use macrotree::kinds::PathKind;
use macrotree::sim::HOME_Q;
use nalgebra::{Quaternion, UnitQuaternion};

use crate::support::flagship;

fn env() -> MacroEnv {
    MacroEnv::new(&App::new(), flagship::scene().clone(), None, EnvConfig::default()).expect("env")
}

fn run(env: &mut MacroEnv, p: Primitive) -> StepResult {
    let r = env.step(&Action::Primitive(p)).unwrap();
    assert_eq!(r.status, Status::Success, "{:?}", r.failure);
    r
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn angle(a: [f64; 4], b: [f64; 4]) -> f64 {
    let q = |v: [f64; 4]| UnitQuaternion::from_quaternion(Quaternion::new(v[0], v[1], v[2], v[3]));
    q(a).angle_to(&q(b))
}

#[test]
fn reach_pose_ends_within_millimetres_keeping_or_taking_the_orientation() {
    let mut env = env();
    let start = env.observe();
    let target = [0.45, 0.05, 0.25];
    // The observed pinch orientation, given back, is kept (the quaternion convention round-trips).
    let r = run(
        &mut env,
        Primitive::ReachPose {
            position: target,
            quaternion: Some(start.pinch_quat),
            path: PathKind::Joint,
            duration: Duration::Auto,
            gripper: None,
        },
    );
    let o = &r.observation;
    assert!(dist(o.pinch_pos, target) < 0.003, "{:?}", o.pinch_pos);
    assert!(
        angle(o.pinch_quat, start.pinch_quat) < 0.01,
        "{}",
        angle(o.pinch_quat, start.pinch_quat)
    );
    // The reference's counts: 150 steps of motion + 50 of settling = 2.0 s; a Cartesian line.
    let target = [0.40, -0.15, 0.15];
    let r = run(
        &mut env,
        Primitive::ReachPose {
            position: target,
            quaternion: None,
            path: PathKind::Cartesian,
            duration: Duration::Steps {
                steps: 150,
                settle: 50,
            },
            gripper: None,
        },
    );
    assert!((r.sim_time - 2.0).abs() < 1e-9, "{}", r.sim_time);
    assert_eq!(r.physics_steps, 1000);
    assert!(
        dist(r.observation.pinch_pos, target) < 0.003,
        "{:?}",
        r.observation.pinch_pos
    );
    assert!(
        angle(r.observation.pinch_quat, start.pinch_quat) < 0.01,
        "orientation kept"
    );
    // A turned tool: 30° about the world z axis.
    let turn = UnitQuaternion::from_euler_angles(0.0, 0.0, 0.5);
    let q0 = start.pinch_quat;
    let want = turn * UnitQuaternion::from_quaternion(Quaternion::new(q0[0], q0[1], q0[2], q0[3]));
    let w = [want.w, want.i, want.j, want.k];
    let r = run(
        &mut env,
        Primitive::ReachPose {
            position: target,
            quaternion: Some(w),
            path: PathKind::Joint,
            duration: Duration::Seconds(1.5),
            gripper: None,
        },
    );
    assert!((r.sim_time - 1.5).abs() < 1e-9);
    assert!(
        angle(r.observation.pinch_quat, w) < 0.01,
        "{}",
        angle(r.observation.pinch_quat, w)
    );
}

#[test]
fn an_unreachable_pose_fails_typed_without_moving() {
    let mut env = env();
    let r = env
        .step(&Action::Primitive(Primitive::ReachPose {
            position: [1.3, 0.0, 0.2],
            quaternion: None,
            path: PathKind::Joint,
            duration: Duration::Auto,
            gripper: None,
        }))
        .unwrap();
    assert_eq!(r.status, Status::Failure);
    let f = r.failure.unwrap();
    assert_eq!(f.kind.as_str(), "unreachable");
    assert_eq!(f.node.as_deref(), Some("reach_pose"));
    assert_eq!(r.physics_steps, 0);
}

#[test]
fn reach_joints_and_reset_go_where_they_are_told() {
    let mut env = env();
    let joints = [-1.2, -1.4, 1.7, -1.8, -1.5, 0.4];
    let r = run(
        &mut env,
        Primitive::ReachJoints {
            joints,
            duration: Duration::Auto,
            gripper: None,
        },
    );
    for (q, want) in r.observation.joint_pos.iter().zip(joints) {
        assert!((q - want).abs() < 0.01, "{:?}", r.observation.joint_pos);
    }
    run(
        &mut env,
        Primitive::CloseGripper {
            command: None,
            width: None,
            duration: Duration::Seconds(0.5),
        },
    );
    let r = run(
        &mut env,
        Primitive::Reset {
            duration: Duration::Steps {
                steps: 250,
                settle: 100,
            },
        },
    );
    assert!((r.sim_time - 3.5).abs() < 1e-9);
    let err: f64 = (0..6)
        .map(|i| (r.observation.joint_pos[i] - HOME_Q[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(err < 0.01, "home error {err} rad (the reference's bound: 0.04)");
    assert_eq!(r.observation.gripper_command, 0.0);
    assert!(
        r.observation.gripper_width > 0.08,
        "{}",
        r.observation.gripper_width
    );
}

#[test]
fn close_on_the_cube_grasps_it_and_open_lets_it_go() {
    let mut env = env();
    env.reset(&Reset::Default).unwrap();
    for leaf in [
        "reach: {target: cube, offset: [0, 0, 0.12]}",
        "reach: {target: cube, path: cartesian}",
    ] {
        assert!(env.step(&Action::Leaf(leaf.into())).unwrap().success());
    }
    // Closed to 3 cm on a 44 mm cube: the pads stop on its faces.
    let r = run(
        &mut env,
        Primitive::CloseGripper {
            command: None,
            width: Some(0.03),
            duration: Duration::Auto,
        },
    );
    let cube = r.observation.object("cube").unwrap();
    assert!(cube.grasped, "{:?}", r.observation.contacts);
    assert!(
        (r.observation.gripper_width - 0.044).abs() < 0.004,
        "{}",
        r.observation.gripper_width
    );
    assert!((r.observation.gripper_command - macrotree::motion::ctrl_for_width(0.03)).abs() < 1e-12);
    // Lifted with the grasp: the cube comes along.
    let z0 = cube.pos[2];
    let p = r.observation.pinch_pos;
    let r = run(
        &mut env,
        Primitive::ReachPose {
            position: [p[0], p[1], p[2] + 0.1],
            quaternion: None,
            path: PathKind::Cartesian,
            duration: Duration::Auto,
            gripper: None,
        },
    );
    let cube = r.observation.object("cube").unwrap();
    assert!(cube.pos[2] - z0 > 0.09, "lift {}", cube.pos[2] - z0);
    let r = run(
        &mut env,
        Primitive::OpenGripper {
            command: None,
            duration: Duration::Steps {
                steps: 100,
                settle: 20,
            },
        },
    );
    assert!((r.sim_time - 1.2).abs() < 1e-9);
    assert!(!r.observation.object("cube").unwrap().grasped);
    assert!(r.observation.gripper_width > 0.08);
    // A command closes an empty gripper fully.
    let r = run(
        &mut env,
        Primitive::CloseGripper {
            command: Some(255.0),
            width: None,
            duration: Duration::Auto,
        },
    );
    assert!(
        r.observation.gripper_width < 0.005,
        "{}",
        r.observation.gripper_width
    );
}

#[test]
fn wait_holds_for_its_duration() {
    let mut env = env();
    let before = env.observe();
    let r = run(
        &mut env,
        Primitive::Wait {
            duration: Duration::Seconds(0.5),
            gripper: None,
        },
    );
    assert_eq!(r.physics_steps, 250);
    let r2 = run(
        &mut env,
        Primitive::Wait {
            duration: Duration::Steps {
                steps: 20,
                settle: 30,
            },
            gripper: None,
        },
    );
    assert_eq!(r2.physics_steps, 250);
    assert_eq!(
        r2.observation.joint_target, before.joint_target,
        "the set point holds"
    );
    assert!(
        dist(r2.observation.pinch_pos, before.pinch_pos) < 0.002,
        "no sag: gravity feedforward"
    );
    let _ = r;
}
