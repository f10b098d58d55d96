//! Trajectory properties (pure kinematics): exact endpoints, zero velocity at the ends, joint
//! speed / acceleration and tool speed limits (sampled every millisecond), Cartesian moves staying
//! on their line, and failures for lines the arm cannot follow.

use std::f64::consts::PI;

use macrotree::motion::ik::TASK_REGION;
use macrotree::motion::{
    CartesianMove, HOME_Q, IkError, JointMove, MotionLimits, Trajectory, down_pose, fk, ik_down,
};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const DT: f64 = 1e-3;

/// Peak joint speed (from the returned velocities) and peak joint acceleration (finite
/// differences of them) over the whole trajectory, and a check that the returned velocities
/// match the finite differences of the positions.
fn peaks(tr: &dyn Trajectory) -> (f64, f64) {
    let n = (tr.duration() / DT).ceil() as usize + 5;
    let (mut v, mut a) = (0.0f64, 0.0f64);
    let mut prev = tr.sample(0.0);
    for i in 1..=n {
        let t = i as f64 * DT;
        let cur = tr.sample(t);
        for j in 0..6 {
            v = v.max(cur.1[j].abs());
            a = a.max(((cur.1[j] - prev.1[j]) / DT).abs());
            let fd = (cur.0[j] - prev.0[j]) / DT;
            let mid = 0.5 * (cur.1[j] + prev.1[j]);
            assert!(
                (fd - mid).abs() < 1e-3 * (1.0 + mid.abs()),
                "t {t}: velocity {mid} vs positions {fd}"
            );
        }
        prev = cur;
    }
    (v, a)
}

fn random_task_point(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    Vector3::new(
        rng.random_range(TASK_REGION[0].0..=TASK_REGION[0].1),
        rng.random_range(TASK_REGION[1].0..=TASK_REGION[1].1),
        rng.random_range(TASK_REGION[2].0..=TASK_REGION[2].1),
    )
}

#[test]
fn joint_moves_respect_limits_and_end_exactly() {
    let lim = MotionLimits::default();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for i in 0..60 {
        let from: [f64; 6] = std::array::from_fn(|j| HOME_Q[j] + rng.random_range(-1.0..1.0));
        let scale = if i % 3 == 0 { 0.01 } else { 2.0 };
        let to: [f64; 6] = std::array::from_fn(|j| from[j] + scale * rng.random_range(-1.0..1.0));
        let m = JointMove::new(from, to, &lim);
        assert!(m.duration() >= lim.min_duration);
        assert_eq!(m.sample(0.0), (from, [0.0; 6]));
        assert_eq!(m.sample(-1.0).0, from);
        assert_eq!(m.sample(m.duration()), (to, [0.0; 6]));
        assert_eq!(m.sample(m.duration() + 5.0).0, to);
        assert_eq!(m.end(), to);
        // Velocity vanishes smoothly at both ends.
        let (_, v_early) = m.sample(1e-4);
        let (_, v_late) = m.sample(m.duration() - 1e-4);
        assert!(v_early.iter().chain(&v_late).all(|v| v.abs() < 1e-3));
        let (v, a) = peaks(&m);
        assert!(v <= lim.max_joint_speed * (1.0 + 1e-9), "{i}: speed {v}");
        assert!(a <= lim.max_joint_acc * 1.01, "{i}: acc {a}");
        // And the duration is not wasteful: one limit is (nearly) reached unless min_duration rules.
        if m.duration() > lim.min_duration {
            assert!(
                v > 0.97 * lim.max_joint_speed || a > 0.97 * lim.max_joint_acc,
                "{i}: {v} {a}"
            );
        }
    }
}

