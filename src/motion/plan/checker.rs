//! What the planner asks of a collision model: is a configuration free, and if not, what touches.

use std::fmt;

use super::spare::{JointSpare, SPARE_CAP};

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
}

/// What a checker may offer the planner beyond state validity, to decide configurations without
/// its exact test: a conservative screen, spare clearances that vouch for the configurations
/// near a free one, and how far a verdict reaches along a line. Every method has a default
/// that offers nothing, so a checker with none of them implements it empty
/// (`impl FastChecks for MyChecker {}`); the planner then asks
/// [`is_free`](CollisionChecker::is_free) about every configuration. (OMPL keeps state validity
/// and motion validation apart the same way.)
pub trait FastChecks: CollisionChecker {
    /// A fast screen, asked before [`is_free`](CollisionChecker::is_free): `Some(true)` only when `q`
    /// (radians) is certainly free (e.g. a model that bounds every part of the robot and the
    /// scene keeps the margin), `Some(false)` only when it is certainly blocked (exact shapes
    /// deeper than the margin), `None` when it cannot tell (the default: no screen). The
    /// planner searches and shortcuts with "screen, else `is_free`" (the start and the goals
    /// with `is_free` alone), then re-checks the final path with `is_free` alone at the edge
    /// resolution, so a screen that errs towards "free" only costs time, never a collision.
    fn screen(&mut self, _q: &[f64; 6]) -> Option<bool> {
        None
    }

    /// The [`screen`](Self::screen)'s verdict at `q` (radians) and, with a "free", its spare
    /// clearance by joint range ([`JointSpare`], metres; none with any other verdict, and none
    /// by default). In each range the spare is at most `caps`': the spare worth measuring
    /// ([`JointSpare::wanted`]), so a pair that surely keeps more need not be measured. The
    /// planner vouches with it for the configurations the joints reach within it, as with
    /// [`exact_spare`](Self::exact_spare), and re-checks the final path like every path the
    /// screen helped find.
    fn screen_spare(&mut self, q: &[f64; 6], _caps: &JointSpare) -> (Option<bool>, JointSpare) {
        (self.screen(q), JointSpare::NONE)
    }

    /// The exact checker's spare clearance at `q` (radians) by joint range ([`JointSpare`]):
    /// lower bounds, in metres, on how much farther than the clearance margin everything the arm
    /// must not touch is, at most `cap` (metres). `None` when `q` may not be free, or the checker
    /// cannot measure it (the default). The planner vouches with it for the configurations near
    /// `q`: a point of the robot moves relative to a partner at most `Σ_j r_j |Δq_j|` over the
    /// joints that move the pair (lever arms `r_j`), so within the range's spare every pair
    /// still keeps the margin.
    fn exact_spare(&mut self, _q: &[f64; 6], _cap: f64) -> Option<JointSpare> {
        None
    }

    /// The verdict at `q` (radians) with how far it reaches along a straight line: `None` when
    /// `q` is blocked; `Some(k)` (`k ≥ 0`, a number of steps, not necessarily whole) when `q`
    /// is free and every configuration `q + λ · step` with `|λ| ≤ k` keeps the margin too
    /// (`step`: a joint change, radians). A reach beyond `want` steps is of no use to the
    /// caller and need not be measured. The planner's segment check
    /// ([`check_segment`](super::edge::check_segment)) does not ask about those configurations.
    /// The default knows no reach: [`is_free`](CollisionChecker::is_free), and `k = 0`.
    fn free_reach(&mut self, q: &[f64; 6], _step: &[f64; 6], _want: f64) -> Option<f64> {
        self.is_free(q).then_some(0.0)
    }

    /// Told by the segment check that `samples` configurations of a segment's resolution were
    /// decided free without asking (within a [`free_reach`](Self::free_reach), or between two
    /// such neighbourhoods less than a step apart): a checker that counts its checks counts
    /// them. False refuses them (a check budget is spent), and the segment counts as blocked.
    /// The default accepts them.
    fn vouched(&mut self, _samples: u64) -> bool {
        true
    }
}

impl<C: CollisionChecker + ?Sized> CollisionChecker for &mut C {
    fn is_free(&mut self, q: &[f64; 6]) -> bool {
        (**self).is_free(q)
    }
    fn collisions(&mut self, q: &[f64; 6]) -> Vec<Collision> {
        (**self).collisions(q)
    }
}

