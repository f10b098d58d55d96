//! Straight joint-space segments checked at a resolution: between two checked configurations
//! no joint turns more than a set angle and no point of the robot moves more than a set distance.

use super::checker::CollisionChecker;

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

/// True when every configuration strictly between `a` and `b`, at [`steps`] equal steps of
/// `res`, is free; `a` and `b` themselves are the caller's (checked before). The steps are visited in
/// bisection order (the middle, then the quarters, …) so a blocked segment is usually found
/// after few checks. On a hit, returns the blocked configuration in `Err`.
pub fn check_segment<C: CollisionChecker + ?Sized>(
    checker: &mut C,
    a: &[f64; 6],
    b: &[f64; 6],
    res: &Resolution,
) -> Result<(), [f64; 6]> {
    let n = steps(a, b, res);
    if n < 2 {
        return Ok(());
    }
    // Breadth-first bisection of the index range: the middle, then the middles of the halves, …
    let mut queue = std::collections::VecDeque::with_capacity(16);
    queue.push_back((0usize, n));
    while let Some((lo, hi)) = queue.pop_front() {
        if hi - lo < 2 {
            continue;
        }
        let k = lo + (hi - lo) / 2;
        let q = lerp(a, b, k, n);
        if !checker.is_free(&q) {
            return Err(q);
        }
        queue.push_back((lo, k));
        queue.push_back((k, hi));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records every configuration it is asked about; all free.
    struct Log(Vec<[f64; 6]>);
    impl CollisionChecker for Log {
        fn is_free(&mut self, q: &[f64; 6]) -> bool {
            self.0.push(*q);
            true
        }
    }

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
