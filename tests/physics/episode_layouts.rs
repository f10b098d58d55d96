//! The flagship tree on real physics: the reference tutorial's five layouts pass its checks, and
//! rotated cubes over the whole task region go into the bowl — as judged by the independent
//! oracle of `support/oracle.rs` (MuJoCo contact with the bowl's floor, height, footprint, at
//! rest), with no MuJoCo warning in any episode.

use std::sync::Arc;

use crate::support::oracle;

use macrotree::episode::{EpisodeConfig, EpisodeReport, NoObserver, run_in_cell};
use macrotree::sim::{Layout, Scene};

fn flagship() -> Arc<macrotree::plan::Plan> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/trees/cube_to_bowl.yaml");
    Arc::new(
        macrotree::plan::Loader::default()
            .load(std::path::Path::new(path))
            .expect("flagship tree is valid"),
    )
}

/// Runs the flagship on every layout; after each episode, checks MuJoCo raised no warning and
/// asks the oracle whether the cube rests in the bowl.
fn run_all(layouts: &[Layout]) -> Vec<(EpisodeReport, oracle::Verdict)> {
    let scene = Scene::load().expect("scene (run tools/bootstrap)");
    let plan = flagship();
    let mut cell =
        macrotree::actions::Cell::new(&scene, &Layout::default(), macrotree::actions::CONTROL_PERIOD);
    layouts
        .iter()
        .map(|layout| {
            let config = EpisodeConfig {
                placement: Some(scene.placement_from_layout(layout)),
                ..EpisodeConfig::default()
            };
            let r = run_in_cell(
                &mut cell,
                plan.clone(),
                &macrotree::factory::Factory::builtin(),
                &config,
                &mut NoObserver,
            );
            oracle::assert_no_warning(cell.sim(), &format!("{layout:?}"));
            let v = oracle::settle_and_judge(cell.sim_mut(), "cube", "bowl");
            (r, v)
        })
        .collect()
}

#[test]
fn reference_layouts_pass_the_tutorial_checks() {
    let layouts = Layout::reference_layouts();
    for (layout, (r, verdict)) in layouts.iter().zip(run_all(&layouts)) {
        let c = &r.outcome.cube_bowl.expect("the tutorial scene has a cube").checks;
        eprintln!(
            "{layout:?}: success {} in {:.2} s sim, grasp {:?} m, motion {:.3} m, lift {:.3} m, home {:.4} rad",
            r.outcome.success,
            r.outcome.sim_time_s,
            c.grasp_distance,
            c.cube_motion_while_closed,
            c.cube_lift_while_closed,
            c.home_error
        );
        assert!(r.outcome.success, "{layout:?}: {:?}", r.outcome.failure_reason);
        let grasp = c.grasp_distance.expect("a grasp happened");
        assert!(grasp <= 0.025, "{layout:?}: grasp distance {grasp} m > 0.025 m");
        assert!(
            c.cube_motion_while_closed >= 0.05,
            "{layout:?}: motion {} m",
            c.cube_motion_while_closed
        );
        assert!(
            c.cube_lift_while_closed >= 0.08,
            "{layout:?}: lift {} m",
            c.cube_lift_while_closed
        );
        assert!(
            c.home_error <= 0.04,
            "{layout:?}: home error {} rad",
            c.home_error
        );
        assert!(
            c.in_bowl,
            "{layout:?}: cube not in the bowl at {:?}",
            r.outcome.cube_bowl.map(|l| l.cube_final)
        );
        assert!(c.pass_reference());
        assert!(verdict.inside(), "{layout:?}: the oracle disagrees: {verdict:?}");
        assert_eq!(
            r.outcome.grasp_attempts, 1,
            "{layout:?}: a clean layout needs one grasp"
        );
    }
}

