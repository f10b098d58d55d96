//! Straight joint-space segments checked at a resolution: between two checked configurations
//! no joint turns more than a set angle and no point of the robot moves more than a set distance.

use super::checker::FastChecks;

/// How finely motions are checked.
///
/// The displacement bound uses lever arms: `r_j` bounds the distance of every point of the
/// moving robot (and a held block) from joint `j`'s axis, so a point moves at most
/// `Σ_j r_j |Δq_j|` metres when the joints change by `Δq`. With a checker whose clearance margin
/// is at least half the displacement bound, every configuration *between* two checked ones is
/// free of contact too: a point is then within half a step of where it was at a checked
/// configuration, where it kept the margin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resolution {
    /// Largest change of any joint between checked configurations, radians.
    pub joint: f64,
    /// Largest displacement of any point of the robot between checked configurations, metres;
    /// `f64::INFINITY` bounds the joints only.
    pub displacement: f64,
    /// Lever arm of each joint, metres (see the type's docs).
    pub lever_arms: [f64; 6],
}

impl Resolution {
    /// Joint steps of at most `joint` radians, no displacement bound.
    pub fn joint(joint: f64) -> Self {
        Self {
            joint,
            displacement: f64::INFINITY,
            lever_arms: [0.0; 6],
        }
    }

    /// Steps needed along a joint-space curve of Euclidean length `len` radians (each joint then
    /// changes by at most `len`, and `Σ_j r_j |Δq_j| ≤ len · Σ_j r_j`).
    pub fn curve_steps(&self, len: f64) -> usize {
        let per_rad = (1.0 / self.joint).max(self.lever_arms.iter().sum::<f64>() / self.displacement);
        ((len * per_rad).ceil() as usize).max(1)
    }
}

/// The number of whole sample indices from `first` to `last` (whole numbers), 0 when none.
fn samples_within(first: f64, last: f64) -> u64 {
    if last >= first {
        (last - first) as u64 + 1
    } else {
        0
    }
}

/// Number of equal steps a segment from `a` to `b` is cut into so that no joint moves more than
/// `res.joint` radians and no point more than `res.displacement` metres per step (at least 1).
pub fn steps(a: &[f64; 6], b: &[f64; 6], res: &Resolution) -> usize {
    let (mut span, mut sweep) = (0.0f64, 0.0);
    for j in 0..6 {
        let d = (b[j] - a[j]).abs();
        span = span.max(d);
        sweep += res.lever_arms[j] * d;
    }
    ((span / res.joint).max(sweep / res.displacement).ceil() as usize).max(1)
}

/// The point `k / n` of the way from `a` to `b`.
#[inline]
pub fn lerp(a: &[f64; 6], b: &[f64; 6], k: usize, n: usize) -> [f64; 6] {
    let s = k as f64 / n as f64;
    let mut q = [0.0; 6];
    for j in 0..6 {
        q[j] = a[j] + (b[j] - a[j]) * s;
    }
    q
}

