//! The arm's own pairs that keep their gap at any angles of the joints between their links:
//! a bound through the joint axes, so such pairs are never tested.

use nalgebra::Vector3;

use super::posed::MovingShape;
use super::shapes::{Shape, V3, segment_box_dist2, segment_segment_dist2};
use crate::sim::chain::{ArmChain, Frame, JointAxis};

/// Where a shape lies about an axis: the range of its points' heights along the axis and the
/// range of their distances from it (metres).
#[derive(Clone, Copy, Debug)]
pub(super) struct AxialPlace {
    /// Least and largest height along the axis, metres.
    heights: [f64; 2],
    /// Least and largest distance from the axis, metres.
    radii: [f64; 2],
}

/// Where a moving shape lies about its own link's joint axis, and about the next link's (`None`
/// past the last link).
#[derive(Clone, Copy, Debug)]
pub(super) struct Places {
    own: AxialPlace,
    next: Option<AxialPlace>,
}

/// Where `shape` (world frame, metres) lies about the axis through `o` along the unit `u`.
fn about_axis(shape: &Shape, o: &Vector3<f64>, u: &Vector3<f64>) -> AxialPlace {
    let height = |p: &V3| (p - o).dot(u);
    let off = |p: &V3| {
        let d = p - o;
        (d - u * d.dot(u)).norm()
    };
    // The axis as a segment far longer than the cell, for the distance from the line.
    let (l0, l1) = (o - u * 100.0, o + u * 100.0);
    match shape {
        Shape::Capsule { a, b, radius } => {
            let (ha, hb) = (height(a), height(b));
            let near = segment_segment_dist2(a, b, &l0, &l1).sqrt();
            AxialPlace {
                heights: [ha.min(hb) - radius, ha.max(hb) + radius],
                radii: [(near - radius).max(0.0), off(a).max(off(b)) + radius],
            }
        }
        Shape::Box { center, axes, half } => {
            let (mut h, mut r) = ([f64::INFINITY, f64::NEG_INFINITY], 0.0f64);
            for k in 0..8 {
                let s = |i: usize| if k >> i & 1 == 0 { -half[i] } else { half[i] };
                let c =
                    V3::from_fn(|x, _| center[x] + axes[0][x] * s(0) + axes[1][x] * s(1) + axes[2][x] * s(2));
                h = [h[0].min(height(&c)), h[1].max(height(&c))];
                r = r.max(off(&c));
            }
            let near = segment_box_dist2(&l0, &l1, center, axes, half).sqrt();
            AxialPlace {
                heights: h,
                radii: [near, r],
            }
        }
        Shape::HalfSpace { .. } => AxialPlace {
            heights: [f64::NEG_INFINITY, f64::INFINITY],
            radii: [0.0, f64::INFINITY],
        },
    }
}

/// The gap between two ranges, 0 where they overlap.
fn range_gap(x: [f64; 2], y: [f64; 2]) -> f64 {
    (x[0] - y[1]).max(y[0] - x[1]).max(0.0)
}

/// The [`Places`] of moving shape `m` at the link frames `frames`.
pub(super) fn axial_places(chain: &ArmChain, frames: &[Frame; 6], m: &MovingShape) -> Places {
    let shape = m.pose(frames).shape;
    let about = |j: usize| {
        let axis = chain.joint_axis(frames, j);
        about_axis(&shape, &axis.point, &axis.direction)
    };
    Places {
        own: about(m.link),
        next: (m.link + 1 < 6).then(|| about(m.link + 1)),
    }
}

/// A lower bound on the distance between a moving shape of link `near.0` and one of link
/// `far.0` (metres; their [`Places`] at the link frames `frames`) at any angles of the joints
/// between the links (`−∞` for two shapes of one link). The farther shape turns about the next
/// joint's axis, which is fixed to the nearer link: heights along that axis and distances from
/// it do not change, and two points are at least as far apart as those differ (the axial and
/// radial parts of their offset). Across more joints the farther shape, turned about the last
/// axis, stays within a ball about a point of that axis, and the ball turns about the axis
/// before.
pub(super) fn turned_apart(
    chain: &ArmChain,
    frames: &[Frame; 6],
    near: (usize, &Places),
    far: (usize, &Places),
) -> f64 {
    let (near, far) = if near.0 < far.0 { (near, far) } else { (far, near) };
    let Some(nearer) = near.1.next.filter(|_| far.0 > near.0) else {
        return f64::NEG_INFINITY;
    };
    let AxialPlace {
        heights: mut h,
        radii: mut r,
    } = far.1.own;
    // Joint by joint towards the nearer link: the ball about the last axis's point at
    // mid-height holds every turn of what lies beyond it, and turns about the axis before.
    for j in (near.0 + 1..far.0).rev() {
        let JointAxis {
            point: o,
            direction: u,
        } = chain.joint_axis(frames, j + 1);
        let centre = o + u * ((h[0] + h[1]) / 2.0);
        let radius = ((h[1] - h[0]) / 2.0).hypot(r[1]);
        let JointAxis {
            point: o,
            direction: u,
        } = chain.joint_axis(frames, j);
        let d = centre - o;
        let (hc, rc) = (d.dot(&u), (d - u * d.dot(&u)).norm());
        h = [hc - radius, hc + radius];
        r = [(rc - radius).max(0.0), rc + radius];
    }
    range_gap(h, nearer.heights).hypot(range_gap(r, nearer.radii))
}
