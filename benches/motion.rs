//! The motion planner's benchmark: `cargo bench --bench motion` (add `-- N` for N queries per
//! family, default 40; `-- coarse` checks joint steps only, without the displacement bound;
//! `-- shortcuts=N` sets the random shortcut attempts; `-- only=NAME` runs one family; `-- noplain`
//! skips the MuJoCo-only comparison, e.g. for a profiler; `-- dump=FILE` writes every query's
//! outcome, check count and path, exactly, to compare two builds byte for byte). Families in the spirit of MotionBenchMaker on the real cell (Menagerie
//! UR5e + 2F-85, MuJoCo collision checking with the default 5 mm margin): open table, deep bin,
//! tall obstacle between, clutter, a shelf opening, a wrist-singular transfer, infeasible
//! queries whose reason must be right, and a check budget too small for a search. Queries are
//! drawn from a seeded stream, so every run plans the same queries; times are wall clock of
//! `plan` alone (one thread), with the thread's CPU time beside them, the checker built once per family. Starts are redrawn until free (the arm never starts in
//! collision), and so are the goals of a feasible family until one of their configurations is
//! free: every feasible query is a real planning problem, as MotionBenchMaker's are.

use std::time::Duration;

use macrotree::motion::plan::{Collision, CollisionChecker, GoalSet, PlanFailure, PlannerConfig, plan};
use macrotree::motion::{HOME_Q, Trajectory, down_pose, ik};
use macrotree::scene::SceneSpec;
use macrotree::sim::{DEFAULT_MARGIN, SceneChecker};
use macrotree::sim::{Scene, Sim};
use nalgebra::{Isometry3, Unit, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// One query: a start, a goal pose (top-down pinch position and yaw, or a horizontal approach),
/// and the reason it must fail with, if it is infeasible by construction.
struct Query {
    start: [f64; 6],
    goal: (Vector3<f64>, f64),
    /// `Some(θ)`: the tool approaches horizontally along world direction θ (radians about z),
    /// fingers closing horizontally; `None`: the tool points down.
    side: Option<f64>,
    expect: Option<&'static str>,
}

struct Family {
    name: &'static str,
    scene: &'static str,
    /// Obstacles moved after the scene is built: (scene object name, position of its bottom
    /// centre, metres).
    placed: &'static [(&'static str, [f64; 3])],
    /// The collision-check budget of each query (`None`: the planner's default).
    max_checks: Option<u64>,
    queries: fn(&mut ChaCha8Rng) -> Query,
}

/// The pinch at `position` with the tool horizontal along world direction `theta` (radians
/// about z) and the fingers closing horizontally, across it.
fn side_pose(position: &Vector3<f64>, theta: f64) -> Isometry3<f64> {
    let down = down_pose(position, theta);
    let axis = Unit::new_normalize(Vector3::new(theta.sin(), -theta.cos(), 0.0));
    let turn = UnitQuaternion::from_axis_angle(&axis, std::f64::consts::FRAC_PI_2);
    Isometry3::from_parts(down.translation, turn * down.rotation)
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

/// A shelf opening in front of the arm: a bottom board 12 cm high and a top board whose bottom
/// is at 30 cm (an 18 cm opening between the boards, 25 cm deep, 40 cm wide). The scene format
/// stands every obstacle on the table and keeps them apart, so the top board is declared aside
/// and moved into place in the simulation (`placed`).
const SHELF: &str = "objects:
  cube: {block: {size: 0.044}, pose: [0.3, -0.4]}
  bottom: {obstacle: {size: [0.25, 0.40, 0.12]}, pose: [0.675, 0.0]}
  top: {obstacle: {size: [0.25, 0.40, 0.02]}, pose: [0.3, 0.45]}
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
        side: None,
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
        side: None,
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
        side: None,
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
        side: None,
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
    let pick = r.random_range(0..3u8);
    if pick == 2 {
        // The arm starts with its pinch inside the post.
        let start = at(
            0.45 + r.random_range(-0.01..0.01),
            r.random_range(-0.01..0.01),
            r.random_range(0.08..0.25),
            r.random_range(-1.0..1.0),
        );
        return Query {
            start,
            goal: (Vector3::new(0.4, -0.25, 0.2), 0.0),
            side: None,
            expect: Some("start_in_collision"),
        };
    }
    if pick == 0 {
        // Inside the post: every IK branch collides.
        let goal = Vector3::new(
            0.45 + r.random_range(-0.01..0.01),
            r.random_range(-0.01..0.01),
            r.random_range(0.05..0.25),
        );
        Query {
            start,
            goal: (goal, r.random_range(-1.5..1.5)),
            side: None,
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
            side: None,
            expect: Some("no_goal"),
        }
    }
}

