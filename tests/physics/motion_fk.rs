//! Cross-check of the analytic kinematics (`motion::fk`, `motion::jacobian`) against MuJoCo's own
//! forward kinematics of the composed scene.

use macrotree::motion::{self, fk, jacobian};
use macrotree::sim::{HOME_Q, Scene, Sim};
use nalgebra::{Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Puts the arm at `q` (qpos and servo commands), runs `mj_forward`, returns the pinch pose.
fn mujoco_pinch(sim: &mut Sim, q: &[f64; 6]) -> (Vector3<f64>, Matrix3<f64>) {
    let ids = sim.scene().ids.clone();
    sim.set_arm_ctrl(q);
    {
        let qpos = sim.data_mut().qpos_mut();
        for (i, &a) in ids.arm_qpos.iter().enumerate() {
            qpos[a] = q[i];
        }
    }
    sim.data_mut().forward();
    let w = sim.observe();
    assert_eq!(w.arm_q, *q);
    (w.pinch_pos, w.pinch_rot)
}

#[test]
fn home_constant_matches_the_simulator() {
    assert_eq!(motion::HOME_Q, HOME_Q);
}

#[test]
fn fk_matches_mujoco_on_random_joints() {
    let scene = Scene::load().expect("scene (run tools/bootstrap)");
    let mut sim = Sim::new(&scene);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut worst = (0.0f64, 0.0f64);
    for i in 0..60 {
        let q: [f64; 6] = if i == 0 {
            HOME_Q
        } else {
            std::array::from_fn(|j| {
                let (lo, hi) = motion::JOINT_LIMITS[j];
                rng.random_range(lo..hi)
            })
        };
        let (p_mj, r_mj) = mujoco_pinch(&mut sim, &q);
        let pose = fk(&q);
        let r = pose.rotation.to_rotation_matrix();
        let dp = (pose.translation.vector - p_mj).norm();
        let dr = (r.matrix() - r_mj).norm();
        worst = (worst.0.max(dp), worst.1.max(dr));
        assert!(dp <= 1e-9, "q {q:?}: position differs by {dp:e} m");
        assert!(dr <= 1e-9, "q {q:?}: rotation differs by {dr:e}");
    }
    eprintln!(
        "worst FK difference: {:.2e} m, {:.2e} (rotation matrix norm)",
        worst.0, worst.1
    );
}

#[test]
fn home_pinch_is_where_the_brief_says() {
    let scene = Scene::load().expect("scene");
    let mut sim = Sim::new(&scene);
    let (p, r) = mujoco_pinch(&mut sim, &HOME_Q);
    assert!((p - Vector3::new(-0.134, 0.492, 0.3322)).norm() < 1e-9, "{p}");
    assert!((r.column(2) + Vector3::z()).norm() < 1e-9);
    assert!((r.column(0) - Vector3::y()).norm() < 1e-9);
}

#[test]
fn jacobian_matches_mujoco_finite_differences() {
    // MuJoCo FK differenced numerically vs. the analytic geometric Jacobian.
    let scene = Scene::load().expect("scene");
    let mut sim = Sim::new(&scene);
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for _ in 0..10 {
        let q: [f64; 6] = std::array::from_fn(|_| rng.random_range(-3.0..3.0));
        let j = jacobian(&q);
        let (p0, r0) = mujoco_pinch(&mut sim, &q);
        let h = 1e-6;
        for c in 0..6 {
            let mut qh = q;
            qh[c] += h;
            let (p1, r1) = mujoco_pinch(&mut sim, &qh);
            let lin = (p1 - p0) / h;
            let ang = motion::kinematics::rotation_vector(&(r1 * r0.transpose())) / h;
            for k in 0..3 {
                assert!((lin[k] - j[(k, c)]).abs() < 1e-5, "lin col {c}");
                assert!((ang[k] - j[(k + 3, c)]).abs() < 1e-5, "ang col {c}");
            }
        }
    }
}
