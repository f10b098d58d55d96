//! The planner on a synthetic checker (boxes in joint space): direct motions, detours, goal
//! sets, determinism, every failure reason, and the timing's limits.

use std::time::Duration;

use super::*;
use crate::motion::Trajectory;

const FULL: (f64, f64) = (-7.0, 7.0);

/// Half the default edge resolution (and a hair): the margin that makes checking at the
/// resolution exact for boxes in joint space.
const HALF_RES: f64 = 0.025 + 1e-9;

/// A wall across joint 1 at `[lo, hi]`, spanning joint 2 over `[lo2, hi2]` and every other joint.
fn wall(name: &str, (lo, hi): (f64, f64), (lo2, hi2): (f64, f64)) -> JointBox {
    JointBox::new(
        name,
        [lo, lo2, FULL.0, FULL.0, FULL.0, FULL.0],
        [hi, hi2, FULL.1, FULL.1, FULL.1, FULL.1],
    )
}

fn q(a: f64, b: f64) -> [f64; 6] {
    [a, b, 0.0, 0.0, 0.0, 0.0]
}

/// Every configuration the trajectory passes through, sampled every 2 ms, is free of the boxes
/// themselves (the planner checked them grown by half its resolution).
fn assert_trajectory_free(checker: &JointBoxes, t: &PathTrajectory) {
    let mut checker = JointBoxes::new(checker.boxes.clone());
    let n = (t.duration() / 0.002).ceil() as usize;
    for k in 0..=n {
        let (qk, _) = t.sample(k as f64 * 0.002);
        assert!(
            checker.collisions(&qk).is_empty(),
            "t = {:.3} s: {qk:?} collides: {:?}",
            k as f64 * 0.002,
            checker.collisions(&qk)
        );
    }
}

#[test]
fn a_free_query_is_the_direct_segment_without_search() {
    let mut c = JointBoxes::default();
    let goal = [0.5, -1.0, 1.2, -0.3, 0.4, 2.0];
    let m = plan(
        &mut c,
        &crate::motion::HOME_Q,
        &GoalSet::configs(vec![goal]),
        &PlannerConfig::default(),
    )
    .unwrap();
    assert!(m.stats.direct);
    assert_eq!(m.stats.iterations, 0);
    assert_eq!(m.raw_path.len(), 2);
    assert_eq!(m.trajectory.end(), goal);
    assert_eq!(m.trajectory.sample(m.trajectory.duration() + 1.0).0, goal);
    assert_eq!(m.trajectory.sample(0.0).0, crate::motion::HOME_Q);
    assert!(m.stats.collision_checks > 2 && m.stats.duration > 0.0);
}

#[test]
fn a_wall_in_the_way_is_gone_around_and_every_configuration_on_the_way_is_free() {
    let mut c = JointBoxes::new(vec![wall("post", (-0.3, 0.3), (-1.0, 1.0))]).with_margin(HALF_RES);
    let (start, goal) = (q(-1.0, 0.0), q(1.0, 0.0));
    let m = plan(
        &mut c,
        &start,
        &GoalSet::configs(vec![goal]),
        &PlannerConfig::default(),
    )
    .unwrap();
    assert!(!m.stats.direct);
    assert!(m.stats.iterations > 0 && m.stats.nodes > 2);
    assert!(m.raw_path.len() >= 3);
    // Around the post: some waypoint clears it in joint 2.
    assert!(
        m.trajectory.waypoints().iter().any(|w| w[1].abs() > 1.0),
        "{:?}",
        m.trajectory.waypoints()
    );
    assert!(m.stats.length <= m.stats.raw_length + 1e-12);
    assert!(m.stats.length >= 2.0);
    assert_eq!(m.trajectory.end(), goal);
    assert_trajectory_free(&c, &m.trajectory);
}