fn shelf(r: &mut ChaCha8Rng) -> Query {
    let start = at(
        r.random_range(0.3..0.5),
        r.random_range(-0.4..-0.25),
        r.random_range(0.1..0.3),
        r.random_range(-1.0..1.0),
    );
    // Into the opening between the boards, approaching horizontally from the arm's side.
    let goal = Vector3::new(
        r.random_range(0.60..0.66),
        r.random_range(-0.08..0.08),
        r.random_range(0.19..0.23),
    );
    Query {
        start,
        goal: (goal, 0.0),
        side: Some(r.random_range(-0.2..0.2)),
        expect: None,
    }
}

fn wrist_singular(r: &mut ChaCha8Rng) -> Query {
    let start = at(
        r.random_range(0.3..0.5),
        r.random_range(-0.35..-0.15),
        r.random_range(0.1..0.3),
        r.random_range(-1.0..1.0),
    );
    // A horizontal approach across the arm's vertical plane (tangential): the wrist-3 axis lies
    // along the wrist-1 axis there (sin q5 ≈ 0, the wrist singularity).
    let goal: Vector3<f64> = Vector3::new(
        r.random_range(0.35..0.5),
        r.random_range(0.1..0.3),
        r.random_range(0.15..0.3),
    );
    let tangential = goal.y.atan2(goal.x) + std::f64::consts::FRAC_PI_2;
    Query {
        start,
        goal: (goal, 0.0),
        side: Some(tangential + r.random_range(-0.05..0.05)),
        expect: None,
    }
}

/// A query across the post (tall_obstacle's) with a budget of 40 collision checks (the start,
/// the goals and the first checks of the direct segments): no search fits, so a query whose
/// direct segment is blocked must end with `search_exhausted`, naming the post.
fn budget(r: &mut ChaCha8Rng) -> Query {
    Query {
        expect: Some("search_exhausted"),
        ..tall_obstacle(r)
    }
}

