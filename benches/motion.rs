//! The motion planner's benchmark: `cargo bench --bench motion` (add `-- N` for N queries per
//! family, default 40; `-- coarse` checks joint steps only, without the displacement bound). Families in the spirit of MotionBenchMaker on the real cell (Menagerie
//! UR5e + 2F-85, MuJoCo collision checking with the default 5 mm margin): open table, deep bin,
//! tall obstacle between, clutter, and infeasible queries whose reason must be right. Queries are
//! drawn from a seeded stream, so every run plans the same queries; times are wall clock of
//! `plan` alone (one thread), the checker built once per family. Starts are redrawn until free (the arm never starts in
//! collision); a feasible-family query whose every goal configuration is blocked is reported
//! apart, not counted.

use std::time::Duration;

use macrotree::motion::plan::{Collision, CollisionChecker, GoalSet, PlanFailure, PlannerConfig, plan};
use macrotree::motion::{HOME_Q, Trajectory, down_pose, ik};
use macrotree::scene::SceneSpec;
use macrotree::sim::collision::{DEFAULT_MARGIN, SceneChecker};
use macrotree::sim::{Scene, Sim};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// One query: a start, a goal pose (top-down pinch position and yaw), and the reason it must
/// fail with, if it is infeasible by construction.
struct Query {
    start: [f64; 6],
    goal: (Vector3<f64>, f64),
    expect: Option<&'static str>,
}

struct Family {
    name: &'static str,
    scene: &'static str,
    queries: fn(&mut ChaCha8Rng) -> Query,
}

const OPEN: &str = "objects:
  cube: {block: {size: 0.044}, pose: [0.5, -0.3]}
";

const BIN: &str = "objects:
  cube: {block: {size: 0.044}, pose: [0.35, -0.25]}
  bin: {container: {inner: [0.24, 0.24], wall_height: 0.12}, pose: [0.45, 0.22]}
";

const POST: &str = "objects:
  cube: {block: {size: 0.044}, pose: [0.3, -0.35]}
  post: {obstacle: {size: [0.06, 0.06, 0.30]}, pose: [0.45, 0.0]}
";

const CLUTTER: &str = "objects:
  cube: {block: {size: 0.044}, pose: [0.3, -0.38]}
  p1: {obstacle: {size: [0.05, 0.05, 0.25]}, pose: [0.40, -0.05]}
  p2: {obstacle: {size: [0.05, 0.05, 0.25]}, pose: [0.55, 0.05]}
  p3: {obstacle: {size: [0.05, 0.05, 0.20]}, pose: [0.35, 0.15]}
  wall: {obstacle: {size: [0.30, 0.02, 0.12]}, pose: [0.50, -0.25]}
";

fn at(x: f64, y: f64, z: f64, yaw: f64) -> [f64; 6] {
    ik(&down_pose(&Vector3::new(x, y, z), yaw), &HOME_Q).expect("start in reach")
}

fn open_table(r: &mut ChaCha8Rng) -> Query {
    let start = at(
        r.random_range(0.3..0.6),
        r.random_range(-0.35..0.35),
        r.random_range(0.1..0.35),
        r.random_range(-1.5..1.5),
    );
    let goal = Vector3::new(
        r.random_range(0.3..0.6),
        r.random_range(-0.35..0.35),
        r.random_range(0.05..0.35),
    );
    Query {
        start,
        goal: (goal, r.random_range(-1.5..1.5)),
        expect: None,
    }
}

fn deep_bin(r: &mut ChaCha8Rng) -> Query {
    let start = at(
        r.random_range(0.3..0.55),
        r.random_range(-0.35..-0.1),
        r.random_range(0.08..0.25),
        r.random_range(-1.0..1.0),
    );
    // Down into the 12 cm deep bin: pinch 6-9 cm above its floor.
    let goal = Vector3::new(
        0.45 + r.random_range(-0.02..0.02),
        0.22 + r.random_range(-0.02..0.02),
        r.random_range(0.07..0.10),
    );
    Query {
        start,
        goal: (goal, r.random_range(-0.3..0.3)),
        expect: None,
    }
}