#[test]
fn the_planner_chooses_a_reachable_goal_of_the_set() {
    // The first goal is boxed in (free itself, but enclosed by a shell); the second is open.
    let shell = |name: &str, lo: f64, hi: f64| wall(name, (lo, hi), FULL);
    let mut c = JointBoxes::new(vec![shell("left", 1.6, 1.8), shell("right", 2.2, 2.4)]);
    let goals = GoalSet::configs(vec![q(2.0, 0.0), q(-2.0, 0.5)]);
    let m = plan(&mut c, &q(0.0, 0.0), &goals, &PlannerConfig::default()).unwrap();
    assert_eq!(m.goal, 1);
    assert_eq!(m.trajectory.end(), q(-2.0, 0.5));
}

fn bits(path: &[[f64; 6]]) -> Vec<u64> {
    path.iter().flatten().map(|v| v.to_bits()).collect()
}

#[test]
fn the_same_seed_gives_the_same_path_bit_for_bit() {
    let boxes = vec![
        wall("post", (-0.3, 0.3), (-1.0, 1.0)),
        wall("shelf", (0.6, 0.9), (0.5, 3.0)),
    ];
    let run = |seed: u64| {
        let mut c = JointBoxes::new(boxes.clone());
        let config = PlannerConfig {
            seed,
            ..PlannerConfig::default()
        };
        let m = plan(
            &mut c,
            &q(-1.0, 0.0),
            &GoalSet::configs(vec![q(1.5, 0.0)]),
            &config,
        )
        .unwrap();
        let samples: Vec<u64> = (0..50)
            .flat_map(|k| m.trajectory.sample(k as f64 * 0.05).0)
            .map(f64::to_bits)
            .collect();
        (
            bits(&m.raw_path),
            bits(m.trajectory.waypoints()),
            samples,
            m.stats.collision_checks,
        )
    };
    let a = run(11);
    assert_eq!(a, run(11));
    let b = run(12);
    assert_ne!(a.0, b.0, "another seed searches differently");
}

#[test]
fn a_start_in_collision_names_the_pair() {
    let mut c = JointBoxes::new(vec![wall("table", (-0.5, 0.5), FULL)]);
    let e = plan(
        &mut c,
        &q(0.0, 0.0),
        &GoalSet::configs(vec![q(1.0, 0.0)]),
        &PlannerConfig::default(),
    )
    .unwrap_err();
    match &e.reason {
        PlanFailure::StartInCollision { collisions } => {
            assert_eq!(collisions.len(), 1);
            assert_eq!(collisions[0].pair(), "arm–table");
            assert!(collisions[0].distance < 0.0);
        }
        r => panic!("{r}"),
    }
    assert_eq!(e.reason.name(), "start_in_collision");
    assert!(e.to_string().contains("arm in table"), "{e}");
    assert_eq!(e.stats.collision_checks, 1);
}

#[test]
fn goals_all_in_collision_are_counted_and_named() {
    let mut c = JointBoxes::new(vec![wall("bin_wall", (0.9, 1.1), FULL)]);
    let mut out = q(0.0, 0.0);
    out[2] = 9.0; // outside the elbow's ±π
    let goals = GoalSet::configs(vec![q(1.0, 0.0), q(1.0, 0.7), out]);
    let e = plan(&mut c, &q(-1.0, 0.0), &goals, &PlannerConfig::default()).unwrap_err();
    match &e.reason {
        PlanFailure::GoalInCollision {
            goals,
            out_of_bounds,
            in_collision,
            collisions,
        } => {
            assert_eq!((*goals, *out_of_bounds, *in_collision), (3, 1, 2));
            assert_eq!(collisions[0].0.pair(), "arm–bin_wall");
            assert_eq!(collisions[0].1, 2);
        }
        r => panic!("{r}"),
    }
    assert_eq!(e.reason.name(), "goal_in_collision");
    assert!(e.to_string().contains("2 in collision, 1 outside"), "{e}");
}

