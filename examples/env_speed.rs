//! How much the step-wise environment costs over bare physics, measured in one run:
//! `cargo run --release --example env_speed`.
//!
//! 1. `setpoint` mode: 5000 `Action::Setpoint` steps (one 4 ms control period = 2 physics steps each)
//!    against the same joint targets written straight into `ctrl` and `mj_step` in a loop.
//! 2. `VecEnv` of 2 environments on 2 threads against one environment, and against two
//!    environments stepped on two threads of their own without any hand-off (the machine's
//!    ceiling), in steps per second: 21 alternating rounds of 250 `setpoint` steps each, the
//!    median round's ratios.
//! 3. The flagship tree driven leaf by leaf (`Action::Leaf`, the leaves `run_episode` starts)
//!    against `run_episode` of the tree (the same physics, bit for bit).

use std::time::Instant;

use macrotree::App;
use macrotree::env::{Action, EnvConfig, MacroEnv, Reset, VecEnv};
use macrotree::episode::{EpisodeConfig, NoObserver, run_episode};
use macrotree::sim::{HOME_Q, Scene, Sim};

const CTRL_STEPS: usize = 5000;
const REPEAT: usize = 5;
const VECTOR_ROUNDS: usize = 21;

fn target(k: usize) -> [f64; 7] {
    let s = (k as f64 * 0.004).sin();
    let mut u = [0.0; 7];
    u[..6].copy_from_slice(&HOME_Q);
    u[0] += 0.3 * s;
    u[2] -= 0.2 * s;
    u[6] = 100.0 + 80.0 * s;
    u
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scene = Scene::load()?;
    let app = App::new();
    let mut env = MacroEnv::new(&app, scene.clone(), None, EnvConfig::default())?;
    let (mut env_t, mut bare_t) = (Vec::new(), Vec::new());
    for _ in 0..REPEAT {
        env.reset(&Reset::Default)?;
        let t = Instant::now();
        for k in 0..CTRL_STEPS {
            env.step(&Action::Setpoint(target(k)))?;
        }
        env_t.push(t.elapsed().as_secs_f64());
        let mut sim = Sim::new(&scene);
        let t = Instant::now();
        for k in 0..CTRL_STEPS {
            let u = target(k);
            for _ in 0..2 {
                sim.set_arm_ctrl(&[u[0], u[1], u[2], u[3], u[4], u[5]]);
                sim.set_gripper_ctrl(u[6]);
                sim.step();
            }
        }
        bare_t.push(t.elapsed().as_secs_f64());
    }
    let (e, b) = (median(env_t), median(bare_t));
    let steps = (2 * CTRL_STEPS) as f64;
    println!(
        "ctrl: {:.2} µs per ctrl step (2 physics steps) vs {:.2} µs bare; {:.1} vs {:.1} µs per physics step; env throughput = {:.3} of bare mj_step",
        e / CTRL_STEPS as f64 * 1e6,
        b / CTRL_STEPS as f64 * 1e6,
        e / steps * 1e6,
        b / steps * 1e6,
        b / e
    );

    // The vector env: 2 environments on 2 threads, against one environment and against two
    // environments stepped freely on two threads of their own (what the machine's two cores give
    // at best), in alternating rounds: the ratio of each round, so a machine whose speed drifts
    // still compares like with like.
    let mut v = VecEnv::with_threads(&app, scene.clone(), None, EnvConfig::default(), 2, 2)?;
    v.reset(&[Reset::Default, Reset::Default])?;
    env.reset(&Reset::Default)?;
    let mut free = [
        MacroEnv::new(&app, scene.clone(), None, EnvConfig::default())?,
        MacroEnv::new(&app, scene.clone(), None, EnvConfig::default())?,
    ];
    let (mut over_single, mut over_free) = (Vec::new(), Vec::new());
    let mut rates = [Vec::new(), Vec::new(), Vec::new()];
    const ROUND: usize = 250;
    for round in 0..VECTOR_ROUNDS {
        let t = Instant::now();
        for k in 0..ROUND {
            env.step(&Action::Setpoint(target(round * ROUND + k)))?;
        }
        let single = ROUND as f64 / t.elapsed().as_secs_f64();
        let t = Instant::now();
        for k in 0..ROUND {
            let j = round * ROUND + k;
            for r in v.step(&[Action::Setpoint(target(j)), Action::Setpoint(target(j + 1))])? {
                r?;
            }
        }
        let vector = (2 * ROUND) as f64 / t.elapsed().as_secs_f64();
        let t = Instant::now();
        std::thread::scope(|s| {
            for (e, env) in free.iter_mut().enumerate() {
                s.spawn(move || {
                    for k in 0..ROUND {
                        let _ = env.step(&Action::Setpoint(target(round * ROUND + k + e)));
                    }
                });
            }
        });
        let two_free = (2 * ROUND) as f64 / t.elapsed().as_secs_f64();
        over_single.push(vector / single);
        over_free.push(vector / two_free);
        for (r, x) in rates.iter_mut().zip([single, vector, two_free]) {
            r.push(x);
        }
    }
    let [single, vector, two_free] = rates.map(median);
    println!(
        "vector: 2 environments on 2 threads, {vector:.0} env steps/s vs {single:.0} for one environment and {two_free:.0} for two on free threads; median of {VECTOR_ROUNDS} alternating rounds: {:.2}x one environment, {:.2} of the free threads",
        median(over_single),
        median(over_free)
    );

    // The flagship, leaf by leaf.
    let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/trees/cube_to_bowl.yaml"));
    let plan = std::sync::Arc::new(app.load_tree(path)?);
    let leaves = [
        r#"{"home": {}}"#,
        r#"{"release": {"width": 0.065, "retreat": 0}}"#,
        r#"{"reach": {"target": "cube", "offset": [0, 0, 0.12]}}"#,
        r#"{"reach": {"target": "cube", "offset": [0, 0, 0.0], "path": "cartesian"}}"#,
        r#"{"grasp": {}}"#,
        r#"{"carry": {"to": "bowl", "lift": 0.15, "place_height": 0.02, "speed": 1.0}}"#,
        r#"{"release": {"retreat": 0.10}}"#,
        r#"{"home": {}}"#,
    ];
    let (mut leaf_t, mut tree_t) = (Vec::new(), Vec::new());
    let mut physics = 0;
    for _ in 0..REPEAT {
        env.reset(&Reset::Default)?;
        let t = Instant::now();
        physics = 0;
        for l in leaves {
            physics += env.step(&Action::Leaf(l.to_string()))?.physics_steps;
        }
        leaf_t.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let r = run_episode(
            &scene,
            plan.clone(),
            app.factory(),
            &EpisodeConfig::default(),
            &mut NoObserver,
        );
        tree_t.push(t.elapsed().as_secs_f64());
        assert!(r.outcome.success);
    }
    let (l, t) = (median(leaf_t), median(tree_t));
    println!(
        "flagship: {} leaves, {physics} physics steps: {:.2} ms leaf by leaf vs {:.2} ms run_episode (ratio {:.3})",
        leaves.len(),
        l * 1e3,
        t * 1e3,
        l / t
    );
    Ok(())
}
