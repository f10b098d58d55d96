//! Convex primitives for a conservative collision screen: capsules (a sphere is a capsule of
//! zero length), oriented boxes and half-spaces, and whether two of them come closer than a
//! distance. Every test errs on the side of "near": it may call a pair near that is a little
//! farther apart (a box's rounded offset is bounded by a larger box), never the other way.
//! Plain `[f64; 3]` arithmetic, no allocation.

/// A point or direction in metres (world or local frame, as documented at each use).
pub type V3 = [f64; 3];

#[inline]
fn sub(a: &V3, b: &V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
fn dot(a: &V3, b: &V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn axpy(s: f64, a: &V3, b: &V3) -> V3 {
    [b[0] + s * a[0], b[1] + s * a[1], b[2] + s * a[2]]
}

/// A convex primitive posed in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// Every point within `radius` metres of the segment `a`–`b`.
    Capsule {
        /// One end of the axis, metres.
        a: V3,
        /// The other end, metres.
        b: V3,
        /// Radius, metres.
        radius: f64,
    },
    /// An oriented box: `center + Σ_i s_i · axes[i]`, `|s_i| ≤ half[i]`.
    Box {
        /// Centre, metres.
        center: V3,
        /// Orthonormal axes (the rows).
        axes: [V3; 3],
        /// Half extents along the axes, metres.
        half: V3,
    },
    /// Every point `p` with `normal · p ≤ offset` (the solid below a plane).
    HalfSpace {
        /// Unit outward normal.
        normal: V3,
        /// `normal · p` on the plane, metres.
        offset: f64,
    },
}

impl Shape {
    /// Centre and radius (metres) of a sphere around the shape; `None` for a half-space.
    pub fn bounding_sphere(&self) -> Option<(V3, f64)> {
        match self {
            Shape::Capsule { a, b, radius } => {
                let c = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, (a[2] + b[2]) / 2.0];
                let h = dot(&sub(b, a), &sub(b, a)).sqrt() / 2.0;
                Some((c, h + radius))
            }
            Shape::Box { center, half, .. } => Some((*center, dot(half, half).sqrt())),
            Shape::HalfSpace { .. } => None,
        }
    }
}

/// True when `x` and `y` may come closer than `gap` metres (`gap` ≥ 0): always true when they
/// are that close, possibly true when a box's corner region makes them look closer than they
/// are. Two half-spaces are always near.
pub fn near(x: &Shape, y: &Shape, gap: f64) -> bool {
    use Shape::*;
    match (x, y) {
        (
            Capsule { a, b, radius },
            Capsule {
                a: c,
                b: d,
                radius: r2,
            },
        ) => {
            let t = radius + r2 + gap;
            segment_segment_dist2(a, b, c, d) < t * t
        }
        (Capsule { a, b, radius }, Box { center, axes, half })
        | (Box { center, axes, half }, Capsule { a, b, radius }) => {
            let t = radius + gap;
            segment_box_dist2(a, b, center, axes, half) < t * t
        }
        (
            Box {
                center: c1,
                axes: a1,
                half: h1,
            },
            Box {
                center: c2,
                axes: a2,
                half: h2,
            },
        ) => {
            let inflated = [h1[0] + gap, h1[1] + gap, h1[2] + gap];
            boxes_overlap(c1, a1, &inflated, c2, a2, h2)
        }
        (Capsule { a, b, radius }, HalfSpace { normal, offset })
        | (HalfSpace { normal, offset }, Capsule { a, b, radius }) => {
            dot(normal, a).min(dot(normal, b)) - offset < radius + gap
        }
        (Box { center, axes, half }, HalfSpace { normal, offset })
        | (HalfSpace { normal, offset }, Box { center, axes, half }) => {
            let reach: f64 = (0..3).map(|i| half[i] * dot(&axes[i], normal).abs()).sum();
            dot(normal, center) - reach - offset < gap
        }
        (HalfSpace { .. }, HalfSpace { .. }) => true,
    }
}