fn tall_obstacle(r: &mut ChaCha8Rng) -> Query {
    let start = at(
        r.random_range(0.38..0.52),
        r.random_range(-0.3..-0.15),
        r.random_range(0.08..0.22),
        r.random_range(-1.0..1.0),
    );
    let goal = Vector3::new(
        r.random_range(0.38..0.52),
        r.random_range(0.15..0.3),
        r.random_range(0.08..0.22),
    );
    Query {
        start,
        goal: (goal, r.random_range(-1.0..1.0)),
        expect: None,
    }
}

fn clutter(r: &mut ChaCha8Rng) -> Query {
    let start = at(
        r.random_range(0.3..0.45),
        r.random_range(-0.2..-0.12),
        r.random_range(0.12..0.3),
        r.random_range(-1.0..1.0),
    );
    let goal = Vector3::new(
        r.random_range(0.45..0.6),
        r.random_range(0.12..0.3),
        r.random_range(0.08..0.3),
    );
    Query {
        start,
        goal: (goal, r.random_range(-1.0..1.0)),
        expect: None,
    }
}

fn infeasible(r: &mut ChaCha8Rng) -> Query {
    let start = at(
        r.random_range(0.3..0.6),
        r.random_range(-0.35..-0.15),
        r.random_range(0.1..0.3),
        0.0,
    );
    if r.random_bool(0.5) {
        // Inside the post: every IK branch collides.
        let goal = Vector3::new(
            0.45 + r.random_range(-0.01..0.01),
            r.random_range(-0.01..0.01),
            r.random_range(0.05..0.25),
        );
        Query {
            start,
            goal: (goal, r.random_range(-1.5..1.5)),
            expect: Some("goal_in_collision"),
        }
    } else {
        // Beyond the reach.
        let goal = Vector3::new(
            r.random_range(1.0..1.3),
            r.random_range(-0.3..0.3),
            r.random_range(0.05..0.3),
        );
        Query {
            start,
            goal: (goal, 0.0),
            expect: Some("no_goal"),
        }
    }
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[i]
}