#[test]
fn no_ik_solution_is_no_goal_with_the_ik_reason() {
    let mut c = JointBoxes::default();
    let goals = GoalSet::down(
        &nalgebra::Vector3::new(2.0, 0.0, 0.2),
        0.0,
        false,
        &crate::motion::HOME_Q,
    );
    let e = plan(&mut c, &crate::motion::HOME_Q, &goals, &PlannerConfig::default()).unwrap_err();
    assert_eq!(e.reason.name(), "no_goal");
    assert!(
        e.to_string().contains("no IK solution") && e.to_string().contains("reach"),
        "{e}"
    );
    let mut out = q(0.0, 0.0);
    out[2] = 4.0;
    let e = plan(
        &mut c,
        &q(0.0, 0.0),
        &GoalSet::configs(vec![out]),
        &PlannerConfig::default(),
    )
    .unwrap_err();
    assert_eq!(e.reason.name(), "no_goal");
    assert!(e.to_string().contains("outside the joint bounds"), "{e}");
}

#[test]
fn a_disconnected_goal_exhausts_the_search_and_names_what_blocked_it() {
    let mut c = JointBoxes::new(vec![wall("fence", (-0.2, 0.2), FULL)]);
    let config = PlannerConfig {
        max_iterations: 300,
        max_checks: 10_000_000,
        ..PlannerConfig::default()
    };
    let e = plan(
        &mut c,
        &q(-1.0, 0.0),
        &GoalSet::configs(vec![q(1.0, 0.0)]),
        &config,
    )
    .unwrap_err();
    match &e.reason {
        PlanFailure::SearchExhausted {
            spent,
            iterations,
            nodes,
            blocking,
            ..
        } => {
            assert_eq!(*spent, super::SearchBudget::Iterations(300));
            assert_eq!(*iterations, 300);
            assert!(*nodes > 2);
            assert_eq!(blocking[0].0.pair(), "arm–fence");
        }
        r => panic!("{r}"),
    }
    assert_eq!(e.reason.name(), "search_exhausted");
    assert_eq!(e.stats.iterations, 300);
}

#[test]
fn the_node_cap_also_ends_the_search() {
    let mut c = JointBoxes::new(vec![wall("fence", (-0.2, 0.2), FULL)]);
    let config = PlannerConfig {
        max_nodes: 40,
        ..PlannerConfig::default()
    };
    let e = plan(
        &mut c,
        &q(-1.0, 0.0),
        &GoalSet::configs(vec![q(1.0, 0.0)]),
        &config,
    )
    .unwrap_err();
    assert_eq!(e.reason.name(), "search_exhausted");
    assert!(e.stats.nodes <= 40 + 20, "{}", e.stats.nodes);
}

#[test]
fn the_time_cap_ends_the_search_with_its_own_reason() {
    let mut c = JointBoxes::new(vec![wall("fence", (-0.2, 0.2), FULL)]);
    // Budgets far beyond what 1 ms allows: the wall-clock cap ends the search.
    let config = PlannerConfig {
        time_cap: Some(Duration::from_millis(1)),
        max_iterations: 10_000_000,
        max_nodes: 10_000_000,
        max_checks: 10_000_000,
        ..PlannerConfig::default()
    };
    let e = plan(
        &mut c,
        &q(-1.0, 0.0),
        &GoalSet::configs(vec![q(1.0, 0.0)]),
        &config,
    )
    .unwrap_err();
    assert!(matches!(e.reason, PlanFailure::TimeCap { .. }), "{}", e.reason);
    assert_eq!(e.reason.name(), "time_cap");
    let zero = PlannerConfig {
        time_cap: Some(Duration::ZERO),
        ..PlannerConfig::default()
    };
    assert!(zero.check().unwrap_err().contains("time_cap"));
}

#[test]
fn the_check_budget_ends_the_search_with_no_path_deterministically() {
    let config = PlannerConfig {
        max_checks: 3000,
        max_iterations: 10_000_000,
        max_nodes: 10_000_000,
        ..PlannerConfig::default()
    };
    let run = || {
        let mut c = JointBoxes::new(vec![wall("fence", (-0.2, 0.2), FULL)]);
        plan(
            &mut c,
            &q(-1.0, 0.0),
            &GoalSet::configs(vec![q(1.0, 0.0)]),
            &config,
        )
        .unwrap_err()
    };
    let (e, again) = (run(), run());
    match &e.reason {
        PlanFailure::SearchExhausted { checks, blocking, .. } => {
            // A hard cap: not one check past the budget (the names come after it).
            assert_eq!(*checks, 3000);
            assert_eq!(blocking[0].0.pair(), "arm–fence");
        }
        r => panic!("{r}"),
    }
    assert_eq!(e.reason, again.reason);
    assert_eq!(e.stats.iterations, again.stats.iterations);
    assert!(config.clone().check().is_ok());
    let bad = PlannerConfig {
        max_checks: 0,
        ..PlannerConfig::default()
    };
    assert!(bad.check().unwrap_err().contains("max_checks"));
}

