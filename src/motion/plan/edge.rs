//! Straight joint-space segments checked at a resolution: the largest change of any joint
//! between two checked configurations.

use super::checker::CollisionChecker;

/// Number of equal steps a segment from `a` to `b` is cut into so that no joint moves more than
/// `resolution` radians per step (at least 1).
pub fn steps(a: &[f64; 6], b: &[f64; 6], resolution: f64) -> usize {
    let span = (0..6).map(|j| (b[j] - a[j]).abs()).fold(0.0, f64::max);
    ((span / resolution).ceil() as usize).max(1)
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

/// True when every configuration strictly between `a` and `b`, at [`steps`] equal steps, is
/// free; `a` and `b` themselves are the caller's (checked before). The steps are visited in
/// bisection order (the middle, then the quarters, …) so a blocked segment is usually found
/// after few checks. On a hit, returns the blocked configuration in `Err`.
pub fn check_segment<C: CollisionChecker + ?Sized>(
    checker: &mut C,
    a: &[f64; 6],
    b: &[f64; 6],
    resolution: f64,
) -> Result<(), [f64; 6]> {
    let n = steps(a, b, resolution);
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
        check_segment(&mut log, &a, &b, 0.1).unwrap();
        assert_eq!(steps(&a, &b, 0.1), 10);
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
        check_segment(&mut log, &[0.0; 6], &[0.04; 6], 0.05).unwrap();
        assert!(log.0.is_empty());
    }
}