/// Rotated cubes spread over the task region x ∈ [0.30, 0.60], y ∈ [−0.30, 0.30], yaw ∈ [−45°, 45°),
/// cube and bowl at least 0.16 m apart, corners and edges included.
fn region_layouts() -> Vec<Layout> {
    vec![
        Layout::new(0.30, -0.30, -45.0, 0.60, 0.30),
        Layout::new(0.60, 0.30, 44.0, 0.30, -0.30),
        Layout::new(0.30, 0.30, 30.0, 0.60, -0.30),
        Layout::new(0.60, -0.30, -30.0, 0.30, 0.30),
        Layout::new(0.45, 0.00, 15.0, 0.45, 0.20),
        Layout::new(0.35, 0.20, -20.0, 0.55, -0.10),
        Layout::new(0.55, -0.25, 40.0, 0.32, 0.05),
        Layout::new(0.40, 0.10, -40.0, 0.40, -0.10),
        Layout::new(0.58, 0.05, 22.5, 0.35, -0.25),
        Layout::new(0.32, -0.05, -10.0, 0.58, 0.18),
        Layout::new(0.50, 0.28, 5.0, 0.50, 0.00),
        Layout::new(0.42, -0.28, -35.0, 0.42, 0.10),
    ]
}

#[test]
fn rotated_cubes_across_the_region_end_in_the_bowl() {
    let layouts = region_layouts();
    for l in &layouts {
        assert!(l.separation() >= 0.16, "{l:?} violates the 0.16 m separation");
    }
    let reports = run_all(&layouts);
    let failures: Vec<String> = layouts
        .iter()
        .zip(&reports)
        .filter(|(_, (r, v))| !r.outcome.success || !v.inside())
        .map(|(l, (r, v))| format!("{l:?}: {:?}, oracle {v:?}", r.outcome.failure_reason))
        .collect();
    for (l, (r, v)) in layouts.iter().zip(&reports) {
        eprintln!(
            "{l:?}: {:.2} s sim, {} grasp(s), oracle offset {:?} of ±{:?} m, height error {:.2e} m",
            r.outcome.sim_time_s, r.outcome.grasp_attempts, v.offset, v.allowed, v.height_error
        );
    }
    assert!(failures.is_empty(), "failed layouts:\n{}", failures.join("\n"));
}

#[test]
fn same_tree_layout_and_seed_give_a_bit_identical_episode() {
    let scene = Scene::load().expect("scene");
    let plan = flagship();
    let config = EpisodeConfig {
        placement: Some(scene.placement_from_layout(&Layout::new(0.38, 0.12, 27.0, 0.55, -0.15))),
        seed: 7,
        ..EpisodeConfig::default()
    };
    let mut a = macrotree::actions::Cell::new(&scene, &Layout::default(), config.control_period);
    let mut b = macrotree::actions::Cell::new(&scene, &Layout::default(), config.control_period);
    // Run `b` once on another layout first: a reused cell must not remember anything.
    let other = EpisodeConfig {
        placement: None,
        ..config.clone()
    };
    run_in_cell(
        &mut b,
        plan.clone(),
        &macrotree::factory::Factory::builtin(),
        &other,
        &mut NoObserver,
    );
    let mut ra = run_in_cell(
        &mut a,
        plan.clone(),
        &macrotree::factory::Factory::builtin(),
        &config,
        &mut NoObserver,
    );
    let mut rb = run_in_cell(
        &mut b,
        plan,
        &macrotree::factory::Factory::builtin(),
        &config,
        &mut NoObserver,
    );
    assert!(ra.outcome.success);
    oracle::assert_no_warning(a.sim(), "episode a");
    oracle::assert_no_warning(b.sim(), "episode b");
    assert_eq!(
        a.sim().state_fingerprint(),
        b.sim().state_fingerprint(),
        "physics state differs bit-wise"
    );
    for r in [&mut ra, &mut rb] {
        r.wall_time_s = 0.0;
        r.planning.planning_wall_s = 0.0;
    }
    assert_eq!(ra, rb);
}
