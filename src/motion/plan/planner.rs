//! One planning query: check the start and the goals, try the direct segment, search, shortcut,
//! smooth and time.

use std::time::Instant;

use super::blend::smooth;
use super::checker::{CollisionChecker, Counting, FastChecks};
use super::config::PlannerConfig;
use super::edge::check_segment;
use super::goal::GoalSet;
use super::reason::{PlanError, PlanFailure, SearchBudget, tally};
use super::rrt::{Search, rrt_connect};
use super::shortcut::shortcut;
use super::stats::{PlanStats, distance, path_length};
use super::timing::PathTrajectory;

// Declared with the spare clearance it bounds; kept at this path too.

/// Goal configurations whose collisions are asked for when every goal is blocked.
const NAMED_GOALS: usize = 8;

/// The direct segment is tried to every free goal at most this many times as far (joint-space
/// distance) as the nearest free goal: a long straight swing to a far IK branch is not preferred
/// over a short detour to a near one.
pub const DIRECT_SLACK: f64 = 1.5;

/// A planned motion.
#[derive(Clone, Debug)]
pub struct PlannedMotion {
    /// Index of the reached goal in the [`GoalSet`] given.
    pub goal: usize,
    /// The path the search found, radians (start and goal included; every segment checked).
    pub raw_path: Vec<[f64; 6]>,
    /// The timed, smoothed trajectory along the shortcut path.
    pub trajectory: PathTrajectory,
    /// What the query cost.
    pub stats: PlanStats,
}

fn in_bounds(q: &[f64; 6], config: &PlannerConfig) -> bool {
    q.iter()
        .zip(&config.bounds)
        .all(|(v, (lo, hi))| v.is_finite() && *v >= *lo && *v <= *hi)
}

/// Plans a collision-free motion for the arm from `start` to any configuration of `goals`
/// (radians), with `checker` deciding what is free.
///
/// Stages: the start is checked (else [`PlanFailure::StartInCollision`] naming the pairs); goals
/// outside `config.bounds` or in collision are dropped (none left: [`PlanFailure::NoGoal`] or
/// [`PlanFailure::GoalInCollision`] naming what blocks them); the straight segment to each free
/// goal at most `DIRECT_SLACK` times as far as the nearest, in the set's order, is tried first; otherwise RRT-Connect searches towards all free goals
/// at once (out of iterations: [`PlanFailure::SearchExhausted`] naming what blocked it most).
/// The path is then shortcut, its corners blended, and timed within `config.limits`. Every
/// configuration the arm passes through was checked, at the edge resolution
/// ([`PlannerConfig::edge_resolution`]) along segments and arcs.
///
/// The search and the shortcuts ask the checker's [`screen`](FastChecks::screen) first
/// and `is_free` only when it cannot tell; when the screen helped find the path, every vertex
/// and every segment of the shortcut path is then checked again with the exact checker alone,
/// at the edge resolution (so are the corner arcs), and if one is blocked the query is planned
/// again with `is_free` alone ([`PlanStats::screen_fallback`]). The start, the goals and the
/// direct segments are checked with `is_free` alone. Along a segment, a configuration found
/// free with a spare clearance vouches for its neighbours within the lever-arm reach of it
/// ([`FastChecks::free_reach`]): the exact checker's
/// ([`exact_spare`](FastChecks::exact_spare)) wherever the screen is off, the screen's by
/// joint range ([`screen_spare`](FastChecks::screen_spare)) wherever it is on (see
/// `docs/motion.md`).
///
/// # Errors
/// A [`PlanError`]: the typed reason, and the statistics of the attempt.
pub fn plan<C: FastChecks + ?Sized>(
    checker: &mut C,
    start: &[f64; 6],
    goals: &GoalSet,
    config: &PlannerConfig,
) -> Result<PlannedMotion, PlanError> {
    let started = Instant::now();
    match attempt(checker, start, goals, config, true, started) {
        Attempt::Done(result) => result,
        Attempt::ScreenWrong { checks, screened } => {
            tracing::warn!(target: "macrotree::plan", "the collision screen passed a configuration of the final path that the exact check finds blocked: planning again with exact checks only");
            let Attempt::Done(mut result) = attempt(checker, start, goals, config, false, started) else {
                unreachable!("an attempt without the screen is never re-checked")
            };
            let stats = match &mut result {
                Ok(m) => &mut m.stats,
                Err(e) => &mut *e.stats,
            };
            stats.collision_checks += checks;
            stats.screened += screened;
            stats.screen_fallback = true;
            result
        }
    }
}