#[test]
fn a_malformed_query_is_refused_before_any_check() {
    let mut c = JointBoxes::default();
    let mut start = q(0.0, 0.0);
    start[3] = f64::NAN;
    let e = plan(
        &mut c,
        &start,
        &GoalSet::configs(vec![q(1.0, 0.0)]),
        &PlannerConfig::default(),
    )
    .unwrap_err();
    assert_eq!(e.reason.name(), "invalid_query");
    let bad = PlannerConfig {
        range: -1.0,
        ..PlannerConfig::default()
    };
    let e = plan(&mut c, &q(0.0, 0.0), &GoalSet::configs(vec![q(1.0, 0.0)]), &bad).unwrap_err();
    assert_eq!(e.reason.name(), "invalid_query");
    assert_eq!(c.checks, 0);
}

/// The peak speed of the pinch point along `t`, m/s: forward kinematics every 1 ms.
fn peak_pinch_speed(t: &PathTrajectory) -> f64 {
    let dt = 1e-3;
    let n = (t.duration() / dt).ceil() as usize;
    let mut prev = crate::motion::fk(&t.sample(0.0).0).translation.vector;
    let mut peak: f64 = 0.0;
    for k in 1..=n {
        let p = crate::motion::fk(&t.sample(k as f64 * dt).0).translation.vector;
        peak = peak.max((p - prev).norm() / dt);
        prev = p;
    }
    peak
}

/// A carry's planned transfer swung the held block at up to 3.3 m/s (`go_around`, seed 1),
/// timed by the joint limits alone, while the carry's `speed` (0.5 m/s) bounded only its straight
/// lines. A tool speed now caps the pinch along the whole timed path: the same path, slower where
/// the arm reaches far, and only there.
#[test]
fn a_planned_carry_swung_the_held_block_far_faster_than_the_carrys_tool_speed() {
    let mut c = JointBoxes::new(vec![wall("post", (-0.3, 0.3), (-1.0, 1.0))]).with_margin(HALF_RES);
    let start = [-1.0, -1.2, 1.5, -1.9, -1.57, 0.0];
    let goal = [1.2, -1.0, 1.2, -1.7, -1.57, 0.5];
    let plan_at = |c: &mut JointBoxes, tool_speed: f64| {
        let config = PlannerConfig {
            seed: 5,
            tool_speed,
            ..PlannerConfig::default()
        };
        plan(c, &start, &GoalSet::configs(vec![goal]), &config).unwrap()
    };
    let free = plan_at(&mut c, f64::INFINITY);
    let capped = plan_at(&mut c, 0.5);
    assert_eq!(
        free.raw_path, capped.raw_path,
        "the cap changes the timing, not the path"
    );
    assert_eq!(free.trajectory.waypoints(), capped.trajectory.waypoints());
    let (fast, slow) = (
        peak_pinch_speed(&free.trajectory),
        peak_pinch_speed(&capped.trajectory),
    );
    assert!(fast > 1.0, "without the cap the pinch swings fast: {fast} m/s");
    // Capped at the timing's cell boundaries (0.01 rad of path apart): a hair over between them.
    assert!(slow <= 0.5 * 1.02, "{slow} m/s");
    assert!(slow > 0.45, "the cap is reached, not undershot: {slow} m/s");
    assert!(capped.trajectory.duration() > free.trajectory.duration());
    assert_eq!(capped.trajectory.sample(capped.trajectory.duration()).0, goal);
    // A non-positive tool speed is an invalid query.
    let bad = PlannerConfig {
        tool_speed: 0.0,
        ..PlannerConfig::default()
    };
    assert!(bad.check().unwrap_err().contains("tool_speed"));
}