/// True when every configuration strictly between `a` and `b`, at `steps` equal steps of
/// `res`, is free; `a` and `b` themselves are the caller's (checked before). The samples are
/// visited in bisection order (the middle, then the quarters, …) so a blocked segment is usually
/// found after few checks; a sample the checker finds free with a reach
/// ([`FastChecks::free_reach`]) vouches for its neighbours within it, which are not
/// asked: each unvouched stretch is bisected in turn. On a hit, returns the blocked
/// configuration in `Err`.
pub fn check_segment<C: FastChecks + ?Sized>(
    checker: &mut C,
    a: &[f64; 6],
    b: &[f64; 6],
    res: &Resolution,
) -> Result<(), [f64; 6]> {
    let n = steps(a, b, res);
    if n < 2 {
        return Ok(());
    }
    let step: [f64; 6] = std::array::from_fn(|j| (b[j] - a[j]) / n as f64);
    // Breadth-first bisection of the stretches not yet vouched for (open intervals in units
    // of steps, between vouched ones): a stretch of at most one step is done (every point of
    // it lies within half a step of a configuration that keeps the margin); else the sample
    // nearest its middle is asked, and vouches for its reach either way. Every sample of the
    // resolution is accounted for once: asked, or told to the checker as vouched for.
    let mut queue = std::collections::VecDeque::with_capacity(16);
    queue.push_back((0.0f64, n as f64));
    while let Some((lo, hi)) = queue.pop_front() {
        if hi - lo <= 1.0 {
            let inside = samples_within(lo.floor() + 1.0, hi.ceil() - 1.0);
            if inside > 0 && !checker.vouched(inside) {
                return Err(lerp(a, b, lo.floor() as usize + 1, n));
            }
            continue;
        }
        let mut k = ((lo + hi) / 2.0).floor();
        if k <= lo {
            k = lo.floor() + 1.0;
        } else if k >= hi {
            k = hi.ceil() - 1.0;
        }
        let q = lerp(a, b, k as usize, n);
        let Some(reach) = checker.free_reach(&q, &step, (k - lo).max(hi - k)) else {
            return Err(q);
        };
        // The samples of the stretch within the reach, besides the one asked.
        let within = samples_within(
            (lo.floor() + 1.0).max((k - reach).ceil()),
            (hi.ceil() - 1.0).min((k + reach).floor()),
        );
        if within > 1 && !checker.vouched(within - 1) {
            return Err(q);
        }
        queue.push_back((lo, k - reach));
        queue.push_back((k + reach, hi));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::plan::CollisionChecker;

    /// Records every configuration it is asked about; all free.
    struct Log(Vec<[f64; 6]>);
    impl CollisionChecker for Log {
        fn is_free(&mut self, q: &[f64; 6]) -> bool {
            self.0.push(*q);
            true
        }
    }

    impl FastChecks for Log {}

    #[test]
    fn every_interior_step_is_checked_once_middle_first() {
        let a = [0.0; 6];
        let b = [1.0, -0.5, 0.0, 0.0, 0.0, 0.0];
        let mut log = Log(Vec::new());
        check_segment(&mut log, &a, &b, &Resolution::joint(0.1)).unwrap();
        assert_eq!(steps(&a, &b, &Resolution::joint(0.1)), 10);
        assert_eq!(log.0.len(), 9);
        assert!((log.0[0][0] - 0.5).abs() < 1e-12, "{:?}", log.0[0]);
        let mut xs: Vec<f64> = log.0.iter().map(|q| q[0]).collect();
        xs.sort_by(f64::total_cmp);
        for (i, x) in xs.iter().enumerate() {
            assert!((x - (i + 1) as f64 * 0.1).abs() < 1e-12);
        }
        // Neighbouring checked configurations differ by at most the resolution in every joint.
        assert!(xs.windows(2).all(|w| w[1] - w[0] <= 0.1 + 1e-12));
    }

    /// Free outside `blocked` (an interval of joint 0, radians), with a reach that keeps out of
    /// it (a sound spare: the distance to it, in steps of joint 0), at most `cap` steps;
    /// records where it is asked (joint 0).
    struct Reach {
        blocked: (f64, f64),
        cap: f64,
        asked: Vec<f64>,
        vouched: u64,
    }
    impl CollisionChecker for Reach {
        fn is_free(&mut self, q: &[f64; 6]) -> bool {
            !(self.blocked.0..=self.blocked.1).contains(&q[0])
        }
    }

    impl FastChecks for Reach {
        fn free_reach(&mut self, q: &[f64; 6], step: &[f64; 6], _want: f64) -> Option<f64> {
            self.asked.push(q[0]);
            let x = q[0];
            if !self.is_free(q) {
                return None;
            }
            let to = if x < self.blocked.0 {
                self.blocked.0 - x
            } else {
                x - self.blocked.1
            };
            Some((to / step[0].abs()).min(self.cap))
        }
        fn vouched(&mut self, samples: u64) -> bool {
            self.vouched += samples;
            true
        }
    }

    #[test]
    fn a_free_reach_vouches_for_its_neighbours_and_leaves_no_gap_over_a_step() {
        let (a, b) = ([0.0; 6], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let res = Resolution::joint(0.01);
        let mut c = Reach {
            blocked: (2.0, 2.0),
            cap: 2.5,
            asked: Vec::new(),
            vouched: 0,
        };
        check_segment(&mut c, &a, &b, &res).unwrap();
        // Each of the 99 samples accounted for once: asked, or told as vouched for.
        assert_eq!(c.asked.len() as u64 + c.vouched, 99);
        // Far fewer questions than the 99 samples, and every point of the segment within a
        // reach of 2.5 steps of an asked one or in a stretch of at most one step between such
        // neighbourhoods (the ends count as checked).
        assert!(c.asked.len() < 30, "{}", c.asked.len());
        let mut covered: Vec<(f64, f64)> = c.asked.iter().map(|x| (x - 0.025, x + 0.025)).collect();
        covered.push((0.0, 0.0));
        covered.push((1.0, 1.0));
        covered.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut end = 0.0f64;
        for (lo, hi) in covered {
            assert!(lo - end <= 0.01 + 1e-12, "a gap from {end} to {lo}");
            end = end.max(hi);
        }
    }

    #[test]
    fn an_obstacle_between_vouched_stretches_is_found() {
        // Blocked over three steps in the middle of a long free stretch.
        let (a, b) = ([0.0; 6], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let mut c = Reach {
            blocked: (0.615, 0.645),
            cap: 4.0,
            asked: Vec::new(),
            vouched: 0,
        };
        let hit = check_segment(&mut c, &a, &b, &Resolution::joint(0.01)).unwrap_err();
        assert!((0.615..=0.645).contains(&hit[0]), "{hit:?}");
    }

    #[test]
    fn a_short_segment_needs_no_check() {
        let mut log = Log(Vec::new());
        check_segment(&mut log, &[0.0; 6], &[0.04; 6], &Resolution::joint(0.05)).unwrap();
        assert!(log.0.is_empty());
    }

    #[test]
    fn the_displacement_bound_adds_steps_for_long_lever_arms() {
        let res = Resolution {
            joint: 0.05,
            displacement: 0.01,
            lever_arms: [1.0, 1.0, 0.5, 0.25, 0.25, 0.1],
        };
        // 0.1 rad of the base joint: 2 joint steps, but 0.1 m of sweep: 10 steps of 1 cm.
        assert_eq!(steps(&[0.0; 6], &[0.1, 0.0, 0.0, 0.0, 0.0, 0.0], &res), 10);
        // 0.1 rad of wrist 3: 0.01 m of sweep, the joint bound (2 steps) decides.
        assert_eq!(steps(&[0.0; 6], &[0.0, 0.0, 0.0, 0.0, 0.0, 0.1], &res), 2);
        // Along a curve every joint may move the whole length: 0.1 rad · 3.1 m/rad = 31 cm.
        assert!(
            (31..=32).contains(&res.curve_steps(0.1)),
            "{}",
            res.curve_steps(0.1)
        );
    }
}
