//! A capsule around an arm link's shapes: tighter than its sphere around a long link (the
//! forearm) or the gripper.

use nalgebra::Vector3;

use super::local::Local;

/// A capsule (in the link's frame, metres) containing every one of `shapes`, `None` when there
/// are none: its axis along whichever of the frame's three
/// axes and the direction between the two farthest shape centres gives the least volume, through
/// the shapes' mean point, from the least to the largest projection of a shape's point on it; its
/// radius the largest distance of a shape from that line. Every point of a capsule or a box lies
/// within its ends' (corners') largest distance from the axis segment, plus the capsule's radius
/// (the distance to a segment is convex), and every such point projects inside the segment.
pub(super) fn link_capsule<'a>(shapes: impl Iterator<Item = &'a Local>) -> Option<Local> {
    // Each shape's extreme points, with how far the shape reaches beyond them.
    let mut points: Vec<(Vector3<f64>, f64)> = Vec::new();
    let mut centres: Vec<Vector3<f64>> = Vec::new();
    for l in shapes {
        match l {
            Local::Capsule { a, b, radius } => {
                points.extend([(*a, *radius), (*b, *radius)]);
                centres.push((a + b) / 2.0);
            }
            Local::Box { center, axes, half } => {
                centres.push(*center);
                for k in 0..8 {
                    let s = |i: usize| if k >> i & 1 == 0 { -half[i] } else { half[i] };
                    points.push((center + axes * Vector3::new(s(0), s(1), s(2)), 0.0));
                }
            }
        }
    }
    if points.is_empty() {
        return None;
    }
    let mean = points.iter().map(|p| p.0).sum::<Vector3<f64>>() / points.len() as f64;
    let mut far = (0.0, Vector3::x());
    for (i, p) in centres.iter().enumerate() {
        for r in &centres[i + 1..] {
            let d = (r - p).norm();
            if d > far.0 {
                far = (d, (r - p) / d);
            }
        }
    }
    let mut best: Option<(f64, Vector3<f64>, Vector3<f64>, f64)> = None;
    for u in [Vector3::x(), Vector3::y(), Vector3::z(), far.1] {
        let (mut lo, mut hi, mut radius) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for (p, extra) in &points {
            let t = (p - mean).dot(&u);
            lo = lo.min(t);
            hi = hi.max(t);
            radius = radius.max((p - mean - u * t).norm() + extra);
        }
        let volume = std::f64::consts::PI * radius * radius * (hi - lo + 4.0 / 3.0 * radius);
        if best.is_none_or(|b| volume < b.0) {
            best = Some((volume, mean + u * lo, mean + u * hi, radius));
        }
    }
    best.map(|(_, a, b, radius)| Local::Capsule { a, b, radius })
}
