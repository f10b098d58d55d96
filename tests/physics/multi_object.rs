//! The multi-object tasks on physics: the three shipped trees on their scenes, the goal judged
//! independently of the tree, motions that name what is in their way, faults on the handled block.

use std::path::Path;
use std::sync::Arc;

use macrotree::actions::{CONTROL_PERIOD, Cell};
use macrotree::episode::{EpisodeConfig, EpisodeReport, NoObserver, run_episode, run_in_cell};
use macrotree::plan::Loader;
use macrotree::sim::{Layout, Scene, Sim};
use macrotree::sweep::SweepConfig;

use crate::support::oracle;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// Scenario `k` of sweep seed `s` of `tree` on its own scene, as `run --scenario k --sweep-seed s`;
/// the report and the cell it ran in (its final state, for the oracle). Asserts MuJoCo raised no
/// warning.
fn run_scenario(
    tree: &str,
    s: u64,
    k: u64,
    fault: Option<macrotree::faults::FaultKind>,
) -> (EpisodeReport, Cell) {
    let plan = Arc::new(
        Loader::default()
            .load(&Path::new(ROOT).join(tree))
            .unwrap_or_else(|d| panic!("{}", d[0])),
    );
    let scene = Scene::load_spec(&plan.scene).expect("scene compiles");
    let sweep = SweepConfig {
        seed: s,
        fault,
        ..SweepConfig::default()
    };
    let scenario = sweep.scenario(&scene, k).expect("a placement");
    let mut cell = Cell::new(&scene, &Layout::default(), CONTROL_PERIOD);
    let r = run_in_cell(
        &mut cell,
        plan,
        &macrotree::factory::Factory::builtin(),
        &sweep.episode_config(&scenario),
        &mut NoObserver,
    );
    oracle::assert_no_warning(cell.sim(), &format!("{tree} #{k}"));
    (r, cell)
}

fn assert_done(r: &EpisodeReport, what: &str) {
    assert!(r.outcome.success, "{what}: {:?}", r.outcome.failure_reason);
    assert!(
        !r.outcome.goal.is_empty() && r.outcome.goal.iter().all(|g| g.holds),
        "{what}: {:?}",
        r.outcome.goal
    );
}

#[test]
fn sort_by_color_puts_every_block_in_the_bin_of_its_colour() {
    for k in [0, 1] {
        let (r, mut cell) = run_scenario("trees/sort_by_color.yaml", 0, k, None);
        assert_done(&r, "sort");
        // Independently of the predicate code: each block's final centre lies inside the walls
        // (12 cm inner, so within 6 cm in x and y) of the bin of its colour, on its floor.
        for colour in ["red", "green", "blue"] {
            let block = r.outcome.objects.iter().find(|o| o.name == colour).unwrap();
            let bin = r
                .outcome
                .objects
                .iter()
                .find(|o| o.name == format!("{colour}_bin"))
                .unwrap();
            let (dx, dy) = (block.end[0] - bin.end[0], block.end[1] - bin.end[1]);
            assert!(dx.abs() < 0.06 && dy.abs() < 0.06, "{colour}: {dx:.3}, {dy:.3}");
            assert!(
                (block.end[2] - (0.01 + 0.022)).abs() < 0.003,
                "{colour} rests on the floor: z {}",
                block.end[2]
            );
        }
        assert!(
            r.outcome.sim_time_s < 3.0 * 6.0,
            "{} s for three blocks",
            r.outcome.sim_time_s
        );
        // The oracle: MuJoCo contact with the bin's floor, height, footprint, at rest.
        for colour in ["red", "green", "blue"] {
            let bin = format!("{colour}_bin");
            oracle::assert_in(cell.sim_mut(), colour, &bin, &format!("sort #{k}"));
        }
    }
}

