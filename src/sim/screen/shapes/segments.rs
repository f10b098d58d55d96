//! The distance between two segments: the core of a capsule pair.

use super::{V3, axpy, dot, sub};

/// Squared distance between segments `p1`–`q1` and `p2`–`q2` (Ericson, *Real-Time Collision
/// Detection*, 5.1.9), metres².
pub(crate) fn segment_segment_dist2(p1: &V3, q1: &V3, p2: &V3, q2: &V3) -> f64 {
    const EPS: f64 = 1e-18;
    let d1 = sub(q1, p1);
    let d2 = sub(q2, p2);
    let r = sub(p1, p2);
    let a = dot(&d1, &d1);
    let e = dot(&d2, &d2);
    let f = dot(&d2, &r);
    let (s, t);
    if a <= EPS && e <= EPS {
        return dot(&r, &r);
    }
    if a <= EPS {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = dot(&d1, &r);
        if e <= EPS {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = dot(&d1, &d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > EPS {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    let c1 = axpy(s, &d1, p1);
    let c2 = axpy(t, &d2, p2);
    let w = sub(&c1, &c2);
    dot(&w, &w)
}
