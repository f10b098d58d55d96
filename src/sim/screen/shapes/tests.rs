//! The primitives' distances against dense sampling.

use super::boxes::boxes_overlap;
use super::segment_box::{piece_minimum, point_box_dist2};
use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn near(x: &Shape, y: &Shape, gap: f64) -> bool {
    separation(x, y).near(gap)
}

fn within(x: &Shape, y: &Shape, d: f64) -> bool {
    separation(x, y).within(d)
}

fn clearance(x: &Shape, y: &Shape) -> f64 {
    separation(x, y).clearance()
}

fn beyond(x: &Shape, y: &Shape, d: f64) -> bool {
    surely_beyond(x, y, d)
}

const I: [V3; 3] = [
    V3::new(1.0, 0.0, 0.0),
    V3::new(0.0, 1.0, 0.0),
    V3::new(0.0, 0.0, 1.0),
];

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
        V3::new(m[(0, 0)], m[(1, 0)], m[(2, 0)]),
        V3::new(m[(0, 1)], m[(1, 1)], m[(2, 1)]),
        V3::new(m[(0, 2)], m[(1, 2)], m[(2, 2)]),
    ]
}

fn v(r: &mut ChaCha8Rng, s: f64) -> V3 {
    V3::new(
        r.random_range(-s..s),
        r.random_range(-s..s),
        r.random_range(-s..s),
    )
}

/// Points of a box, dense on its surface.
fn box_points(c: &V3, axes: &[V3; 3], h: &V3) -> Vec<V3> {
    let mut out = Vec::new();
    let n = 6;
    for i in 0..=n {
        for j in 0..=n {
            for k in 0..=n {
                let s = V3::new(
                    -h[0] + 2.0 * h[0] * i as f64 / n as f64,
                    -h[1] + 2.0 * h[1] * j as f64 / n as f64,
                    -h[2] + 2.0 * h[2] * k as f64 / n as f64,
                );
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
    let h = V3::new(
        r.random_range(0.01..0.2),
        r.random_range(0.01..0.2),
        r.random_range(0.01..0.2),
    );
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
            let l = V3::new(dot(&axes[0], &rx), dot(&axes[1], &rx), dot(&axes[2], &rx));
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
    let a = V3::new(dot(&axes[0], &rp), dot(&axes[1], &rp), dot(&axes[2], &rp));
    let b = V3::new(dot(&axes[0], &rq), dot(&axes[1], &rq), dot(&axes[2], &rq));
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
    let at = |t: f64| V3::new(a[0] + d[0] * t, a[1] + d[1] * t, a[2] + d[2] * t);
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
        a: V3::repeat(0.0),
        b: V3::repeat(0.0),
        radius: 0.01,
    };
    let far = Shape::Capsule {
        a: V3::new(5.0, 0.0, 0.0),
        b: V3::new(5.0, 0.0, 0.0),
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
        let h1 = V3::new(
            r.random_range(0.02..0.1),
            r.random_range(0.02..0.1),
            r.random_range(0.02..0.1),
        );
        let h2 = V3::new(
            r.random_range(0.02..0.1),
            r.random_range(0.02..0.1),
            r.random_range(0.02..0.1),
        );
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
        let far = dot(&sub(&c1, &c2), &sub(&c1, &c2)).sqrt() > dot(&h1, &h1).sqrt() + dot(&h2, &h2).sqrt();
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
        a: V3::new(0.0, 0.0, 0.1),
        b: V3::new(0.0, 0.0, 0.3),
        radius: 0.05,
    };
    let floor = Shape::HalfSpace {
        normal: V3::new(0.0, 0.0, 1.0),
        offset: 0.0,
    };
    assert!(!near(&cap, &floor, 0.04));
    assert!(near(&cap, &floor, 0.051));
    let block = Shape::Box {
        center: V3::new(0.2, 0.0, 0.2),
        axes: I,
        half: V3::repeat(0.05),
    };
    // Capsule surface at x = 0.05, box face at x = 0.15: 10 cm apart.
    assert!(!near(&cap, &block, 0.099));
    assert!(near(&cap, &block, 0.101));
    let pad = Shape::Box {
        center: V3::new(0.0, 0.0, 0.2),
        axes: I,
        half: V3::repeat(0.05),
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
        center: V3::new(0.21, 0.0, 0.2),
        axes: I,
        half: V3::repeat(0.05),
    };
    assert!(within(&inside, &block, 0.001) && !within(&inside, &block, 0.0));
}

/// Points of a shape for sampling distances: a box's dense lattice, a capsule's axis points
/// pushed out by its radius towards `towards` (its nearest surface to that point lies on one).
fn sampled_distance(x: &Shape, y: &Shape) -> f64 {
    let points = |s: &Shape| -> Vec<V3> {
        match s {
            Shape::Box { center, axes, half } => box_points(center, axes, half),
            Shape::Capsule { a, b, .. } => (0..=200).map(|k| axpy(k as f64 / 200.0, &sub(b, a), a)).collect(),
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
                half: V3::new(
                    r.random_range(0.01..0.08),
                    r.random_range(0.01..0.08),
                    r.random_range(0.01..0.08),
                ),
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
        normal: V3::new(0.0, 0.0, 1.0),
        offset: 0.0,
    };
    let cube = Shape::Box {
        center: V3::new(0.3, 0.0, 0.07),
        axes: I,
        half: V3::repeat(0.02),
    };
    assert!((clearance(&cube, &floor) - 0.05).abs() < 1e-12);
    let far = Shape::Box {
        center: V3::new(0.5, 0.0, 0.07),
        axes: I,
        half: V3::repeat(0.02),
    };
    assert!((clearance(&cube, &far) - 0.16).abs() < 1e-12);
    assert_eq!(clearance(&floor, &floor), 0.0);
}
