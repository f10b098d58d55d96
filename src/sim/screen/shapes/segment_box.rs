//! The distance between a segment and an oriented box: the core of a capsule–box pair, and
//! its quick lower bound.

use super::{V3, dot, sub};

/// Squared distance from local point `x` to the box `|x_i| ≤ h_i`.
#[inline]
pub(super) fn point_box_dist2(x: &V3, h: &V3) -> f64 {
    let mut d = 0.0;
    for i in 0..3 {
        let e = x[i].abs() - h[i];
        if e > 0.0 {
            d += e * e;
        }
    }
    d
}

/// The piece of the segment–box squared distance around the point `m` (box coordinates) of the
/// segment `a + t d`: coordinate i adds `(x_i − c_i)²`, `c_i = ±h_i` outside the slab and
/// nothing inside, so the piece's quadratic has its minimum at `t = num / den` (`den` 0: flat).
pub(super) fn piece_minimum(a: &V3, d: &V3, half: &V3, m: &V3) -> (f64, f64) {
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..3 {
        let c = if m[i] > half[i] {
            half[i]
        } else if m[i] < -half[i] {
            -half[i]
        } else {
            continue;
        };
        num -= (a[i] - c) * d[i];
        den += d[i] * d[i];
    }
    (num, den)
}

/// Squared distance between the segment `p`–`q` and an oriented box, metres². Exact: along the
/// segment the squared distance is a convex piecewise quadratic whose pieces change where a
/// coordinate crosses a face plane. The pieces are walked from `p`: the first whose own
/// minimiser does not lie past its end holds the minimum (the function cannot fall again after
/// it), found in closed form.
pub(crate) fn segment_box_dist2(p: &V3, q: &V3, center: &V3, axes: &[V3; 3], half: &V3) -> f64 {
    let rp = sub(p, center);
    let rq = sub(q, center);
    let a = V3::new(dot(&axes[0], &rp), dot(&axes[1], &rp), dot(&axes[2], &rp));
    let b = V3::new(dot(&axes[0], &rq), dot(&axes[1], &rq), dot(&axes[2], &rq));
    let d = sub(&b, &a);
    // The interior break points, where a coordinate crosses ±h, in order (insertion).
    let mut ts = [0.0f64; 6];
    let mut n = 0;
    for i in 0..3 {
        if d[i] != 0.0 {
            for s in [-half[i], half[i]] {
                let t = (s - a[i]) / d[i];
                if t > 0.0 && t < 1.0 {
                    let mut k = n;
                    while k > 0 && ts[k - 1] > t {
                        ts[k] = ts[k - 1];
                        k -= 1;
                    }
                    ts[k] = t;
                    n += 1;
                }
            }
        }
    }
    let at = |t: f64| V3::new(a[0] + d[0] * t, a[1] + d[1] * t, a[2] + d[2] * t);
    let mut t0 = 0.0;
    for &t1 in ts[..n].iter().chain(&[1.0]) {
        if t1 <= t0 {
            continue;
        }
        let (num, den) = piece_minimum(&a, &d, half, &at(0.5 * (t0 + t1)));
        // Flat (den 0), or rising by the piece's end: the minimum is on this piece.
        if den == 0.0 || num <= t1 * den {
            let t = if den > 0.0 { (num / den).clamp(t0, t1) } else { t0 };
            return point_box_dist2(&at(t), half);
        }
        t0 = t1;
    }
    point_box_dist2(&b, half)
}

/// A quick lower bound on [`segment_box_dist2`], metres²: the squared distance from the box of
/// the segment's bounding box in the box's frame (the segment lies inside that bounding box, so
/// it is never farther from the box).
#[inline]
pub(super) fn axis_box_out2(a: &V3, b: &V3, center: &V3, axes: &[V3; 3], half: &V3) -> f64 {
    let (ra, rb) = (sub(a, center), sub(b, center));
    let mut out2 = 0.0;
    for i in 0..3 {
        let (u, v) = (dot(&axes[i], &ra), dot(&axes[i], &rb));
        let e = (u.min(v) - half[i]).max(-half[i] - u.max(v));
        if e > 0.0 {
            out2 += e * e;
        }
    }
    out2
}
