//! What the planner asks of a collision model: is a configuration free, and if not, what touches.

use std::fmt;

use super::planner::SPARE_CAP;

/// A collision model of the arm in its cell, queried one joint configuration at a time.
///
/// The planner only calls [`is_free`](Self::is_free) while it searches; it asks
/// [`collisions`](Self::collisions) for the few configurations it names in a failure (the
/// start, the goals, the places that blocked the search most). An implementation keeps its own
/// scratch state (hence `&mut self`), so use one checker per thread.
pub trait CollisionChecker {
    /// True when the arm at `q` (six joint angles, radians, base to wrist 3) keeps at least the
    /// checker's clearance margin from everything it must not touch.
    fn is_free(&mut self, q: &[f64; 6]) -> bool;

    /// The pairs in collision at `q` (radians), for failure messages; empty when `q` is free or
    /// the checker cannot name them (the default).
    fn collisions(&mut self, _q: &[f64; 6]) -> Vec<Collision> {
        Vec::new()
    }

    /// A fast screen, asked before [`is_free`](Self::is_free): `Some(true)` only when `q`
    /// (radians) is certainly free (e.g. a model that bounds every part of the robot and the
    /// scene keeps the margin), `Some(false)` only when it is certainly blocked (exact shapes
    /// deeper than the margin), `None` when it cannot tell (the default: no screen). The
    /// planner searches and shortcuts with "screen, else `is_free`" (the start and the goals
    /// with `is_free` unless certainly free), then re-checks with `is_free` alone every
    /// configuration of the final path the screen called free, so a screen that errs towards
    /// "free" only costs time, never a collision.
    fn screen(&mut self, _q: &[f64; 6]) -> Option<bool> {
        None
    }

    /// The exact checker's spare clearance at `q` (radians): a lower bound, in metres, on how
    /// much farther than the clearance margin everything the arm must not touch is, at most
    /// `cap` (metres); negative when `q` may not be free. `None` when the checker cannot
    /// measure it (the default). The planner's final re-check uses it to vouch for the
    /// configurations near `q`: a point of the robot moves at most `Σ_j r_j |Δq_j|` (lever
    /// arms `r_j`), so within that much of the spare clearance every pair still keeps the margin.
    fn exact_spare(&mut self, _q: &[f64; 6], _cap: f64) -> Option<f64> {
        None
    }
}

impl<C: CollisionChecker + ?Sized> CollisionChecker for &mut C {
    fn is_free(&mut self, q: &[f64; 6]) -> bool {
        (**self).is_free(q)
    }
    fn collisions(&mut self, q: &[f64; 6]) -> Vec<Collision> {
        (**self).collisions(q)
    }
    fn screen(&mut self, q: &[f64; 6]) -> Option<bool> {
        (**self).screen(q)
    }
    fn exact_spare(&mut self, q: &[f64; 6], cap: f64) -> Option<f64> {
        (**self).exact_spare(q, cap)
    }
}

/// Two named things that touch (or come closer than the margin) at one configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct Collision {
    /// The robot's part (a body or geom name), e.g. `forearm_link`.
    pub a: String,
    /// What it touches: a scene object, the table, another robot part, the held block.
    pub b: String,
    /// Signed distance between the two, metres: negative is penetration, positive is closer than
    /// the clearance margin but not touching.
    pub distance: f64,
}

impl Collision {
    /// The pair as one stable label, `a–b`, for counting and messages.
    pub fn pair(&self) -> String {
        format!("{}–{}", self.a, self.b)
    }
}

impl fmt::Display for Collision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.distance < 0.0 {
            write!(f, "{} in {} by {:.1} mm", self.a, self.b, -self.distance * 1e3)
        } else {
            write!(f, "{} within {:.1} mm of {}", self.a, self.distance * 1e3, self.b)
        }
    }
}