/// True when `x` and `y` surely lie more than `d` metres apart by a quick bound, false when it
/// cannot tell: for a capsule against a box, the distance from the box of the capsule axis's
/// bounding box in the box's frame, less the radius (the axis lies inside that bounding box,
/// so it is never farther from the box). A lower bound on [`clearance`]; a few products
/// against the exact distance's walk.
pub fn beyond(x: &Shape, y: &Shape, d: f64) -> bool {
    use Shape::*;
    match (x, y) {
        (Capsule { a, b, radius }, Box { center, axes, half })
        | (Box { center, axes, half }, Capsule { a, b, radius }) => {
            let (ra, rb) = (sub(a, center), sub(b, center));
            let mut out2 = 0.0;
            for i in 0..3 {
                let (u, v) = (dot(&axes[i], &ra), dot(&axes[i], &rb));
                let e = (u.min(v) - half[i]).max(-half[i] - u.max(v));
                if e > 0.0 {
                    out2 += e * e;
                }
            }
            let t = radius + d;
            t < 0.0 || out2 > t * t
        }
        _ => false,
    }
}

/// `None` when `x` and `y` may come closer than `gap` metres ([`near`]), else their
/// [`clearance`] (at least `gap`), computed once where the two tests share their distance
/// (capsule pairs, capsule–box).
pub fn apart(x: &Shape, y: &Shape, gap: f64) -> Option<f64> {
    use Shape::*;
    let (d2, radii) = match (x, y) {
        (
            Capsule { a, b, radius },
            Capsule {
                a: c,
                b: e,
                radius: r2,
            },
        ) => (segment_segment_dist2(a, b, c, e), radius + r2),
        (Capsule { a, b, radius }, Box { center, axes, half })
        | (Box { center, axes, half }, Capsule { a, b, radius }) => {
            (segment_box_dist2(a, b, center, axes, half), *radius)
        }
        _ => return (!near(x, y, gap)).then(|| clearance(x, y)),
    };
    let t = radii + gap;
    (d2 >= t * t).then(|| (d2.sqrt() - radii).max(0.0))
}

/// A lower bound on the distance between `x` and `y`, metres (0 when they may touch, and for
/// two half-spaces): exact for capsule pairs, capsule–box and anything against a half-space; for
/// two boxes the widest gap of their projections on the six face axes (every separating
/// projection bounds the distance from below).
pub fn clearance(x: &Shape, y: &Shape) -> f64 {
    use Shape::*;
    let d = match (x, y) {
        (
            Capsule { a, b, radius },
            Capsule {
                a: c,
                b: e,
                radius: r2,
            },
        ) => segment_segment_dist2(a, b, c, e).sqrt() - radius - r2,
        (Capsule { a, b, radius }, Box { center, axes, half })
        | (Box { center, axes, half }, Capsule { a, b, radius }) => {
            segment_box_dist2(a, b, center, axes, half).sqrt() - radius
        }
        (
            Box {
                center: c1,
                axes: a1,
                half: h1,
            },
            Box {
                center: c2,
                axes: a2,
                half: h2,
            },
        ) => boxes_face_gap(c1, a1, h1, c2, a2, h2),
        (Capsule { a, b, radius }, HalfSpace { normal, offset })
        | (HalfSpace { normal, offset }, Capsule { a, b, radius }) => {
            dot(normal, a).min(dot(normal, b)) - offset - radius
        }
        (Box { center, axes, half }, HalfSpace { normal, offset })
        | (HalfSpace { normal, offset }, Box { center, axes, half }) => {
            let reach: f64 = (0..3).map(|i| half[i] * dot(&axes[i], normal).abs()).sum();
            dot(normal, center) - reach - offset
        }
        (HalfSpace { .. }, HalfSpace { .. }) => 0.0,
    };
    d.max(0.0)
}