impl<C: FastChecks + ?Sized> FastChecks for &mut C {
    fn screen(&mut self, q: &[f64; 6]) -> Option<bool> {
        (**self).screen(q)
    }
    fn screen_spare(&mut self, q: &[f64; 6], caps: &JointSpare) -> (Option<bool>, JointSpare) {
        (**self).screen_spare(q, caps)
    }
    fn exact_spare(&mut self, q: &[f64; 6], cap: f64) -> Option<JointSpare> {
        (**self).exact_spare(q, cap)
    }
    fn free_reach(&mut self, q: &[f64; 6], step: &[f64; 6], want: f64) -> Option<f64> {
        (**self).free_reach(q, step, want)
    }
    fn vouched(&mut self, samples: u64) -> bool {
        (**self).vouched(samples)
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
/// checker's [`screen`](FastChecks::screen) answers first: its "free" is taken, its
/// "blocked" too; each check counts once either way. With `vouch_arms` set, the verdicts come
/// with a spare clearance (the screen's while `screen` is on, the exact checker's while it is
/// off), [`free_reach`](FastChecks::free_reach) turns it into the samples it vouches for
/// along a segment, and while the screen is off a configuration a remembered exact spare covers
/// is free without asking. (The screen's spares are not remembered: asked only up to what a
/// move wants of each range, they seldom cover another segment's configurations, and looking
/// them up cost more than it saved.)
pub(crate) struct Counting<'a, C: FastChecks + ?Sized> {
    pub(crate) inner: &'a mut C,
    pub(crate) checks: u64,
    /// Checks at most (`u64::MAX`: none).
    pub(crate) budget: u64,
    /// Ask the inner checker's screen first.
    pub(crate) screen: bool,
    /// Checks decided without the exact test while the screen is on: answered by the screen,
    /// or vouched for along a segment.
    pub(crate) screened: u64,
    /// Lever arms (metres) to vouch with a measured spare clearance for configurations near
    /// the measured one: the exact checker's ([`FastChecks::exact_spare`]) while the
    /// screen is off, the screen's ([`FastChecks::screen_spare`]) while it is on; `None`:
    /// every configuration is asked.
    pub(crate) vouch_arms: Option<[f64; 6]>,
    /// Configurations the exact checker measured, with their spare clearance.
    balls: Balls,
}

/// Measured configurations [`Counting`] remembers to vouch with the exact checker's spare.
const EXACT_BALLS: usize = 32;

/// Recently measured configurations and their spare clearance by joint range (radians;
/// metres), a ring: a configuration the joints reach within a remembered spare keeps the margin
/// too ([`JointSpare::covers`]).
struct Balls {
    /// Configuration and spare (metres).
    ring: Vec<([f64; 6], JointSpare)>,
    next: usize,
    size: usize,
}

impl Balls {
    fn new(size: usize) -> Self {
        Self {
            ring: Vec::with_capacity(size),
            next: 0,
            size,
        }
    }

    /// The spare left at `q` ([`JointSpare::after`]) by the newest remembered configuration
    /// whose spare covers it, joint `j` turning a point at most `arms[j]` metres per radian
    /// (less where the spare's reach is nearer the axis); `None` when none does.
    fn cover(&self, q: &[f64; 6], arms: &[f64; 6]) -> Option<JointSpare> {
        self.ring.iter().rev().find_map(|(c, spare)| {
            let dq: [f64; 6] = std::array::from_fn(|j| q[j] - c[j]);
            // Most remembered configurations are far: rejected without the ranges.
            if spare.surely_beyond(arms, &dq) {
                return None;
            }
            spare.after(arms, &dq)
        })
    }

    fn remember(&mut self, q: &[f64; 6], spare: JointSpare) {
        let entry = (*q, spare);
        if self.ring.len() < self.size {
            self.ring.push(entry);
        } else {
            self.ring[self.next] = entry;
            self.next = (self.next + 1) % self.size;
        }
    }
}

impl<'a, C: FastChecks + ?Sized> Counting<'a, C> {
    pub(crate) fn new(inner: &'a mut C) -> Self {
        Self {
            inner,
            checks: 0,
            budget: u64::MAX,
            screen: true,
            screened: 0,
            vouch_arms: None,
            balls: Balls::new(EXACT_BALLS),
        }
    }