/// A checker that counts the configurations it is asked about (the planner's statistics) and,
/// while a budget is set, answers "blocked" without asking once the budget is used (a refusal
/// never lets a collision through; it only ends the search). While `screen` is on, the inner
/// checker's [`screen`](CollisionChecker::screen) answers first: its "free" is taken (and the
/// configuration logged for the final re-check), its "blocked" too; each check counts once
/// either way.
pub(crate) struct Counting<'a, C: CollisionChecker + ?Sized> {
    pub(crate) inner: &'a mut C,
    pub(crate) checks: u64,
    /// Checks at most (`u64::MAX`: none).
    pub(crate) budget: u64,
    /// Ask the inner checker's screen first.
    pub(crate) screen: bool,
    /// Checks the screen answered.
    pub(crate) screened: u64,
    /// The configurations the screen called free, for the final re-check, at most
    /// [`VOUCHED_LOG`]; `vouched_lost` when more were.
    pub(crate) vouched: Vec<[f64; 6]>,
    pub(crate) vouched_lost: bool,
    /// While the screen is off: lever arms (metres) to vouch with the exact checker's spare
    /// clearance ([`CollisionChecker::exact_spare`]) for configurations near a measured one;
    /// `None`: every configuration asks `is_free`.
    pub(crate) exact_vouch: Option<[f64; 6]>,
    /// Recently measured configurations and their spare clearance (radians; metres), a ring.
    balls: Vec<([f64; 6], f64)>,
    ball_next: usize,
}

/// Measured configurations [`Counting`] remembers to vouch with.
const EXACT_BALLS: usize = 32;

/// Most configurations the screen called free that a query remembers for the final re-check
/// (48 bytes each); past it, the final path is re-checked at its own edge resolution instead.
pub(crate) const VOUCHED_LOG: usize = 1 << 20;

impl<'a, C: CollisionChecker + ?Sized> Counting<'a, C> {
    pub(crate) fn new(inner: &'a mut C) -> Self {
        Self {
            inner,
            checks: 0,
            budget: u64::MAX,
            screen: true,
            screened: 0,
            vouched: Vec::new(),
            vouched_lost: false,
            exact_vouch: None,
            balls: Vec::with_capacity(EXACT_BALLS),
            ball_next: 0,
        }
    }

    /// True when `q` (radians) is free by the exact checker's spare clearance: within the
    /// lever-arm reach of a measured configuration's, or measured now with some to spare.
    /// False when that cannot tell (the caller asks `is_free`).
    fn exact_vouched(&mut self, q: &[f64; 6]) -> bool {
        let Some(arms) = self.exact_vouch else {
            return false;
        };
        let near = self.balls.iter().rev().any(|(c, spare)| {
            let moved: f64 = (0..6).map(|j| arms[j] * (q[j] - c[j]).abs()).sum();
            moved <= *spare
        });
        if near {
            return true;
        }
        match self.inner.exact_spare(q, SPARE_CAP) {
            Some(spare) if spare >= 0.0 => {
                if self.balls.len() < EXACT_BALLS {
                    self.balls.push((*q, spare));
                } else {
                    self.balls[self.ball_next] = (*q, spare);
                    self.ball_next = (self.ball_next + 1) % EXACT_BALLS;
                }
                true
            }
            _ => false,
        }
    }

    /// True when the budget is used.
    pub(crate) fn spent(&self) -> bool {
        self.checks >= self.budget
    }
}

impl<C: CollisionChecker + ?Sized> CollisionChecker for Counting<'_, C> {
    fn is_free(&mut self, q: &[f64; 6]) -> bool {
        if self.spent() {
            return false;
        }
        self.checks += 1;
        if self.screen {
            match self.inner.screen(q) {
                Some(true) => {
                    self.screened += 1;
                    if self.vouched.len() < VOUCHED_LOG {
                        self.vouched.push(*q);
                    } else {
                        self.vouched_lost = true;
                    }
                    return true;
                }
                Some(false) => {
                    self.screened += 1;
                    return false;
                }
                _ => {}
            }
        } else if self.exact_vouched(q) {
            return true;
        }
        self.inner.is_free(q)
    }
    fn collisions(&mut self, q: &[f64; 6]) -> Vec<Collision> {
        self.inner.collisions(q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collision_reads_as_depth_or_clearance() {
        let c = Collision {
            a: "forearm_link".into(),
            b: "post".into(),
            distance: -0.0042,
        };
        assert_eq!(c.to_string(), "forearm_link in post by 4.2 mm");
        assert_eq!(c.pair(), "forearm_link–post");
        let near = Collision { distance: 0.003, ..c };
        assert_eq!(near.to_string(), "forearm_link within 3.0 mm of post");
    }
}