/// CPU time this thread has run, seconds (`CLOCK_THREAD_CPUTIME_ID`): what a query costs one
/// core, whatever else the machine runs.
fn thread_cpu() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec the call writes.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    assert_eq!(rc, 0, "clock_gettime");
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
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
    // `shortcuts=N`: random shortcut attempts per path (default: the planner's).
    let shortcuts: usize = std::env::args()
        .find_map(|a| a.strip_prefix("shortcuts=").and_then(|v| v.parse().ok()))
        .unwrap_or(PlannerConfig::default().shortcut_attempts);
    // `only=NAME`: run one family (for profiling); `noplain`: skip the MuJoCo-only comparison.
    let only: Option<String> = std::env::args().find_map(|a| a.strip_prefix("only=").map(str::to_string));
    let with_plain = !std::env::args().any(|a| a == "noplain");
    // `dump=FILE`: each query's outcome, checks and path (shortest round-trip decimals).
    let mut dump: Option<std::io::BufWriter<std::fs::File>> = std::env::args()
        .find_map(|a| a.strip_prefix("dump=").map(str::to_string))
        .map(|path| std::io::BufWriter::new(std::fs::File::create(path).expect("dump file")));

    let families = [
        Family {
            name: "open_table",
            scene: OPEN,
            placed: &[],
            max_checks: None,
            queries: open_table,
        },
        Family {
            name: "deep_bin",
            scene: BIN,
            placed: &[],
            max_checks: None,
            queries: deep_bin,
        },
        Family {
            name: "tall_obstacle",
            scene: POST,
            placed: &[],
            max_checks: None,
            queries: tall_obstacle,
        },
        Family {
            name: "clutter",
            scene: CLUTTER,
            placed: &[],
            max_checks: None,
            queries: clutter,
        },
        Family {
            name: "shelf",
            scene: SHELF,
            placed: &[("top", [0.675, 0.0, 0.30])],
            max_checks: None,
            queries: shelf,
        },
        Family {
            name: "wrist_singular",
            scene: POST,
            placed: &[],
            max_checks: None,
            queries: wrist_singular,
        },
        Family {
            name: "infeasible",
            scene: POST,
            placed: &[],
            max_checks: None,
            queries: infeasible,
        },
        Family {
            name: "budget",
            scene: POST,
            placed: &[],
            max_checks: Some(40),
            queries: budget,
        },
    ];
    println!(
        "motion planner benchmark: {n} queries per family, the conservative screen then the MuJoCo checker (margin {} mm), edge resolution {} rad{}, one thread",
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
    for f in families
        .iter()
        .filter(|f| only.as_deref().is_none_or(|o| o == f.name))
    {
        let spec = SceneSpec::from_str(f.scene, "bench.yaml").expect("valid scene");
        let scene = Scene::load_spec(&spec).expect("scene (run tools/bootstrap)");
        let mut sim = Sim::new(&scene);
        for (name, at) in f.placed {
            let i = spec
                .objects
                .iter()
                .position(|o| o.name == *name)
                .expect("placed object in the scene");
            let m = scene.objects[i].mocap.expect("a mocap obstacle");
            sim.data_mut().mocap_pos_mut()[m] = *at;
        }
        let mut checker = SceneChecker::from_sim(&sim, DEFAULT_MARGIN).expect("checker");
        // The same query planned with MuJoCo checks only (no screen), interleaved: the times
        // before the screen, in the same run.
        let mut plain = SceneChecker::from_sim(&sim, DEFAULT_MARGIN).expect("checker");
        plain.set_screen(false);
        let mut exact = SceneChecker::from_sim(&sim, 0.0).expect("checker");
        let (mut plain_times, mut same, mut screened, mut fallbacks) = (Vec::new(), 0, 0u64, 0);
        let mut clean = 0;
        let mut worst: Vec<Collision> = Vec::new();
        let mut rng = ChaCha8Rng::seed_from_u64(0x0B07_0100);
        let (mut ok, mut feasible, mut right, mut infeasible) = (0, 0, 0, 0);
        let (mut times, mut checks, mut lengths, mut durations) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut direct = 0;
        // CPU time of each screened query on this thread, ms.
        let mut cpu: Vec<f64> = Vec::new();
        let mut stages = [0u64; 4];
        let mut blocked_goal = 0;
        // Drawn queries whose start was free but every goal configuration blocked.
        let mut redrawn = 0;
        let mut failures: Vec<String> = Vec::new();
        for k in 0..n {
            // The arm never starts in collision, and a feasible family's goal has at least one
            // free configuration: redraw until both hold.
            let goals_of = |q: &Query| match q.side {
                None => GoalSet::down(&q.goal.0, q.goal.1, false, &q.start),
                Some(theta) => GoalSet::poses(
                    &[
                        side_pose(&q.goal.0, theta),
                        side_pose(&q.goal.0, theta + std::f64::consts::PI),
                    ],
                    &q.start,
                ),
            };
            let mut q = (f.queries)(&mut rng);
            let mut goals = goals_of(&q);
            for _ in 0..1000 {
                let start_ok = q.expect == Some("start_in_collision") || checker.is_free(&q.start);
                let goal_ok = q.expect.is_some() || goals.configs.iter().any(|g| checker.is_free(g));
                if start_ok && goal_ok {
                    break;
                }
                redrawn += usize::from(start_ok);
                q = (f.queries)(&mut rng);
                goals = goals_of(&q);
            }
            let config = PlannerConfig {
                seed: k as u64,
                max_checks: f.max_checks.unwrap_or(PlannerConfig::default().max_checks),
                shortcut_attempts: shortcuts,
                // A safety cap only: the deterministic check budget ends every search first.
                time_cap: Some(Duration::from_secs(5)),
                max_displacement: if coarse { f64::INFINITY } else { 0.01 },
                ..PlannerConfig::default()
            };
            let before = if with_plain {
                plan(&mut plain, &q.start, &goals, &config)
            } else {
                plan(&mut checker, &q.start, &goals, &config)
            };
            let cpu0 = thread_cpu();
            let out = plan(&mut checker, &q.start, &goals, &config);
            cpu.push((thread_cpu() - cpu0) * 1e3);
            if let Some(w) = dump.as_mut() {
                use std::io::Write;
                let line = match &out {
                    Ok(m) => format!(
                        "{} {k} ok checks={} raw={:?} waypoints={:?}",
                        f.name,
                        m.stats.collision_checks,
                        m.raw_path,
                        m.trajectory.waypoints()
                    ),
                    Err(e) => format!(
                        "{} {k} {} checks={}",
                        f.name,
                        e.reason.name(),
                        e.stats.collision_checks
                    ),
                };
                writeln!(w, "{line}").expect("dump write");
            }
            let stats = match &out {
                Ok(m) => m.stats.clone(),
                Err(e) => (*e.stats).clone(),
            };
            let plain_stats = match &before {
                Ok(m) => m.stats.clone(),
                Err(e) => (*e.stats).clone(),
            };
            plain_times.push(plain_stats.planning_time.as_secs_f64() * 1e3);
            screened += stats.screened;
            fallbacks += usize::from(stats.screen_fallback);
            same += usize::from(match (&before, &out) {
                (Ok(a), Ok(b)) => {
                    a.raw_path == b.raw_path && a.trajectory.waypoints() == b.trajectory.waypoints()
                }
                (Err(a), Err(b)) => a.reason.name() == b.reason.name(),
                _ => false,
            });
            times.push(stats.planning_time.as_secs_f64() * 1e3);
            for (s, c) in stages.iter_mut().zip(stats.stage_checks) {
                *s += c;
            }
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
                    // The reason, and for an exhausted search the obstacle in the way named.
                    let named = match &e.reason {
                        PlanFailure::SearchExhausted { blocking, .. } => {
                            blocking.iter().any(|(c, _)| c.b == "post")
                        }
                        _ => true,
                    };
                    if e.reason.name() == want && named {
                        right += 1;
                    } else {
                        failures.push(format!("query {k}: expected {want}, got {e}"));
                    }
                }
                (Ok(m), Some("search_exhausted")) if m.stats.direct => {
                    // The direct segment was free: no search, the budget does not apply.
                    direct += 1;
                }
                (Ok(_), Some(want)) => {
                    infeasible += 1;
                    failures.push(format!("query {k}: planned, expected {want}"));
                }
            }
        }
        let total_checks: f64 = checks.iter().sum();
        times.sort_by(f64::total_cmp);
        plain_times.sort_by(f64::total_cmp);
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
        println!(
            "    MuJoCo only (no screen), the same queries interleaved: p50 {:.2} ms, p95 {:.2} ms, max {:.2} ms (screen: p50 {:.2}x, p95 {:.2}x faster); same outcome and path {same}/{n}; checks answered by the screen {:.2}; fell back to exact {fallbacks}",
            quantile(&plain_times, 0.5),
            quantile(&plain_times, 0.95),
            plain_times.last().copied().unwrap_or(f64::NAN),
            quantile(&plain_times, 0.5) / quantile(&times, 0.5),
            quantile(&plain_times, 0.95) / quantile(&times, 0.95),
            screened as f64 / total_checks.max(1.0),
        );
        cpu.sort_by(f64::total_cmp);
        println!(
            "    CPU time of this thread (one core, whatever the load): p50 {:.2} ms, p95 {:.2} ms, max {:.2} ms",
            quantile(&cpu, 0.5),
            quantile(&cpu, 0.95),
            cpu.last().copied().unwrap_or(f64::NAN)
        );
        let total: u64 = stages.iter().sum::<u64>().max(1);
        println!(
            "    checks by stage (share): goals+direct {:.2}, search {:.2}, shortcut {:.2}, validation+blends {:.2}",
            stages[0] as f64 / total as f64,
            stages[1] as f64 / total as f64,
            stages[2] as f64 / total as f64,
            stages[3] as f64 / total as f64
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
        if redrawn > 0 {
            println!(
                "    ({redrawn} drawn queries had every goal configuration blocked (inside an obstacle, or the arm behind the gripper) and were drawn again)"
            );
        }
        if blocked_goal > 0 {
            println!(
                "    ({blocked_goal} queries ended with every goal configuration blocked and are not counted)"
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