fn main() {
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(40)
        .clamp(1, 10_000);
    // `coarse`: joint steps only (no displacement bound): faster, may graze between checks.
    let coarse = std::env::args().any(|a| a == "coarse");
    let families = [
        Family {
            name: "open_table",
            scene: OPEN,
            queries: open_table,
        },
        Family {
            name: "deep_bin",
            scene: BIN,
            queries: deep_bin,
        },
        Family {
            name: "tall_obstacle",
            scene: POST,
            queries: tall_obstacle,
        },
        Family {
            name: "clutter",
            scene: CLUTTER,
            queries: clutter,
        },
        Family {
            name: "infeasible",
            scene: POST,
            queries: infeasible,
        },
    ];
    println!(
        "motion planner benchmark: {n} queries per family, MuJoCo checker (margin {} mm), edge resolution {} rad{}, one thread",
        DEFAULT_MARGIN * 1e3,
        PlannerConfig::default().resolution,
        if coarse {
            " only (coarse)"
        } else {
            " and 1 cm displacement"
        }
    );
    println!(
        "{:<14} {:>9} {:>8} {:>8} {:>8} {:>8} {:>7} {:>6} {:>9} {:>9} {:>8}",
        "family",
        "success",
        "p50 ms",
        "p95 ms",
        "max ms",
        "checks",
        "direct",
        "clean",
        "length",
        "duration",
        "reason"
    );
    for f in &families {
        let spec = SceneSpec::from_str(f.scene, "bench.yaml").expect("valid scene");
        let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
        let sim = Sim::new(&scene);
        let mut checker = SceneChecker::from_sim(&sim, DEFAULT_MARGIN).expect("checker");
        let mut exact = SceneChecker::from_sim(&sim, 0.0).expect("checker");
        let mut clean = 0;
        let mut worst: Vec<Collision> = Vec::new();
        let mut rng = ChaCha8Rng::seed_from_u64(0x0B07_0100);
        let (mut ok, mut feasible, mut right, mut infeasible) = (0, 0, 0, 0);
        let (mut times, mut checks, mut lengths, mut durations) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut direct = 0;
        let mut blocked_goal = 0;
        let mut failures: Vec<String> = Vec::new();
        for k in 0..n {
            // The arm never starts in collision: redraw until the start is free.
            let mut q = (f.queries)(&mut rng);
            for _ in 0..1000 {
                if checker.is_free(&q.start) {
                    break;
                }
                q = (f.queries)(&mut rng);
            }
            let goals = GoalSet::down(&q.goal.0, q.goal.1, false, &q.start);
            let config = PlannerConfig {
                seed: k as u64,
                time_cap: Some(Duration::from_millis(250)),
                max_displacement: if coarse { f64::INFINITY } else { 0.01 },
                ..PlannerConfig::default()
            };
            let out = plan(&mut checker, &q.start, &goals, &config);
            let stats = match &out {
                Ok(m) => m.stats.clone(),
                Err(e) => (*e.stats).clone(),
            };
            times.push(stats.planning_time.as_secs_f64() * 1e3);
            checks.push(stats.collision_checks as f64);
            match (&out, q.expect) {
                (Ok(m), None) => {
                    feasible += 1;
                    ok += 1;
                    direct += usize::from(m.stats.direct);
                    // Re-checked every 2 ms of the timed motion without margin.
                    let steps = (m.trajectory.duration() / 0.002).ceil() as usize;
                    let mut deepest: Option<Collision> = None;
                    for i in 0..=steps {
                        for c in exact.collisions(&m.trajectory.sample(i as f64 * 0.002).0) {
                            if deepest.as_ref().is_none_or(|d| c.distance < d.distance) {
                                deepest = Some(c);
                            }
                        }
                    }
                    match deepest {
                        None => clean += 1,
                        Some(c) => worst.push(c),
                    }
                    lengths.push(m.stats.length);
                    durations.push(m.stats.duration);
                }
                (Err(e), None) => {
                    feasible += 1;
                    // Goals the planner proves blocked are not planner failures: the query was
                    // infeasible for this cell (a random goal inside an obstacle).
                    if matches!(
                        e.reason,
                        PlanFailure::GoalInCollision { .. }
                            | PlanFailure::NoGoal { .. }
                            | PlanFailure::StartInCollision { .. }
                    ) {
                        feasible -= 1;
                        blocked_goal += 1;
                    } else {
                        failures.push(format!("query {k}: {e}"));
                    }
                }
                (Err(e), Some(want)) => {
                    infeasible += 1;
                    right += usize::from(e.reason.name() == want);
                }
                (Ok(_), Some(want)) => {
                    infeasible += 1;
                    failures.push(format!("query {k}: planned, expected {want}"));
                }
            }
        }
        times.sort_by(f64::total_cmp);
        checks.sort_by(f64::total_cmp);
        let mean = |v: &[f64]| {
            if v.is_empty() {
                f64::NAN
            } else {
                v.iter().sum::<f64>() / v.len() as f64
            }
        };
        let success = if feasible > 0 {
            format!("{ok}/{feasible}")
        } else {
            "-".into()
        };
        let reason = if infeasible > 0 {
            format!("{right}/{infeasible}")
        } else {
            "-".into()
        };
        println!(
            "{:<14} {:>9} {:>8.2} {:>8.2} {:>8.2} {:>8.0} {:>7} {:>6} {:>9.3} {:>9.3} {:>8}",
            f.name,
            success,
            quantile(&times, 0.5),
            quantile(&times, 0.95),
            times.last().copied().unwrap_or(f64::NAN),
            quantile(&checks, 0.5),
            direct,
            clean,
            mean(&lengths),
            mean(&durations),
            reason
        );
        if !worst.is_empty() {
            worst.sort_by(|a, b| a.distance.total_cmp(&b.distance));
            let depths: Vec<f64> = worst.iter().map(|c| -c.distance * 1e3).collect();
            println!(
                "    not clean: deepest contact per motion p50 {:.1} mm, max {:.1} mm ({})",
                depths[depths.len() / 2],
                depths[0],
                worst[0]
            );
        }
        if blocked_goal > 0 {
            println!(
                "    ({blocked_goal} drawn queries had every goal configuration blocked and are not counted)"
            );
        }
        for line in failures.iter().take(3) {
            println!("    {line}");
        }
    }
    println!(
        "(success: planned / feasible queries; checks: median per query; direct: planned without search; clean: planned motions with no contact at all when re-checked every 2 ms without margin; length: mean joint-space path length after shortcutting, rad; duration: mean timed trajectory, s; reason: right reason / infeasible queries)"
    );
}
