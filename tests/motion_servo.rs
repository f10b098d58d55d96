//! The analytic gravity model of `motion::servo` against MuJoCo's `qfrc_bias` at rest.

use macrotree::motion::{self, gravity_torque};
use macrotree::sim::{Scene, Sim};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn gravity_torque_matches_mujoco_bias_at_rest() {
    let scene = Scene::load().expect("scene (run tools/bootstrap)");
    let mut sim = Sim::new(&scene);
    let ids = scene.ids.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut worst = 0.0f64;
    for i in 0..40 {
        let q: [f64; 6] = if i == 0 {
            motion::HOME_Q
        } else {
            std::array::from_fn(|_| rng.random_range(-3.0..3.0))
        };
        {
            let d = sim.data_mut();
            let qpos = d.qpos_mut();
            for (k, &a) in ids.arm_qpos.iter().enumerate() {
                qpos[a] = q[k];
            }
            // Fingers open and at rest, everything still.
            qpos[ids.gripper_driver_qpos] = 0.0;
            d.qvel_mut().iter_mut().for_each(|v| *v = 0.0);
            d.forward();
        }
        let bias = sim.data().qfrc_bias();
        let ours = gravity_torque(&q, 0.0);
        for j in 0..6 {
            let theirs = bias[ids.arm_dof[j]];
            worst = worst.max((ours[j] - theirs).abs());
            // Finger linkage poses differ slightly from the lumped open-hand model.
            assert!(
                (ours[j] - theirs).abs() < 1e-6,
                "q {q:?} joint {j}: {} vs {theirs}",
                ours[j]
            );
        }
    }
    eprintln!("worst gravity torque difference {worst:.2e} N·m");
}