#[test]
fn stack_three_builds_the_tower() {
    let (r, _) = run_scenario("trees/stack_three.yaml", 0, 3, None);
    assert_done(&r, "stack");
    let z = |n: &str| r.outcome.objects.iter().find(|o| o.name == n).unwrap().end;
    let (red, green, blue) = (z("red"), z("green"), z("blue"));
    // 44 mm blocks: centres at 22, 66, 110 mm, each within half a block of the one below.
    for (top, below, height) in [(red, green, 0.110), (green, blue, 0.066)] {
        assert!((top[2] - height).abs() < 0.005, "height {} vs {height}", top[2]);
        assert!((top[0] - below[0]).abs() < 0.027 && (top[1] - below[1]).abs() < 0.027);
    }
    assert!((blue[2] - 0.022).abs() < 0.003, "the base stays on the table");
}

#[test]
fn clear_table_puts_every_block_in_the_bin() {
    let (r, mut cell) = run_scenario("trees/clear_table.yaml", 0, 0, None);
    assert_done(&r, "clear");
    let bin = r.outcome.objects.iter().find(|o| o.name == "bin").unwrap().end;
    for o in r.outcome.objects.iter().filter(|o| o.name != "bin") {
        assert!(
            (o.end[0] - bin[0]).abs() < 0.14 && (o.end[1] - bin[1]).abs() < 0.14,
            "{}",
            o.name
        );
    }
    for block in ["a", "b", "c", "d", "e"] {
        oracle::assert_in(cell.sim_mut(), block, "bin", "clear");
    }
}

#[test]
fn a_slip_hits_the_carried_block_and_the_task_still_finishes() {
    let (r, mut cell) = run_scenario(
        "trees/sort_by_color.yaml",
        0,
        0,
        Some(macrotree::faults::FaultKind::Slip),
    );
    assert_done(&r, "sort with a slip");
    for colour in ["red", "green", "blue"] {
        oracle::assert_in(
            cell.sim_mut(),
            colour,
            &format!("{colour}_bin"),
            "sort with a slip",
        );
    }
    assert!(
        r.outcome.grasp_attempts >= 4,
        "one block was grasped twice: {}",
        r.outcome.grasp_attempts
    );
}

/// A tree that does nothing succeeds as a tree, but the episode fails: the scene's goal decides.
#[test]
fn a_tree_that_succeeds_without_doing_the_job_is_caught() {
    let dir = tempdir("goal");
    let tree = dir.join("idle.yaml");
    std::fs::write(
        &tree,
        format!("scene: {ROOT}/scenes/sort_three.yaml\nmain: {{home: {{}}}}\n"),
    )
    .unwrap();
    // The scene is the repository's, outside this tree's folder and its `scenes/` neighbour.
    let plan = Arc::new(
        Loader::default()
            .includes_anywhere(true)
            .load(&tree)
            .unwrap_or_else(|d| panic!("{}", d[0])),
    );
    let scene = Scene::load_spec(&plan.scene).unwrap();
    let r = run_episode(
        &scene,
        plan,
        &macrotree::factory::Factory::builtin(),
        &EpisodeConfig::default(),
        &mut NoObserver,
    );
    assert_eq!(r.outcome.tree_status, "success");
    assert!(!r.outcome.success);
    assert_eq!(r.outcome.failure_kind, Some(macrotree::FailureKind::GoalNotMet));
    let reason = r.outcome.failure_reason.unwrap();
    assert!(
        reason.contains("the scene's goal does not hold: not red in red_bin"),
        "{reason}"
    );
}

/// A carry whose set-down spot is beside the bowl fails before lowering, naming the bowl.
#[test]
fn a_carry_that_would_lower_the_fingers_onto_the_bowl_names_it() {
    let dir = tempdir("descent");
    let tree = dir.join("beside.yaml");
    std::fs::write(
        &tree,
        "main:\n  sequence:\n    children:\n      - release: {width: 0.065, retreat: 0}\n      - reach: {target: cube, offset: [0, 0, 0.12]}\n      - reach: {target: cube, path: cartesian}\n      - grasp: {}\n      - carry: {to: [0.45, -0.02, 0.0], lift: 0.15}\n",
    )
    .unwrap();
    let plan = Arc::new(Loader::default().load(&tree).unwrap());
    let scene = Scene::load().unwrap();
    let r = run_episode(
        &scene,
        plan,
        &macrotree::factory::Factory::builtin(),
        &EpisodeConfig::default(),
        &mut NoObserver,
    );
    assert_eq!(r.outcome.failure_kind, Some(macrotree::FailureKind::Blocked));
    let reason = r.outcome.failure_reason.unwrap_or_default();
    assert!(
        reason.contains("no clear way down") && reason.contains("would hit bowl"),
        "{reason}"
    );
    assert_eq!(r.outcome.failed_node.as_deref(), Some("main/sequence/carry"));
}