/// The widest gap between the projections of two oriented boxes on their six face axes,
/// metres (negative when every projection overlaps): a lower bound on their distance when
/// positive.
fn boxes_face_gap(c1: &V3, a1: &[V3; 3], h1: &V3, c2: &V3, a2: &[V3; 3], h2: &V3) -> f64 {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = dot(&a1[i], &a2[j]).abs();
        }
    }
    let tw = sub(c2, c1);
    let mut best = f64::NEG_INFINITY;
    for i in 0..3 {
        let rb = h2[0] * r[i][0] + h2[1] * r[i][1] + h2[2] * r[i][2];
        best = best.max(dot(&tw, &a1[i]).abs() - h1[i] - rb);
    }
    for j in 0..3 {
        let ra = h1[0] * r[0][j] + h1[1] * r[1][j] + h1[2] * r[2][j];
        best = best.max(dot(&tw, &a2[j]).abs() - ra - h2[j]);
    }
    best
}

/// True only when `x` and `y` certainly come closer than `d` metres: exact for every pair but
/// two boxes, which count only when they overlap and `d` is positive (beyond 1 µm).
pub fn within(x: &Shape, y: &Shape, d: f64) -> bool {
    use Shape::*;
    match (x, y) {
        (
            Capsule { a, b, radius },
            Capsule {
                a: c,
                b: e,
                radius: r2,
            },
        ) => {
            let t = radius + r2 + d;
            t > 0.0 && segment_segment_dist2(a, b, c, e) < t * t
        }
        (Capsule { a, b, radius }, Box { center, axes, half })
        | (Box { center, axes, half }, Capsule { a, b, radius }) => {
            let t = radius + d;
            t > 0.0 && segment_box_dist2(a, b, center, axes, half) < t * t
        }
        (
            Box {
                center: c1,
                axes: a1,
                half: h1,
            },
            Box {
                center: c2,
                axes: a2,
                half: h2,
            },
        ) => d > 1e-6 && boxes_overlap(c1, a1, h1, c2, a2, h2),
        (Capsule { .. } | Box { .. }, HalfSpace { .. }) | (HalfSpace { .. }, Capsule { .. } | Box { .. }) => {
            // The nearness test of a half-space is exact.
            near(x, y, d)
        }
        (HalfSpace { .. }, HalfSpace { .. }) => false,
    }
}