    /// The verdict at `q` (radians) and, with a "free", the spare clearance by joint range that
    /// vouches for configurations near it ([`JointSpare::NONE`] when none is known): the
    /// screen's while `screen` is on (unsure: the exact checker's verdict), the exact checker's
    /// while it is off (a remembered spare, else measured, else
    /// `is_free`). Counted as one check; `None` also once the budget is spent.
    fn verdict(&mut self, q: &[f64; 6], caps: &JointSpare) -> Option<JointSpare> {
        if self.spent() {
            return None;
        }
        self.checks += 1;
        if self.screen {
            if self.vouch_arms.is_none() {
                return match self.inner.screen(q) {
                    Some(free) => {
                        self.screened += 1;
                        free.then_some(JointSpare::NONE)
                    }
                    None => self.inner.is_free(q).then_some(JointSpare::NONE),
                };
            }
            match self.inner.screen_spare(q, caps) {
                (Some(true), spare) => {
                    self.screened += 1;
                    return Some(spare);
                }
                (Some(false), _) => {
                    self.screened += 1;
                    return None;
                }
                (None, _) => {}
            }
        } else if let Some(arms) = self.vouch_arms {
            if let Some(rest) = self.balls.cover(q, &arms) {
                return Some(rest);
            }
            // The exact spare is one for every range: the whole chain's cap, the widest.
            if let Some(spare) = self.inner.exact_spare(q, caps.get(0, 5)) {
                self.balls.remember(q, spare);
                return Some(spare);
            }
        }
        self.inner.is_free(q).then_some(JointSpare::NONE)
    }

    /// True when the budget is used.
    pub(crate) fn spent(&self) -> bool {
        self.checks >= self.budget
    }
}

impl<C: FastChecks + ?Sized> CollisionChecker for Counting<'_, C> {
    fn is_free(&mut self, q: &[f64; 6]) -> bool {
        self.verdict(q, &JointSpare::uniform(SPARE_CAP)).is_some()
    }
    fn collisions(&mut self, q: &[f64; 6]) -> Vec<Collision> {
        self.inner.collisions(q)
    }
}

impl<C: FastChecks + ?Sized> FastChecks for Counting<'_, C> {
    /// The steps of `step` (radians per step) within the spare the verdict at `q` comes with
    /// ([`JointSpare::steps_along`] through the vouching lever arms; none without them). Each
    /// range's spare is measured up to what `want` steps need of it ([`JointSpare::wanted`],
    /// [`SPARE_CAP`] at most): a small cap lets the checkers skip the pairs that surely keep it.
    fn free_reach(&mut self, q: &[f64; 6], step: &[f64; 6], want: f64) -> Option<f64> {
        let Some(arms) = self.vouch_arms else {
            return self.verdict(q, &JointSpare::uniform(SPARE_CAP)).map(|_| 0.0);
        };
        let caps = JointSpare::wanted(&arms, step, want, SPARE_CAP);
        Some(self.verdict(q, &caps)?.steps_along(&arms, step))
    }
    /// Counts the samples as checks (as screened ones while the screen is on), refusing them
    /// past the budget.
    fn vouched(&mut self, samples: u64) -> bool {
        if self.checks.saturating_add(samples) > self.budget {
            self.checks = self.budget;
            return false;
        }
        self.checks += samples;
        if self.screen {
            self.screened += samples;
        }
        true
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

    #[test]
    fn the_spare_ring_keeps_the_newest_and_covers_only_within_a_spare() {
        let arms = [1.0; 6];
        let mut balls = Balls::new(2);
        let at = |x: f64| [x, 0.0, 0.0, 0.0, 0.0, 0.0];
        balls.remember(&at(0.0), JointSpare::uniform(0.01));
        // Covered, with the spare left: 1 mm of the 1 cm.
        let rest = balls.cover(&at(0.009), &arms).expect("within the spare");
        assert!((rest.least() - 0.001).abs() < 1e-12, "{}", rest.least());
        assert!(balls.cover(&at(0.011), &arms).is_none());
        balls.remember(&at(1.0), JointSpare::uniform(0.01));
        balls.remember(&at(2.0), JointSpare::uniform(0.01));
        // The oldest was replaced: two remembered at most.
        assert!(balls.cover(&at(0.0), &arms).is_none());
        assert!(balls.cover(&at(1.005), &arms).is_some() && balls.cover(&at(1.995), &arms).is_some());
    }
}
