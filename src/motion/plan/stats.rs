//! What one planning query cost and produced.

use std::time::Duration;

/// Counts and measures of one planning query (also carried by a failure).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlanStats {
    /// Goal configurations offered.
    pub goals: usize,
    /// Goal configurations inside the bounds and free of collision.
    pub free_goals: usize,
    /// True when the straight joint-space segment from the start to a goal was free (no search).
    pub direct: bool,
    /// Search iterations run (0 for a direct motion).
    pub iterations: usize,
    /// Nodes of both search trees at the end (roots included).
    pub nodes: usize,
    /// Configurations given to the collision checker, all stages together.
    pub collision_checks: u64,
    /// Of those, per stage: start and goals with the direct segments, the search, the
    /// shortcutting, and the final validation with the corner blends.
    pub stage_checks: [u64; 4],
    /// Joint-space length of the path the search found, radians (Euclidean).
    pub raw_length: f64,
    /// Joint-space length after shortcutting, radians (Euclidean, corners not blended).
    pub length: f64,
    /// Waypoints of the shortcut path, start and goal included.
    pub waypoints: usize,
    /// Corners blended (the others the arm stops at).
    pub blends: usize,
    /// Duration of the timed trajectory, seconds.
    pub duration: f64,
    /// Wall-clock time the query took (for reports only; no decision uses it).
    pub planning_time: Duration,
    /// Checks decided without the checker's exact test while its screen was on: answered by the
    /// screen ([`screen`](super::FastChecks::screen)), or vouched for along a segment by a
    /// neighbour's spare clearance.
    pub screened: u64,
    /// True when the exact re-check of the final path found a configuration the screen had
    /// passed blocked, and the query was planned again with exact checks only (its checks
    /// included).
    pub screen_fallback: bool,
}

impl PlanStats {
    /// One line for logs: time, nodes, checks, lengths, duration.
    pub fn summary(&self) -> String {
        format!(
            "{:.2} ms, {} iterations, {} nodes, {} checks ({:?} by stage, {} screened{}), {}/{} goals free, length {:.3} rad ({:.3} found), {} waypoints, {} blends, {:.3} s{}",
            self.planning_time.as_secs_f64() * 1e3,
            self.iterations,
            self.nodes,
            self.collision_checks,
            self.stage_checks,
            self.screened,
            if self.screen_fallback {
                ", fell back to exact checks"
            } else {
                ""
            },
            self.free_goals,
            self.goals,
            self.length,
            self.raw_length,
            self.waypoints,
            self.blends,
            self.duration,
            if self.direct { ", direct" } else { "" }
        )
    }
}

/// Euclidean joint-space length of a polyline, radians.
pub fn path_length(path: &[[f64; 6]]) -> f64 {
    path.windows(2).map(|w| distance(&w[0], &w[1])).sum()
}

/// Euclidean joint-space distance, radians.
#[inline]
pub fn distance(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    distance2(a, b).sqrt()
}

/// Squared Euclidean joint-space distance, rad².
#[inline]
pub fn distance2(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    let mut s = 0.0;
    for j in 0..6 {
        let d = a[j] - b[j];
        s += d * d;
    }
    s
}