#[test]
fn cartesian_moves_stay_on_the_line_and_respect_limits() {
    let lim = MotionLimits::default();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut done = 0;
    for i in 0..40 {
        let a = random_task_point(&mut rng);
        let b = random_task_point(&mut rng);
        let from_q = ik_down(&a, rng.random_range(-PI..PI), false, &HOME_Q).unwrap();
        // Mostly downward targets (the task's moves), some tilted by up to 0.4 rad.
        let mut to = down_pose(
            &b,
            rng.random_range(-1.5..1.5) + fk(&from_q).rotation.euler_angles().2,
        );
        if i % 4 == 0 {
            let tilt = UnitQuaternion::from_euler_angles(
                rng.random_range(-0.4..0.4),
                rng.random_range(-0.4..0.4),
                0.0,
            );
            to = Isometry3::from_parts(Translation3::from(b), tilt * to.rotation);
        }
        let m = match CartesianMove::new(from_q, to, &lim) {
            Ok(m) => m,
            Err(e) => panic!("{i}: {a} → {b}: {e}"),
        };
        done += 1;
        assert_eq!(m.sample(0.0).0, from_q);
        assert_eq!(m.sample(m.duration()), (m.end(), [0.0; 6]));
        let end = fk(&m.end());
        assert!((end.translation.vector - b).norm() <= 1e-6);
        assert!(end.rotation.angle_to(&to.rotation) <= 1e-5);
        let (v, acc) = peaks(&m);
        assert!(v <= lim.max_joint_speed * 1.001, "{i}: joint speed {v}");
        assert!(acc <= lim.max_joint_acc * 1.02, "{i}: joint acc {acc}");
        // Tool on the line (≤ 1 mm), tool speed within the limit.
        let n = (m.duration() / DT).ceil() as usize;
        let dir = (b - a).normalize();
        let mut prev = a;
        let mut off_line = 0.0f64;
        let mut speed = 0.0f64;
        for k in 0..=n {
            let t = (k as f64 * DT).min(m.duration());
            let pose = fk(&m.sample(t).0);
            let p = pose.translation.vector;
            let rel = p - a;
            off_line = off_line.max((rel - dir * rel.dot(&dir)).norm());
            let along = rel.dot(&dir);
            assert!(along >= -1e-6 && along <= (b - a).norm() + 1e-6);
            // And it follows the planned timing along the line (position and orientation).
            let plan = m.pose_at(t);
            assert!((plan.translation.vector - p).norm() < 1e-3);
            assert!(plan.rotation.angle_to(&pose.rotation) < 1e-3);
            if k > 0 {
                speed = speed.max((p - prev).norm() / DT);
            }
            prev = p;
        }
        assert!(off_line <= 1e-3, "{i}: {off_line} m off the line");
        assert!(speed <= lim.tool_speed * 1.01, "{i}: tool speed {speed}");
    }
    assert_eq!(done, 40);
}

#[test]
fn cartesian_line_through_the_base_fails_with_the_waypoint() {
    let lim = MotionLimits::default();
    let a = Vector3::new(0.35, 0.05, 0.3);
    let from_q = ik_down(&a, 0.0, false, &HOME_Q).unwrap();
    let to = down_pose(&Vector3::new(-0.35, 0.05, 0.3), 0.0);
    match CartesianMove::new(from_q, to, &lim) {
        Err(IkError::Unreachable { reason }) => assert!(reason.contains("waypoint"), "{reason}"),
        Err(e) => panic!("{e}"),
        Ok(m) => panic!("went through the base in {} s", m.duration()),
    }
}

#[test]
fn cartesian_rotation_in_place_is_timed_by_the_joints() {
    let lim = MotionLimits::default();
    let p = Vector3::new(0.45, -0.1, 0.2);
    let from_q = ik_down(&p, 0.0, false, &HOME_Q).unwrap();
    let yaw0 = {
        let x = fk(&from_q).rotation * Vector3::x();
        (-x.x).atan2(x.y)
    };
    let m = CartesianMove::new(from_q, down_pose(&p, yaw0 + 1.5), &lim).unwrap();
    // Wrist 3 turns 1.5 rad: at least 1.875·1.5/3 s.
    assert!(
        m.duration() >= 1.875 * 1.5 / lim.max_joint_speed * 0.999,
        "{}",
        m.duration()
    );
    let (v, _) = peaks(&m);
    assert!(v <= lim.max_joint_speed * 1.001);
    for k in 0..=20 {
        let t = m.duration() * k as f64 / 20.0;
        assert!((fk(&m.sample(t).0).translation.vector - p).norm() < 1e-4);
    }
}