/// MuJoCo resets a simulation whose state blows up and carries on; the episode must not.
#[test]
fn a_mujoco_instability_is_reported() {
    let scene = Scene::load().unwrap();
    let mut sim = Sim::new(&scene);
    assert_eq!(sim.instability(), None);
    sim.data_mut().qpos_mut()[0] = f64::NAN;
    sim.step();
    let why = sim.instability().expect("a warning");
    assert!(why.contains("bad qpos"), "{why}");
    sim.reset(&macrotree::sim::Layout::default());
    assert_eq!(sim.instability(), None, "a reset clears the warnings");
}

fn tempdir(name: &str) -> std::path::PathBuf {
    let dir = Path::new(ROOT)
        .join("target")
        .join(format!("multi_object_{name}"))
        .join("t");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Issue 18: which sampler a sweep uses is the scene file's `sampler:` setting, not whether the
/// scene equals the built-in one: a renamed copy of `cube_bowl.yaml` keeps the tutorial's
/// sampler (and its `--cube … --bowl …` layouts), the same cell without the line samples every
/// object from its own `random:`.
#[test]
fn the_tutorial_sampler_follows_the_scene_setting_not_the_scene_name() {
    use macrotree::scene::SceneSpec;
    let text = std::fs::read_to_string(Path::new(ROOT).join("scenes/cube_bowl.yaml")).unwrap();
    let sweep = SweepConfig {
        seed: 11,
        ..SweepConfig::default()
    };
    let copy = Scene::load_spec(&SceneSpec::from_str(&text, "my_cell.yaml").unwrap()).unwrap();
    let s = sweep.scenario(&copy, 3).unwrap();
    let (seed, layout) = macrotree::sweep::sample_layout(11, 3);
    assert_eq!(s.layout, Some(layout));
    assert_eq!(s.seed, seed);
    let cube = copy.spec.legacy_cube().unwrap();
    assert_eq!(s.placement.poses[cube].x, layout.cube[0]);
    let plain = text.replace("\nsampler: tutorial\n", "\n");
    let plain = Scene::load_spec(&SceneSpec::from_str(&plain, "cube_bowl.yaml").unwrap()).unwrap();
    let s = sweep.scenario(&plain, 3).unwrap();
    assert_eq!(s.layout, None, "no tutorial layout without the setting");
    let (seed, placement) = macrotree::scene::sample_placement(&plain.spec, 11, 3).unwrap();
    assert_eq!((s.seed, s.placement), (seed, placement));
}

#[test]
fn an_unsatisfiable_random_placement_is_a_typed_error_from_load_spec_not_a_panic() {
    // A scene built in code (never read from a file, so never checked there) whose two
    // `random:`-only objects must both sit on one point: no draw can separate them.
    let mut spec = macrotree::scene::SceneSpec::builtin();
    for o in &mut spec.objects {
        o.pose = None;
        o.random = Some(macrotree::scene::RandomPlacement {
            x: [0.5, 0.5],
            y: [0.2, 0.2],
            yaw: None,
            clearance: 0.01,
            support: None,
            regions: Vec::new(),
        });
    }
    match Scene::load_spec(&spec) {
        Err(e @ macrotree::sim::SimError::Placement { .. }) => {
            let text = e.to_string();
            assert!(text.contains("default placement cannot be drawn"), "{text}");
            assert!(text.contains("random:"), "says what to change: {text}");
        }
        Err(e) => panic!("expected a placement error, got {e}"),
        Ok(_) => panic!("a scene whose placement cannot be drawn was built"),
    }
}
