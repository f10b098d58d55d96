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

    /// The [`screen`](Self::screen)'s verdict at `q` (radians) and, with a "free", its spare
    /// clearance by joint range ([`JointSpare`], metres, at most `cap`; none with any other
    /// verdict, and none by default). The planner vouches with it for the configurations the
    /// joints reach within it, as with [`exact_spare`](Self::exact_spare), and re-checks them
    /// like every configuration the screen called free.
    fn screen_spare(&mut self, q: &[f64; 6], _cap: f64) -> (Option<bool>, JointSpare) {
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
    fn screen_spare(&mut self, q: &[f64; 6], cap: f64) -> (Option<bool>, JointSpare) {
        (**self).screen_spare(q, cap)
    }
    fn exact_spare(&mut self, q: &[f64; 6], cap: f64) -> Option<JointSpare> {
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

/// Spare clearance by joint range, metres: for each range of arm joints `lo..=hi` (0 = base …
/// 5 = wrist 3), a lower bound on how much farther than the clearance margin every pair of
/// parts that only those joints move relative to each other is. The fixed cell and a part of
/// link `k` (moved by joints `0..=k`) form a pair of range `0..=k`; parts of links `a < b`, a pair
/// of range `a+1..=b`. A point of a part moves relative to its partner at most
/// `Σ_{j in range} r_j |Δq_j|` (lever arms `r_j`), so a configuration whose joint changes keep
/// every range's sum within its spare keeps the margin too. Self pairs of the wrist links change
/// only with the wrist joints: a single spare for all joints would be held down by them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointSpare {
    /// `by_range[lo][hi]` for `lo ≤ hi`, metres; unused below the diagonal.
    by_range: [[f64; 6]; 6],
}

impl JointSpare {
    /// No spare anywhere: vouches for nothing.
    pub const NONE: JointSpare = JointSpare {
        by_range: [[0.0; 6]; 6],
    };

    /// The same spare `s` (metres) for every range.
    pub fn uniform(s: f64) -> Self {
        Self {
            by_range: [[s; 6]; 6],
        }
    }

    /// The spare of the range `lo..=hi` (joint indices, `lo ≤ hi ≤ 5`), metres.
    pub fn get(&self, lo: usize, hi: usize) -> f64 {
        self.by_range[lo][hi]
    }

    /// Lowers the spare of the range `lo..=hi` to `s` metres (to 0 for a negative `s`: a bound
    /// too weak to vouch) if it is less.
    pub fn tighten(&mut self, lo: usize, hi: usize, s: f64) {
        let v = &mut self.by_range[lo][hi];
        *v = v.min(s.max(0.0));
    }

    /// The least spare of any range, metres.
    pub fn least(&self) -> f64 {
        (0..6)
            .flat_map(|lo| (lo..6).map(move |hi| (lo, hi)))
            .map(|(lo, hi)| self.by_range[lo][hi])
            .fold(f64::INFINITY, f64::min)
    }

    /// True when displacements `moved[j]` (metres: joint `j`'s lever arm times its change) keep
    /// every range's sum within its spare.
    pub fn covers(&self, moved: &[f64; 6]) -> bool {
        let mut prefix = [0.0; 7];
        for j in 0..6 {
            prefix[j + 1] = prefix[j] + moved[j];
        }
        // The wrists' ranges first: their own pairs hold the smallest spares.
        (0..6)
            .rev()
            .all(|lo| (lo..6).all(|hi| prefix[hi + 1] - prefix[lo] <= self.by_range[lo][hi]))
    }
}

/// A checker that counts the configurations it is asked about (the planner's statistics) and,
/// while a budget is set, answers "blocked" without asking once the budget is used (a refusal
/// never lets a collision through; it only ends the search). While `screen` is on, the inner
/// checker's [`screen`](CollisionChecker::screen) answers first: its "free" is taken (and the
/// configuration logged for the final re-check), its "blocked" too; each check counts once
/// either way. With `vouch_arms` set, a configuration a remembered spare clearance covers is
/// free without asking: the screen's while `screen` is on (logged like the screen's "free"),
/// the exact checker's while it is off.
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
    /// Lever arms (metres) to vouch with a measured spare clearance for configurations near
    /// the measured one: the exact checker's ([`CollisionChecker::exact_spare`]) while the
    /// screen is off, the screen's ([`CollisionChecker::screen_spare`]) while it is on; `None`:
    /// every configuration is asked.
    pub(crate) vouch_arms: Option<[f64; 6]>,
    /// Configurations the exact checker measured, with their spare clearance.
    balls: Balls,
    /// Configurations the screen called free, with its spare clearance (while `screen` is on;
    /// what they vouch for is logged for the final re-check like the screen's own answers).
    screen_balls: Balls,
}

/// Measured configurations [`Counting`] remembers to vouch with the exact checker's spare.
const EXACT_BALLS: usize = 32;

/// Configurations [`Counting`] remembers to vouch with the screen's spare: enough to hold the
/// neighbours of a segment's deepest bisection level (checked up to half the segment's samples
/// earlier) for segments of a few hundred samples.
const SCREEN_BALLS: usize = 128;

/// Recently measured configurations and their spare clearance by joint range (radians;
/// metres), a ring: a configuration the joints reach within a remembered spare keeps the margin
/// too ([`JointSpare::covers`]).
struct Balls {
    /// Configuration, spare, and the spare's least range (metres).
    ring: Vec<([f64; 6], JointSpare, f64)>,
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