/// Squared distance between segments `p1`–`q1` and `p2`–`q2` (Ericson, *Real-Time Collision
/// Detection*, 5.1.9), metres².
pub fn segment_segment_dist2(p1: &V3, q1: &V3, p2: &V3, q2: &V3) -> f64 {
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

/// Squared distance from local point `x` to the box `|x_i| ≤ h_i`.
#[inline]
fn point_box_dist2(x: &V3, h: &V3) -> f64 {
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
fn piece_minimum(a: &V3, d: &V3, half: &V3, m: &V3) -> (f64, f64) {
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
pub fn segment_box_dist2(p: &V3, q: &V3, center: &V3, axes: &[V3; 3], half: &V3) -> f64 {
    let rp = sub(p, center);
    let rq = sub(q, center);
    let a = [dot(&axes[0], &rp), dot(&axes[1], &rp), dot(&axes[2], &rp)];
    let b = [dot(&axes[0], &rq), dot(&axes[1], &rq), dot(&axes[2], &rq)];
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
    let at = |t: f64| [a[0] + d[0] * t, a[1] + d[1] * t, a[2] + d[2] * t];
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

/// True when two oriented boxes overlap (the separating axis test over the 15 candidate axes;
/// Ericson 4.4.1). Touching counts as overlapping; near-parallel edge axes are treated
/// conservatively (an epsilon added to the projections).
pub fn boxes_overlap(c1: &V3, a1: &[V3; 3], h1: &V3, c2: &V3, a2: &[V3; 3], h2: &V3) -> bool {
    const EPS: f64 = 1e-9;
    let mut r = [[0.0; 3]; 3];
    let mut abs_r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = dot(&a1[i], &a2[j]);
            abs_r[i][j] = r[i][j].abs() + EPS;
        }
    }
    let tw = sub(c2, c1);
    let t = [dot(&tw, &a1[0]), dot(&tw, &a1[1]), dot(&tw, &a1[2])];
    for i in 0..3 {
        let ra = h1[i];
        let rb = h2[0] * abs_r[i][0] + h2[1] * abs_r[i][1] + h2[2] * abs_r[i][2];
        if t[i].abs() > ra + rb {
            return false;
        }
    }
    for j in 0..3 {
        let ra = h1[0] * abs_r[0][j] + h1[1] * abs_r[1][j] + h1[2] * abs_r[2][j];
        let rb = h2[j];
        let tj = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
        if tj.abs() > ra + rb {
            return false;
        }
    }
    for i in 0..3 {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        for j in 0..3 {
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            let ra = h1[i1] * abs_r[i2][j] + h1[i2] * abs_r[i1][j];
            let rb = h2[j1] * abs_r[i][j2] + h2[j2] * abs_r[i][j1];
            let tl = (t[i2] * r[i1][j] - t[i1] * r[i2][j]).abs();
            if tl > ra + rb {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const I: [V3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    fn rot(r: &mut ChaCha8Rng) -> [V3; 3] {
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
        ));
        let m = q.to_rotation_matrix();
        let m = m.matrix();
        [
            [m[(0, 0)], m[(1, 0)], m[(2, 0)]],
            [m[(0, 1)], m[(1, 1)], m[(2, 1)]],
            [m[(0, 2)], m[(1, 2)], m[(2, 2)]],
        ]
    }

    fn v(r: &mut ChaCha8Rng, s: f64) -> V3 {
        [
            r.random_range(-s..s),
            r.random_range(-s..s),
            r.random_range(-s..s),
        ]
    }

    /// Points of a box, dense on its surface.
    fn box_points(c: &V3, axes: &[V3; 3], h: &V3) -> Vec<V3> {
        let mut out = Vec::new();
        let n = 6;
        for i in 0..=n {
            for j in 0..=n {
                for k in 0..=n {
                    let s = [
                        -h[0] + 2.0 * h[0] * i as f64 / n as f64,
                        -h[1] + 2.0 * h[1] * j as f64 / n as f64,
                        -h[2] + 2.0 * h[2] * k as f64 / n as f64,
                    ];
                    let mut p = *c;
                    for a in 0..3 {
                        p = axpy(s[a], &axes[a], &p);
                    }
                    out.push(p);
                }
            }
        }
        out
    }

    /// A seeded oriented box: axes, half extents 1–20 cm, centre within 10 cm of the origin.
    fn random_box(r: &mut ChaCha8Rng) -> ([V3; 3], V3, V3) {
        let axes = rot(r);
        let h = [
            r.random_range(0.01..0.2),
            r.random_range(0.01..0.2),
            r.random_range(0.01..0.2),
        ];
        (axes, h, v(r, 0.1))
    }

    #[test]
    fn segment_box_distance_is_exact_against_dense_sampling() {
        let mut r = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..300 {
            let (axes, h, c) = random_box(&mut r);
            let p = v(&mut r, 0.4);
            let q = v(&mut r, 0.4);
            let exact = segment_box_dist2(&p, &q, &c, &axes, &h).sqrt();
            // Sampled: points along the segment against the box (local coordinates).
            let mut sampled = f64::INFINITY;
            for k in 0..=2000 {
                let x = axpy(k as f64 / 2000.0, &sub(&q, &p), &p);
                let rx = sub(&x, &c);
                let l = [dot(&axes[0], &rx), dot(&axes[1], &rx), dot(&axes[2], &rx)];
                sampled = sampled.min(point_box_dist2(&l, &h).sqrt());
            }
            assert!(exact <= sampled + 1e-12, "{exact} > {sampled}");
            assert!(sampled - exact < 1e-3, "{exact} vs {sampled}");
        }
    }

    /// The squared segment–box distance as the least of every piece's minimum (closed form)
    /// and both ends: the walk's reference, without its early stop.
    fn every_piece(p: &V3, q: &V3, center: &V3, axes: &[V3; 3], half: &V3) -> f64 {
        let (rp, rq) = (sub(p, center), sub(q, center));
        let a = [dot(&axes[0], &rp), dot(&axes[1], &rp), dot(&axes[2], &rp)];
        let b = [dot(&axes[0], &rq), dot(&axes[1], &rq), dot(&axes[2], &rq)];
        let d = sub(&b, &a);
        let mut ts = vec![0.0, 1.0];
        for i in 0..3 {
            if d[i] != 0.0 {
                for s in [-half[i], half[i]] {
                    let t = (s - a[i]) / d[i];
                    if t > 0.0 && t < 1.0 {
                        ts.push(t);
                    }
                }
            }
        }
        ts.sort_by(f64::total_cmp);
        let at = |t: f64| [a[0] + d[0] * t, a[1] + d[1] * t, a[2] + d[2] * t];
        let mut best = point_box_dist2(&a, half).min(point_box_dist2(&b, half));
        for w in ts.windows(2) {
            let (t0, t1) = (w[0], w[1]);
            if t1 <= t0 {
                continue;
            }
            let (num, den) = piece_minimum(&a, &d, half, &at(0.5 * (t0 + t1)));
            let t = if den > 0.0 { (num / den).clamp(t0, t1) } else { t0 };
            best = best.min(point_box_dist2(&at(t), half));
        }
        best
    }

    #[test]
    fn the_segment_box_walk_stops_at_the_global_minimum() {
        // Segments through, along and beside boxes, some parallel to a face (flat pieces).
        let mut r = ChaCha8Rng::seed_from_u64(9);
        let mut flat = 0;
        for k in 0..2000 {
            let (axes, h, c) = random_box(&mut r);
            let p = v(&mut r, 0.4);
            let mut q = v(&mut r, 0.4);
            if k % 4 == 0 {
                // Parallel to the box's first face: the same first local coordinate.
                let along = dot(&axes[0], &sub(&q, &p));
                q = axpy(-along, &axes[0], &q);
                flat += 1;
            }
            let walked = segment_box_dist2(&p, &q, &c, &axes, &h);
            let reference = every_piece(&p, &q, &c, &axes, &h);
            assert!(
                (walked - reference).abs() <= 1e-15,
                "{walked} against {reference}"
            );
        }
        assert_eq!(flat, 500);
    }

    #[test]
    fn the_quick_capsule_box_bound_never_exceeds_the_clearance() {
        // Capsules through, beside and far from boxes: `beyond` only says "farther than d"
        // where the exact clearance is, and it says so for most pairs well apart.
        let mut r = ChaCha8Rng::seed_from_u64(10);
        let (mut said, mut apart) = (0, 0);
        for _ in 0..4000 {
            let (axes, half, center) = random_box(&mut r);
            let capsule = Shape::Capsule {
                a: v(&mut r, 0.5),
                b: v(&mut r, 0.5),
                radius: r.random_range(0.0..0.05),
            };
            let boxed = Shape::Box { center, axes, half };
            let c = clearance(&capsule, &boxed);
            let d = r.random_range(0.0..0.1);
            for (x, y) in [(&capsule, &boxed), (&boxed, &capsule)] {
                if beyond(x, y, d) {
                    assert!(c > d, "beyond {d} m but {c} m apart: {capsule:?} {boxed:?}");
                    said += 1;
                }
            }
            apart += usize::from(c > d + 0.1);
        }
        assert!(apart > 200 && said > apart, "{said} {apart}");
        // Other pairs: no quick bound.
        let ball = Shape::Capsule {
            a: [0.0; 3],
            b: [0.0; 3],
            radius: 0.01,
        };
        let far = Shape::Capsule {
            a: [5.0, 0.0, 0.0],
            b: [5.0, 0.0, 0.0],
            radius: 0.01,
        };
        assert!(!beyond(&ball, &far, 0.0));
    }

    #[test]
    fn segment_distance_never_exceeds_sampled_distance() {
        let mut r = ChaCha8Rng::seed_from_u64(8);
        for _ in 0..300 {
            let (p1, q1, p2, q2) = (v(&mut r, 0.3), v(&mut r, 0.3), v(&mut r, 0.3), v(&mut r, 0.3));
            let exact = segment_segment_dist2(&p1, &q1, &p2, &q2).sqrt();
            let mut sampled = f64::INFINITY;
            for i in 0..=200 {
                let x = axpy(i as f64 / 200.0, &sub(&q1, &p1), &p1);
                for j in 0..=200 {
                    let y = axpy(j as f64 / 200.0, &sub(&q2, &p2), &p2);
                    let w = sub(&x, &y);
                    sampled = sampled.min(dot(&w, &w).sqrt());
                }
            }
            assert!(exact <= sampled + 1e-12, "{exact} > {sampled}");
            assert!(sampled - exact < 5e-3, "{exact} vs {sampled}");
        }
    }

    #[test]
    fn boxes_that_share_a_point_overlap_and_separated_ones_do_not() {
        let mut r = ChaCha8Rng::seed_from_u64(9);
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..400 {
            let (a1, a2) = (rot(&mut r), rot(&mut r));
            let h1 = [
                r.random_range(0.02..0.1),
                r.random_range(0.02..0.1),
                r.random_range(0.02..0.1),
            ];
            let h2 = [
                r.random_range(0.02..0.1),
                r.random_range(0.02..0.1),
                r.random_range(0.02..0.1),
            ];
            let (c1, c2) = (v(&mut r, 0.1), v(&mut r, 0.1));
            // A point of box 2 inside box 1 proves overlap.
            let inside = box_points(&c2, &a2, &h2).iter().any(|p| {
                let d = sub(p, &c1);
                (0..3).all(|i| dot(&a1[i], &d).abs() <= h1[i])
            });
            let overlap = boxes_overlap(&c1, &a1, &h1, &c2, &a2, &h2);
            if inside {
                assert!(overlap);
                hits += 1;
            }
            // Far apart (bounding spheres disjoint): never an overlap.
            let far =
                dot(&sub(&c1, &c2), &sub(&c1, &c2)).sqrt() > dot(&h1, &h1).sqrt() + dot(&h2, &h2).sqrt();
            if far {
                assert!(!overlap);
                misses += 1;
            }
        }
        assert!(hits > 50 && misses > 10, "{hits} {misses}");
    }

    #[test]
    fn near_inflates_by_the_gap() {
        let cap = Shape::Capsule {
            a: [0.0, 0.0, 0.1],
            b: [0.0, 0.0, 0.3],
            radius: 0.05,
        };
        let floor = Shape::HalfSpace {
            normal: [0.0, 0.0, 1.0],
            offset: 0.0,
        };
        assert!(!near(&cap, &floor, 0.04));
        assert!(near(&cap, &floor, 0.051));
        let block = Shape::Box {
            center: [0.2, 0.0, 0.2],
            axes: I,
            half: [0.05; 3],
        };
        // Capsule surface at x = 0.05, box face at x = 0.15: 10 cm apart.
        assert!(!near(&cap, &block, 0.099));
        assert!(near(&cap, &block, 0.101));
        let pad = Shape::Box {
            center: [0.0, 0.0, 0.2],
            axes: I,
            half: [0.05; 3],
        };
        assert!(!near(&pad, &block, 0.099));
        assert!(near(&pad, &block, 0.101));
        assert!(!near(&block, &floor, 0.149));
        assert!(near(&block, &floor, 0.151));
        // `within` is exact where it answers.
        assert!(within(&cap, &block, 0.101) && !within(&cap, &block, 0.099));
        assert!(within(&cap, &floor, 0.051) && !within(&cap, &floor, 0.049));
        assert!(!within(&pad, &block, 0.101), "two boxes apart: no answer");
        let inside = Shape::Box {
            center: [0.21, 0.0, 0.2],
            axes: I,
            half: [0.05; 3],
        };
        assert!(within(&inside, &block, 0.001) && !within(&inside, &block, 0.0));
    }

    /// Points of a shape for sampling distances: a box's dense lattice, a capsule's axis points
    /// pushed out by its radius towards `towards` (its nearest surface to that point lies on one).
    fn sampled_distance(x: &Shape, y: &Shape) -> f64 {
        let points = |s: &Shape| -> Vec<V3> {
            match s {
                Shape::Box { center, axes, half } => box_points(center, axes, half),
                Shape::Capsule { a, b, .. } => {
                    (0..=200).map(|k| axpy(k as f64 / 200.0, &sub(b, a), a)).collect()
                }
                Shape::HalfSpace { .. } => unreachable!("sampled against solids only"),
            }
        };
        let radius = |s: &Shape| match s {
            Shape::Capsule { radius, .. } => *radius,
            _ => 0.0,
        };
        let (px, py) = (points(x), points(y));
        let mut best = f64::INFINITY;
        for p in &px {
            for q in &py {
                let w = sub(p, q);
                best = best.min(dot(&w, &w).sqrt());
            }
        }
        best - radius(x) - radius(y)
    }

    #[test]
    fn clearance_never_exceeds_the_sampled_distance_and_is_exact_where_documented() {
        let mut r = ChaCha8Rng::seed_from_u64(10);
        let shape = |r: &mut ChaCha8Rng, boxy: bool| {
            if boxy {
                Shape::Box {
                    center: v(r, 0.15),
                    axes: rot(r),
                    half: [
                        r.random_range(0.01..0.08),
                        r.random_range(0.01..0.08),
                        r.random_range(0.01..0.08),
                    ],
                }
            } else {
                Shape::Capsule {
                    a: v(r, 0.15),
                    b: v(r, 0.15),
                    radius: r.random_range(0.005..0.05),
                }
            }
        };
        let (mut apart, mut tight) = (0, 0);
        for k in 0..240 {
            let (x, y) = (shape(&mut r, k % 3 != 0), shape(&mut r, k % 2 == 0));
            let c = clearance(&x, &y);
            let sampled = sampled_distance(&x, &y);
            assert!(c >= 0.0);
            // The lattice of a box misses its nearest point by at most a cell's half diagonal.
            assert!(c <= sampled.max(0.0) + 1e-9, "{x:?} {y:?}: {c} > {sampled}");
            // Consistent with the nearness test: a pair kept apart by more than the gap is not
            // near (two boxes excepted: their nearness test inflates a box along its axes,
            // which may call a pair near that this bound keeps apart).
            let boxes = matches!((x, y), (Shape::Box { .. }, Shape::Box { .. }));
            for gap in [0.0, 0.005, 0.02] {
                if c > gap && !boxes {
                    assert!(!near(&x, &y, gap), "{x:?} {y:?}: clearance {c}, near at {gap}");
                }
            }
            if c > 0.0 {
                apart += 1;
                if !boxes && sampled - c < 0.02 {
                    tight += 1;
                }
            }
        }
        assert!(apart > 60 && tight > 20, "{apart} {tight}");
        let floor = Shape::HalfSpace {
            normal: [0.0, 0.0, 1.0],
            offset: 0.0,
        };
        let cube = Shape::Box {
            center: [0.3, 0.0, 0.07],
            axes: I,
            half: [0.02; 3],
        };
        assert!((clearance(&cube, &floor) - 0.05).abs() < 1e-12);
        let far = Shape::Box {
            center: [0.5, 0.0, 0.07],
            axes: I,
            half: [0.02; 3],
        };
        assert!((clearance(&cube, &far) - 0.16).abs() < 1e-12);
        assert_eq!(clearance(&floor, &floor), 0.0);
    }
}