/// How one attempt ended (short-lived: the size difference of the variants does not matter).
#[allow(clippy::large_enum_variant)]
enum Attempt {
    /// A motion or a reason.
    Done(Result<PlannedMotion, PlanError>),
    /// The exact re-check of the final path found a configuration the screen had passed blocked
    /// (the checks spent, and how many of them the screen answered).
    ScreenWrong { checks: u64, screened: u64 },
}

/// The lever arms the final re-check's vouching uses, metres: the configured ones, and never
/// less than [`LEVER_ARMS`](crate::motion::ur5e::LEVER_ARMS) (a setting that bounds fewer
/// joints or shorter arms only coarsens the search's edges; it never lets the re-check skip a
/// configuration the documented bound does not cover).
fn vouching_arms(res: &super::edge::Resolution) -> [f64; 6] {
    std::array::from_fn(|j| res.lever_arms[j].max(crate::motion::ur5e::LEVER_ARMS[j]))
}

/// The exact re-check of a path the screen helped find: every vertex of `path` and every
/// segment at the edge resolution `res`, with `checker`'s screen off, in the order of the path
/// (the exact checker's spare clearance at one configuration vouches for the next ones within
/// its reach). True when all are free.
fn revalidate<C: FastChecks + ?Sized>(
    checker: &mut Counting<'_, C>,
    path: &[[f64; 6]],
    res: &super::edge::Resolution,
) -> bool {
    checker.screen = false;
    checker.is_free(&path[0])
        && path
            .windows(2)
            .all(|w| check_segment(checker, &w[0], &w[1], res).is_ok() && checker.is_free(&w[1]))
}