#[test]
fn the_timed_trajectory_keeps_every_joint_within_its_speed_and_acceleration() {
    let mut c = JointBoxes::new(vec![
        wall("post", (-0.3, 0.3), (-1.0, 1.0)),
        JointBox::new(
            "block",
            [0.8, -7.0, -0.5, -7.0, -7.0, -7.0],
            [1.2, 7.0, 0.5, 7.0, 7.0, 7.0],
        ),
    ])
    .with_margin(HALF_RES);
    let limits = JointLimits {
        velocity: [3.0, 2.5, 3.0, 1.0, 2.0, 3.0],
        acceleration: [15.0, 10.0, 12.0, 5.0, 8.0, 15.0],
    };
    let config = PlannerConfig {
        limits,
        seed: 3,
        ..PlannerConfig::default()
    };
    let goal = [2.0, 0.3, 1.0, 1.5, -0.5, 0.2];
    let m = plan(&mut c, &q(-1.0, 0.0), &GoalSet::configs(vec![goal]), &config).unwrap();
    assert!(
        m.stats.blends > 0 || m.stats.waypoints == 2,
        "{}",
        m.stats.summary()
    );
    let t = &m.trajectory;
    let dt = 1e-4;
    let n = (t.duration() / dt).ceil() as usize;
    let (mut vmax, mut amax) = ([0.0f64; 6], [0.0f64; 6]);
    let mut prev = t.sample(0.0).0;
    for k in 0..=n {
        let tk = k as f64 * dt;
        let (qk, qd, qdd) = t.sample_full(tk);
        for j in 0..6 {
            vmax[j] = vmax[j].max(qd[j].abs());
            amax[j] = amax[j].max(qdd[j].abs());
            // The reported velocity is the derivative of the position.
            if k > 0 {
                let fd = (qk[j] - prev[j]) / dt;
                assert!(
                    fd.abs() <= limits.velocity[j] * (1.0 + 1e-6) + 1e-9,
                    "joint {j} at {tk}: {fd}"
                );
            }
        }
        prev = qk;
    }
    for j in 0..6 {
        assert!(
            vmax[j] <= limits.velocity[j] * (1.0 + 1e-9),
            "joint {j} speed {}",
            vmax[j]
        );
        assert!(
            amax[j] <= limits.acceleration[j] * (1.0 + 1e-9),
            "joint {j} acceleration {}",
            amax[j]
        );
    }
    // Some joint runs at its limit somewhere (the profile is not needlessly slow).
    assert!((0..6).any(|j| vmax[j] > 0.95 * limits.velocity[j]), "{vmax:?}");
    assert_eq!(t.sample(0.0).1, [0.0; 6]);
    assert_eq!(t.sample(t.duration()).0, goal);
    assert_trajectory_free(&c, t);
}

#[test]
fn the_stats_summary_is_one_line_with_the_counts() {
    let mut c = JointBoxes::new(vec![wall("post", (-0.3, 0.3), (-1.0, 1.0))]);
    let m = plan(
        &mut c,
        &q(-1.0, 0.0),
        &GoalSet::configs(vec![q(1.0, 0.0)]),
        &PlannerConfig::default(),
    )
    .unwrap();
    let s = m.stats.summary();
    assert!(!s.contains('\n'));
    assert!(s.contains(&format!("{} nodes", m.stats.nodes)), "{s}");
    assert_eq!(m.stats.collision_checks, c.checks);
}

/// A checker with a screen: `inner` decides, the screen answers for configurations whose joint
/// 1 is farther than `clear_above` from 0 (a lying screen calls everything free).
struct Screened {
    inner: JointBoxes,
    clear_above: f64,
    lies: bool,
    asked: u64,
}