    /// True when `q` lies within a remembered spare, joint `j` moving a point at most
    /// `arms[j]` metres per radian.
    fn cover(&self, q: &[f64; 6], arms: &[f64; 6]) -> bool {
        self.ring.iter().rev().any(|(c, spare, least)| {
            let moved: [f64; 6] = std::array::from_fn(|j| arms[j] * (q[j] - c[j]).abs());
            // Within the least range's spare every range holds; beyond the whole chain's,
            // that range fails (most configurations far away); else each range decides.
            let total: f64 = moved.iter().sum();
            total <= *least || (total <= spare.by_range[0][5] && spare.covers(&moved))
        })
    }

    fn remember(&mut self, q: &[f64; 6], spare: JointSpare) {
        let entry = (*q, spare, spare.least());
        if self.ring.len() < self.size {
            self.ring.push(entry);
        } else {
            self.ring[self.next] = entry;
            self.next = (self.next + 1) % self.size;
        }
    }
}

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
            vouch_arms: None,
            balls: Balls::new(EXACT_BALLS),
            screen_balls: Balls::new(SCREEN_BALLS),
        }
    }

    /// True when `q` (radians) is free by the exact checker's spare clearance: within the
    /// lever-arm reach of a measured configuration's, or measured now with some to spare.
    /// False when that cannot tell (the caller asks `is_free`).
    fn exact_vouched(&mut self, q: &[f64; 6]) -> bool {
        let Some(arms) = self.vouch_arms else {
            return false;
        };
        if self.balls.cover(q, &arms) {
            return true;
        }
        match self.inner.exact_spare(q, SPARE_CAP) {
            Some(spare) => {
                self.balls.remember(q, spare);
                true
            }
            None => false,
        }
    }

    /// The screen's verdict at `q` (radians): vouched free within the reach of a remembered
    /// screen spare, else asked (its spare remembered).
    fn screened(&mut self, q: &[f64; 6]) -> Option<bool> {
        let Some(arms) = self.vouch_arms else {
            return self.inner.screen(q);
        };
        if self.screen_balls.cover(q, &arms) {
            return Some(true);
        }
        let (verdict, spare) = self.inner.screen_spare(q, SPARE_CAP);
        if verdict == Some(true) {
            self.screen_balls.remember(q, spare);
        }
        verdict
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
            match self.screened(q) {
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

    #[test]
    fn a_joint_spare_bounds_each_range_by_its_own_joints() {
        // 3 cm everywhere but the wrists' own pairs (joints 4..=5): 5 mm.
        let mut spare = JointSpare::uniform(0.03);
        spare.tighten(4, 5, 0.005);
        assert_eq!(spare.least(), 0.005);
        assert_eq!(spare.get(4, 5), 0.005);
        // A negative bound leaves no spare (0), and a larger one never raises it again.
        spare.tighten(0, 0, -1.0);
        assert_eq!(spare.get(0, 0), 0.0);
        spare.tighten(0, 0, 0.03);
        assert_eq!(spare.get(0, 0), 0.0);
        assert!(
            !spare.covers(&[0.015, 0.01, 0.0, 0.0, 0.0, 0.0]),
            "range 0..=0 has no spare"
        );
        // The base and shoulder move 2.5 cm between them: every range within its spare.
        let mut spare = JointSpare::uniform(0.03);
        spare.tighten(4, 5, 0.005);
        assert!(spare.covers(&[0.015, 0.01, 0.0, 0.0, 0.0, 0.0]));
        // Past the whole chain's spare: not covered.
        assert!(!spare.covers(&[0.015, 0.01, 0.006, 0.0, 0.0, 0.0]));
        // The wrists move 6 mm between them: range 4..=5 fails although the sum is small.
        assert!(!spare.covers(&[0.0, 0.0, 0.0, 0.0, 0.003, 0.003]));
        assert!(spare.covers(&[0.0, 0.0, 0.0, 0.0, 0.002, 0.003]));
        // Wrist 2 alone, 6 mm: range 4..=4 keeps 3 cm, but the wrists' pairs (4..=5) move by
        // joint 4 too, 6 mm against 5 mm.
        assert!(!spare.covers(&[0.0, 0.0, 0.0, 0.0, 0.006, 0.0]));
        assert!(JointSpare::NONE.covers(&[0.0; 6]));
        assert!(!JointSpare::NONE.covers(&[0.0, 0.0, 0.0, 1e-9, 0.0, 0.0]));
    }

    #[test]
    fn the_spare_ring_keeps_the_newest_and_covers_only_within_a_spare() {
        let arms = [1.0; 6];
        let mut balls = Balls::new(2);
        let at = |x: f64| [x, 0.0, 0.0, 0.0, 0.0, 0.0];
        balls.remember(&at(0.0), JointSpare::uniform(0.01));
        assert!(balls.cover(&at(0.009), &arms));
        assert!(!balls.cover(&at(0.011), &arms));
        balls.remember(&at(1.0), JointSpare::uniform(0.01));
        balls.remember(&at(2.0), JointSpare::uniform(0.01));
        // The oldest was replaced: two remembered at most.
        assert!(!balls.cover(&at(0.0), &arms));
        assert!(balls.cover(&at(1.005), &arms) && balls.cover(&at(1.995), &arms));
    }
}