/// One planning attempt, with the checker's screen asked first (`screen`) or not.
fn attempt<C: FastChecks + ?Sized>(
    checker: &mut C,
    start: &[f64; 6],
    goals: &GoalSet,
    config: &PlannerConfig,
    screen: bool,
    started: Instant,
) -> Attempt {
    let mut stats = PlanStats {
        goals: goals.len(),
        ..PlanStats::default()
    };
    let mut checker = Counting::new(checker);
    // Wherever the screen is off, the exact checker's spare clearance vouches for nearby
    // configurations (the same verdicts, fewer MuJoCo calls).
    checker.vouch_arms = Some(vouching_arms(&config.edge_resolution()));
    // The start, the goals and the direct segments are checked exactly: their reasons name what
    // the exact checker finds, and a free direct segment is the path (the screen would only
    // add the re-check). The screen helps the search, the shortcuts and nothing else.
    checker.screen = false;
    let fail = |reason: PlanFailure, mut stats: PlanStats, checks: u64| {
        stats.collision_checks = checks;
        stats.planning_time = started.elapsed();
        Attempt::Done(Err(PlanError {
            reason,
            stats: Box::new(stats),
        }))
    };
    if let Err(e) = config.check() {
        return fail(PlanFailure::InvalidQuery { reason: e }, stats, 0);
    }
    let res = config.edge_resolution();
    if !in_bounds(start, config) {
        let reason = format!(
            "start {start:?} is not finite or lies outside the joint bounds {:?} (radians)",
            config.bounds
        );
        return fail(PlanFailure::InvalidQuery { reason }, stats, 0);
    }
    if !checker.is_free(start) {
        let collisions = checker.collisions(start);
        return fail(
            PlanFailure::StartInCollision { collisions },
            stats,
            checker.checks,
        );
    }
    if goals.is_empty() {
        let reason = goals
            .ik_failure
            .clone()
            .unwrap_or_else(|| "the goal set is empty".into());
        return fail(PlanFailure::NoGoal { reason }, stats, checker.checks);
    }
    let inside: Vec<usize> = (0..goals.len())
        .filter(|&i| in_bounds(&goals.configs[i], config))
        .collect();
    let out_of_bounds = goals.len() - inside.len();
    if inside.is_empty() {
        let reason = format!("all {out_of_bounds} goal configurations lie outside the joint bounds");
        return fail(PlanFailure::NoGoal { reason }, stats, checker.checks);
    }
    let mut free: Vec<usize> = Vec::with_capacity(inside.len());
    let mut blocked: Vec<usize> = Vec::new();
    for &i in &inside {
        if checker.is_free(&goals.configs[i]) {
            free.push(i);
        } else {
            blocked.push(i);
        }
    }
    stats.free_goals = free.len();
    if free.is_empty() {
        let named: Vec<_> = blocked
            .iter()
            .take(NAMED_GOALS)
            .map(|&i| checker.collisions(&goals.configs[i]))
            .collect();
        let reason = PlanFailure::GoalInCollision {
            goals: goals.len(),
            out_of_bounds,
            in_collision: blocked.len(),
            collisions: tally(named),
        };
        return fail(reason, stats, checker.checks);
    }
    // The direct segment to each free goal not much farther than the nearest, in the set's order.
    let mut found: Option<(Vec<[f64; 6]>, usize)> = None;
    // Where the direct segments were blocked: named with the search's blocks if it fails.
    let mut direct_hits: Vec<[f64; 6]> = Vec::new();
    let nearest = free
        .iter()
        .map(|&i| distance(start, &goals.configs[i]))
        .fold(f64::INFINITY, f64::min);
    for &i in &free {
        let g = &goals.configs[i];
        if distance(start, g) > DIRECT_SLACK * nearest {
            continue;
        }
        match check_segment(&mut checker, start, g, &res) {
            Ok(()) => {
                found = Some((vec![*start, *g], i));
                stats.direct = true;
                break;
            }
            Err(hit) => direct_hits.push(hit),
        }
    }
    stats.stage_checks[0] = checker.checks;
    checker.screen = screen;
    if found.is_none() {
        let free_configs: Vec<[f64; 6]> = free.iter().map(|&i| goals.configs[i]).collect();
        let (outcome, log) = rrt_connect(&mut checker, start, &free_configs, config, started);
        stats.iterations = log.iterations;
        stats.nodes = log.nodes;
        match outcome {
            Search::Found { path, goal } => found = Some((path, free[goal])),
            Search::Exhausted => {
                // Which budget ended it: the checks (counted over the whole query, so they may
                // have run out before the search began), the nodes, or the iterations.
                let spent = if checker.checks >= config.max_checks {
                    SearchBudget::Checks(config.max_checks)
                } else if log.nodes >= config.max_nodes {
                    SearchBudget::Nodes(config.max_nodes)
                } else {
                    SearchBudget::Iterations(config.max_iterations)
                };
                let named: Vec<_> = direct_hits
                    .iter()
                    .take(NAMED_GOALS)
                    .chain(&log.blocked)
                    .map(|q| checker.collisions(q))
                    .collect();
                let reason = PlanFailure::SearchExhausted {
                    spent,
                    iterations: log.iterations,
                    nodes: log.nodes,
                    checks: checker.checks,
                    blocking: tally(named),
                };
                stats.screened = checker.screened;
                return fail(reason, stats, checker.checks);
            }
            Search::TimeCap => {
                let reason = PlanFailure::TimeCap {
                    cap_s: config.time_cap.map_or(0.0, |d| d.as_secs_f64()),
                    iterations: log.iterations,
                };
                return fail(reason, stats, checker.checks);
            }
        }
    }
    stats.stage_checks[1] = checker.checks - stats.stage_checks[0];
    let (raw_path, goal) = found.expect("set above");
    stats.raw_length = path_length(&raw_path);
    let path = if raw_path.len() > 2 {
        shortcut(
            &mut checker,
            raw_path.clone(),
            config.shortcut_attempts,
            config.shortcut_min_gain,
            &res,
            config.seed,
        )
    } else {
        raw_path.clone()
    };
    stats.stage_checks[2] = checker.checks - stats.stage_checks[0] - stats.stage_checks[1];
    stats.length = path_length(&path);
    stats.waypoints = path.len();
    // From here on every check is exact: the path the screen passed is re-checked, and the
    // corner arcs are checked, with the checker's exact test alone.
    if checker.screen && checker.screened > 0 && !revalidate(&mut checker, &path, &res) {
        return Attempt::ScreenWrong {
            checks: checker.checks,
            screened: checker.screened,
        };
    }
    checker.screen = false;
    let smoothed = smooth(&mut checker, &path, config.blend_deviation, &res);
    stats.blends = smoothed.blends;
    let trajectory = PathTrajectory::new(smoothed, path, &config.limits, config.tool_speed);
    stats.duration = crate::motion::trajectory::Trajectory::duration(&trajectory);
    stats.collision_checks = checker.checks;
    stats.stage_checks[3] = checker.checks - stats.stage_checks[..3].iter().sum::<u64>();
    stats.screened = checker.screened;
    stats.planning_time = started.elapsed();
    debug_assert!(distance(&trajectory.start(), start) == 0.0);
    Attempt::Done(Ok(PlannedMotion {
        goal,
        raw_path,
        trajectory,
        stats,
    }))
}