impl CollisionChecker for Screened {
    fn is_free(&mut self, q: &[f64; 6]) -> bool {
        self.inner.is_free(q)
    }
    fn collisions(&mut self, q: &[f64; 6]) -> Vec<Collision> {
        self.inner.collisions(q)
    }
}

impl FastChecks for Screened {
    fn screen(&mut self, q: &[f64; 6]) -> Option<bool> {
        self.asked += 1;
        if self.lies {
            return Some(true);
        }
        (q[0].abs() > self.clear_above).then(|| self.inner.is_free(q))
    }
}

fn post() -> JointBoxes {
    JointBoxes::new(vec![wall("post", (-0.3, 0.3), (-1.0, 1.0))]).with_margin(HALF_RES)
}

#[test]
fn an_honest_screen_changes_no_path_and_the_final_path_is_rechecked_exactly() {
    let (start, goal) = (q(-1.0, 0.0), q(1.0, 0.0));
    for seed in 0..4 {
        let config = PlannerConfig {
            seed,
            ..PlannerConfig::default()
        };
        let exact = plan(&mut post(), &start, &GoalSet::configs(vec![goal]), &config).unwrap();
        let mut s = Screened {
            inner: post(),
            clear_above: 0.5,
            lies: false,
            asked: 0,
        };
        let fast = plan(&mut s, &start, &GoalSet::configs(vec![goal]), &config).unwrap();
        assert_eq!(exact.raw_path, fast.raw_path, "seed {seed}");
        assert_eq!(exact.trajectory.waypoints(), fast.trajectory.waypoints());
        assert!(fast.stats.screened > 0 && s.asked > 0);
        assert_eq!(exact.stats.screened, 0);
        assert!(!fast.stats.screen_fallback);
        // The re-check adds exact checks of the final path, nothing else.
        assert!(fast.stats.collision_checks > exact.stats.collision_checks);
        assert_eq!(fast.stats.stage_checks[..3], exact.stats.stage_checks[..3]);
    }
}

#[test]
fn a_screen_that_lies_is_caught_by_the_recheck_and_the_query_planned_exactly() {
    let (start, goal) = (q(-1.0, 0.0), q(1.0, 0.0));
    let config = PlannerConfig::default();
    let mut s = Screened {
        inner: post(),
        clear_above: 0.0,
        lies: true,
        asked: 0,
    };
    let m = plan(&mut s, &start, &GoalSet::configs(vec![goal]), &config).unwrap();
    assert!(m.stats.screen_fallback);
    let exact = plan(&mut post(), &start, &GoalSet::configs(vec![goal]), &config).unwrap();
    assert_eq!(m.raw_path, exact.raw_path);
    assert!(m.stats.collision_checks > exact.stats.collision_checks);
    assert_trajectory_free(&post(), &m.trajectory);
}

#[test]
fn a_shortcut_that_would_save_little_is_not_checked() {
    // A path bent by 0.05 rad around a small box on its chord: the straight segment from the
    // start to the end is blocked, and every random shortcut between its two legs saves under
    // 0.2 % of the stretch it would replace.
    let mut c = JointBoxes::new(vec![wall("peg", (0.99, 1.01), (-0.01, 0.01))]);
    let path = vec![q(0.0, 0.0), q(1.0, 0.05), q(2.0, 0.0)];
    let res = PlannerConfig::default().edge_resolution();
    let run = |c: &mut JointBoxes, gain: f64| {
        c.checks = 0;
        let out = super::shortcut::shortcut(c, path.clone(), 16, gain, &res, 7);
        (out, c.checks)
    };
    let (skipped, few) = run(&mut c, 0.02);
    let (checked, many) = run(&mut c, 0.0);
    // Skipped: only the greedy pass and the final sweep asked (the blocked chord, twice).
    assert_eq!(skipped, path);
    assert!(
        few > 0 && many > few + 16,
        "{few} checks with the threshold, {many} without"
    );
    // Checked, the shortcuts that pass beside the peg were taken: shorter, by under 0.2 %.
    let (a, b) = (stats::path_length(&skipped), stats::path_length(&checked));
    assert!(b < a && b > a * 0.998, "{a} → {b}");
}
