//! [`Screen`]: a conservative fast collision model of the cell, asked before MuJoCo
//! ([`SceneChecker::certainly_free`](super::collision::SceneChecker)).
//!
//! Each collidable geom is bounded by one convex primitive ([`Shape`]): capsules and spheres
//! exactly, a cylinder by the capsule of its radius and half-height, a box exactly, a plane as
//! its half-space, and a mesh or an ellipsoid by MuJoCo's bounding box of it (`geom_aabb`, which
//! contains its convex hull, what MuJoCo collides). Robot geoms are fixed in the frame of the
//! arm link that moves them (the gripper at its snapshot opening, a held block in the wrist-3
//! frame); the six link frames are computed from the model's own body offsets and joint axes
//! (the same products as `mj_kinematics`). The pairs tested are exactly the pairs MuJoCo tests
//! in the checker's private model: its contact bitmasks, its body filters (same weld body,
//! weld parent and child unless disabled, `<exclude>`), plus explicit `<pair>`s. A configuration
//! is certainly free when every pair's primitives are at least the pair's margin plus
//! [`PAD`] apart: the geoms inside them are then farther apart than the margin, so MuJoCo
//! reports no contact. `tests/physics/motion_screen.rs` checks this against MuJoCo over thousands of
//! configurations near obstacles.

use mujoco_rs::prelude::*;
use nalgebra::{Matrix3, Vector3};

use super::chain::{ArmChain, Frame, Link, mat};
use super::pair_filter::PairFilter;
use crate::motion::plan::JointSpare;
use crate::motion::plan::config::UR5E_LEVER_ARMS;
use crate::motion::plan::shapes::{
    Shape, V3, apart, beyond, clearance, near, segment_box_dist2, segment_segment_dist2, within,
};

/// Extra distance every pair must keep beyond its margin for the screen to vouch, metres: room
/// for MuJoCo's own tolerances (its convex-hull distances converge to about 1e-6 m).
pub const PAD: f64 = 5e-4;

/// A primitive in a body frame.
#[derive(Clone, Copy, Debug)]
enum Local {
    Capsule {
        a: Vector3<f64>,
        b: Vector3<f64>,
        radius: f64,
    },
    Box {
        center: Vector3<f64>,
        axes: Matrix3<f64>,
        half: V3,
    },
}

impl Local {
    /// Radius of a sphere about the shape's centre that contains it, metres.
    fn reach(&self) -> f64 {
        match self {
            Local::Capsule { a, b, radius } => (b - a).norm() / 2.0 + radius,
            Local::Box { half, .. } => (half[0] * half[0] + half[1] * half[1] + half[2] * half[2]).sqrt(),
        }
    }

    fn posed(&self, r: &Matrix3<f64>, t: &Vector3<f64>) -> Shape {
        match self {
            Local::Capsule { a, b, radius } => {
                let (a, b) = (r * a + t, r * b + t);
                Shape::Capsule {
                    a: [a.x, a.y, a.z],
                    b: [b.x, b.y, b.z],
                    radius: *radius,
                }
            }
            Local::Box { center, axes, half } => {
                let c = r * center + t;
                let m = r * axes;
                Shape::Box {
                    center: [c.x, c.y, c.z],
                    axes: [
                        [m[(0, 0)], m[(1, 0)], m[(2, 0)]],
                        [m[(0, 1)], m[(1, 1)], m[(2, 1)]],
                        [m[(0, 2)], m[(1, 2)], m[(2, 2)]],
                    ],
                    half: *half,
                }
            }
        }
    }
}

/// One pair to test: two shape indices (moving shapes first, then fixed ones), the distance
/// they must keep for "free" (the pair's margin plus [`PAD`], metres), and the distance below
/// which exact shapes are "blocked": [`PAD`] of penetration (MuJoCo reports every
/// penetration, but not every pair closer than a margin: its plane–box and capsule–box
/// contacts within a margin were found missing in `tests/physics/motion_screen.rs`).
#[derive(Clone, Copy, Debug)]
struct Pair {
    a: u16,
    b: u16,
    gap: f64,
    block: f64,
    /// The pair's lever-arm ratio ([`Screen::lever_ratio`]): its parts move relative to each
    /// other at most this fraction of the planner's lever-arm bound, so a clearance `c` beyond
    /// the gap vouches for `c / kappa` of that bound. In (0, 1].
    kappa: f64,
}

/// The conservative model of one snapshot of the cell (see the module docs).
#[derive(Clone, Debug)]
pub struct Screen {
    /// The arm's link frames at any joints.
    chain: ArmChain,
    /// Shapes moved by the arm: (link index 0..6, shape in the link's frame, whether the
    /// shape is the geom itself rather than a bound of it).
    moving: Vec<(usize, Local, bool, f64)>,
    /// Fixed shapes, world frame, with their bounding spheres and exactness.
    fixed: Vec<Posed>,
    pairs: Vec<Pair>,
    /// The pairs in groups of one arm link against one partner (a fixed shape or another
    /// link), each group tested first with bounding spheres ([`Group`]).
    groups: Vec<Group>,
    /// Bounding sphere of each link's moving shapes in the link's frame (centre, radius,
    /// metres); radius negative for a link without shapes.
    link_spheres: [(Vector3<f64>, f64); 6],
    /// A capsule around each link's moving shapes in the link's frame ([`link_capsule`]; `None`
    /// for a link without shapes): tighter than the sphere around a long link (the forearm) or
    /// the gripper, it culls a group the spheres cannot.
    link_capsules: [Option<Local>; 6],
    /// Geom id of each shape (moving ones, then fixed ones).
    geoms: Vec<usize>,
    /// The pairs the last [`Screen::free_spare`] could not decide.
    undecided: Vec<Undecided>,
    /// The moving shapes posed for the verdicts ([`Screen::free_spare`]).
    posed: Posing,
    /// Index of each geom's shape (`u32::MAX`: none), for [`Screen::geom_clearance`].
    shape_of: Vec<u32>,
    /// The moving shapes posed for [`Screen::geom_clearance`], at `bound_frames`.
    bound_posed: Posing,
    bound_frames: [Frame; 6],
}

/// Scratch of the moving shapes posed at one set of link frames, each when first needed: shape
/// `i` is posed while `stamp[i]` matches `call`.
#[derive(Clone, Debug)]
struct Posing {
    posed: Vec<Posed>,
    stamp: Vec<u32>,
    call: u32,
}

impl Posing {
    fn new(n: usize) -> Self {
        let none = (
            Shape::HalfSpace {
                normal: [0.0; 3],
                offset: 0.0,
            },
            None,
            false,
        );
        Self {
            posed: vec![none; n],
            stamp: vec![0; n],
            call: 0,
        }
    }

    /// Forgets every posed shape (new link frames).
    fn renew(&mut self) {
        self.call = self.call.wrapping_add(1);
        if self.call == 0 {
            self.stamp.iter_mut().for_each(|s| *s = u32::MAX);
            self.call = 1;
        }
    }

    /// Shape `i` (moving ones first, then `fixed`), posed by [`Posing::ensure`] if moving.
    #[inline]
    fn get<'a>(&'a self, i: usize, fixed: &'a [Posed]) -> &'a Posed {
        match self.posed.get(i) {
            Some(p) => p,
            None => &fixed[i - self.posed.len()],
        }
    }

    /// Poses moving shape `i` at `frames` unless it is posed already (`i` past the moving
    /// shapes: a fixed one, nothing to do).
    #[inline]
    fn ensure(&mut self, i: usize, moving: &[(usize, Local, bool, f64)], frames: &[Frame; 6]) {
        if i < moving.len() && self.stamp[i] != self.call {
            self.posed[i] = pose(&moving[i], frames);
            self.stamp[i] = self.call;
        }
    }
}

/// A pair whose primitives come within its margin plus [`PAD`] but that the screen cannot call
/// blocked: only the geoms' exact distance decides it ([`Screen::undecided`]).
#[derive(Clone, Copy, Debug)]
pub struct Undecided {
    /// The two geom ids.
    pub geoms: (usize, usize),
    /// The distance the geoms must keep beyond the margin for the screen's vouching, metres:
    /// the pair's margin plus [`PAD`].
    pub gap: f64,
    /// The pair's lever-arm ratio, in (0, 1].
    pub kappa: f64,
    /// The joints `lo..=hi` that move the pair's parts relative to each other (`lo > hi`:
    /// none).
    pub range: (usize, usize),
}

/// The partner of an arm link in a [`Group`].
#[derive(Clone, Copy, Debug, PartialEq)]
enum Partner {
    /// A fixed shape (index into `fixed`).
    Fixed(usize),
    /// Another arm link (0..6).
    Link(usize),
}

/// Consecutive pairs (`pairs[start..end]`) between the shapes of arm link `link` and one
/// partner. When the link's bounding sphere keeps `gap` (the largest of the pairs' gaps, metres)
/// from the partner's (a fixed shape's bounding sphere or half-space, or the other link's
/// sphere), every pair of the group does, and none needs testing.
#[derive(Clone, Copy, Debug)]
struct Group {
    link: usize,
    partner: Partner,
    gap: f64,
    /// The largest lever-arm ratio of the group's pairs.
    kappa: f64,
    start: u32,
    end: u32,
}

impl Group {
    /// The joints `lo..=hi` that move the group's pairs relative to each other: every joint up
    /// to the link against a fixed shape, those after the nearer link up to the farther one
    /// against another link (`lo > hi`: none).
    fn joints(&self) -> (usize, usize) {
        match self.partner {
            Partner::Fixed(_) => (0, self.link),
            Partner::Link(m) => (self.link.min(m) + 1, self.link.max(m)),
        }
    }
}

/// A shape in the world, its bounding sphere, and whether it is the geom itself.
type Posed = (Shape, Option<(V3, f64)>, bool);

/// The geom's bounding primitive in its own frame; `None` for a type the screen cannot bound
/// (a height field, an SDF).
fn geom_local(m: &MjModel, g: usize) -> Option<GeomShape> {
    let size = m.geom_size()[g];
    let aabb = m.geom_aabb()[g];
    Some(match m.geom_type()[g] {
        MjtGeomBase::mjGEOM_PLANE => GeomShape::Plane,
        MjtGeomBase::mjGEOM_SPHERE => GeomShape::Solid(Local::Capsule {
            a: Vector3::zeros(),
            b: Vector3::zeros(),
            radius: size[0],
        }),
        MjtGeomBase::mjGEOM_CAPSULE | MjtGeomBase::mjGEOM_CYLINDER => GeomShape::Solid(Local::Capsule {
            a: Vector3::new(0.0, 0.0, -size[1]),
            b: Vector3::new(0.0, 0.0, size[1]),
            radius: size[0],
        }),
        MjtGeomBase::mjGEOM_BOX => GeomShape::Solid(Local::Box {
            center: Vector3::zeros(),
            axes: Matrix3::identity(),
            half: size,
        }),
        MjtGeomBase::mjGEOM_MESH | MjtGeomBase::mjGEOM_ELLIPSOID => GeomShape::Solid(Local::Box {
            center: Vector3::new(aabb[0], aabb[1], aabb[2]),
            axes: Matrix3::identity(),
            half: [aabb[3], aabb[4], aabb[5]],
        }),
        _ => return None,
    })
}

enum GeomShape {
    Plane,
    Solid(Local),
}

/// True when the screen's shape of the geom is the geom itself (a sphere, capsule, box or
/// plane), not a bound of it.
fn exact(m: &MjModel, g: usize) -> bool {
    matches!(
        m.geom_type()[g],
        MjtGeomBase::mjGEOM_PLANE
            | MjtGeomBase::mjGEOM_SPHERE
            | MjtGeomBase::mjGEOM_CAPSULE
            | MjtGeomBase::mjGEOM_BOX
    )
}

/// A local shape expressed in another frame: `rel` maps the shape's frame into it.
fn moved(l: &Local, r: &Matrix3<f64>, t: &Vector3<f64>) -> Local {
    match l {
        Local::Capsule { a, b, radius } => Local::Capsule {
            a: r * a + t,
            b: r * b + t,
            radius: *radius,
        },
        Local::Box { center, axes, half } => Local::Box {
            center: r * center + t,
            axes: r * axes,
            half: *half,
        },
    }
}

/// What the screen needs of the checker that builds it.
pub(crate) struct Build<'a> {
    /// The checker's private data, posed by `mj_kinematics` (any arm joints; a held block at
    /// its pose for those joints).
    pub(crate) data: &'a MjData<Box<MjModel>>,
    /// Arm group of each geom (0 fixed, 1..=6 moved by that arm joint; a held block's geoms 6).
    pub(crate) group: &'a [u8],
    /// Body ids of the six arm links, base to wrist 3.
    pub(crate) link_bodies: [usize; 6],
    /// The six arm links as a chain (their frames at any joints).
    pub(crate) chain: &'a ArmChain,
}

/// A moving shape posed at the link frames, with its bounding sphere and exactness.
fn pose(m: &(usize, Local, bool, f64), frames: &[Frame; 6]) -> Posed {
    let (k, l, e, reach) = m;
    let (r, t) = &frames[*k];
    let s = l.posed(r, t);
    let sphere = match &s {
        Shape::Capsule { a, b, .. } => (
            [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, (a[2] + b[2]) / 2.0],
            *reach,
        ),
        Shape::Box { center, .. } => (*center, *reach),
        Shape::HalfSpace { .. } => ([0.0; 3], f64::INFINITY),
    };
    (s, Some(sphere), *e)
}

/// True when spheres `(c1, r1)` and `(c2, r2)` (metres) keep at least `gap` between them; a
/// negative radius (no shape) is always apart.
fn sphere_apart(c1: &V3, r1: f64, c2: &V3, r2: f64, gap: f64) -> bool {
    if r1 < 0.0 || r2 < 0.0 {
        return true;
    }
    let t = r1 + r2 + gap;
    let d = [c1[0] - c2[0], c1[1] - c2[1], c1[2] - c2[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2] >= t * t
}

/// True when `shape` is a box and the sphere `(c, r)` (metres) keeps at least `gap` from it
/// (the distance from the centre to the box, less the radius); false otherwise.
fn sphere_box_apart(c: &V3, r: f64, shape: &Shape, gap: f64) -> bool {
    let Some(out2) = box_dist2(c, shape) else {
        return false;
    };
    let t = r + gap;
    out2 >= t * t
}

/// The squared distance from the point `c` to `shape` if it is a box, metres².
fn box_dist2(c: &V3, shape: &Shape) -> Option<f64> {
    let Shape::Box { center, axes, half } = shape else {
        return None;
    };
    let d = [c[0] - center[0], c[1] - center[1], c[2] - center[2]];
    let mut out2 = 0.0;
    for i in 0..3 {
        let u = (d[0] * axes[i][0] + d[1] * axes[i][1] + d[2] * axes[i][2]).abs() - half[i];
        if u > 0.0 {
            out2 += u * u;
        }
    }
    Some(out2)
}

/// A lower bound on the distance between spheres `(c1, r1)` and `(c2, r2)`, metres (infinite
/// when either has no shape).
fn sphere_gap(c1: &V3, r1: f64, c2: &V3, r2: f64) -> f64 {
    if r1 < 0.0 || r2 < 0.0 {
        return f64::INFINITY;
    }
    let d = [c1[0] - c2[0], c1[1] - c2[1], c1[2] - c2[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - r1 - r2
}

/// A lower bound on the distance between the sphere `(c, r)` and a posed shape, metres: the
/// larger of the bounds through the shape's bounding sphere and, for a box or a half-space,
/// through the shape itself.
fn sphere_shape_gap(c: &V3, r: f64, shape: &Posed) -> f64 {
    if r < 0.0 {
        return f64::INFINITY;
    }
    let through_sphere = shape
        .1
        .map_or(f64::NEG_INFINITY, |(c2, r2)| sphere_gap(c, r, &c2, r2));
    let through_shape = match &shape.0 {
        Shape::HalfSpace { normal, offset } => {
            normal[0] * c[0] + normal[1] * c[1] + normal[2] * c[2] - offset - r
        }
        Shape::Box { .. } => box_dist2(c, &shape.0).map_or(f64::NEG_INFINITY, |d2| d2.sqrt() - r),
        Shape::Capsule { .. } => f64::NEG_INFINITY,
    };
    through_sphere.max(through_shape)
}

/// A sphere (centre, radius, metres) containing every one of `shapes` (each within its own
/// bounding sphere about its centre); radius −1 when there are none.
fn link_sphere<'a>(shapes: impl Iterator<Item = &'a Local> + Clone) -> (Vector3<f64>, f64) {
    let centre = |l: &Local| match l {
        Local::Capsule { a, b, .. } => (a + b) / 2.0,
        Local::Box { center, .. } => *center,
    };
    let (mut lo, mut hi) = (Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY));
    for l in shapes.clone() {
        let (c, r) = (centre(l), l.reach());
        lo = lo.inf(&(c - Vector3::repeat(r)));
        hi = hi.sup(&(c + Vector3::repeat(r)));
    }
    if !lo.x.is_finite() {
        return (Vector3::zeros(), -1.0);
    }
    let mid = (lo + hi) / 2.0;
    let r = shapes
        .map(|l| (centre(l) - mid).norm() + l.reach())
        .fold(0.0, f64::max);
    (mid, r)
}

/// Where `shape` (world frame, metres) lies about the axis through `o` along the unit `u`: the
/// ranges of its points' heights along the axis and of their distances from it (metres).
fn about_axis(shape: &Shape, o: &Vector3<f64>, u: &Vector3<f64>) -> ([f64; 2], [f64; 2]) {
    let height = |p: &V3| (Vector3::from(*p) - o).dot(u);
    let off = |p: &V3| {
        let d = Vector3::from(*p) - o;
        (d - u * d.dot(u)).norm()
    };
    // The axis as a segment far longer than the cell, for the distance from the line.
    let (l0, l1) = (o - u * 100.0, o + u * 100.0);
    let (l0, l1) = ([l0.x, l0.y, l0.z], [l1.x, l1.y, l1.z]);
    match shape {
        Shape::Capsule { a, b, radius } => {
            let (ha, hb) = (height(a), height(b));
            let near = segment_segment_dist2(a, b, &l0, &l1).sqrt();
            (
                [ha.min(hb) - radius, ha.max(hb) + radius],
                [(near - radius).max(0.0), off(a).max(off(b)) + radius],
            )
        }
        Shape::Box { center, axes, half } => {
            let (mut h, mut r) = ([f64::INFINITY, f64::NEG_INFINITY], 0.0f64);
            for k in 0..8 {
                let s = |i: usize| if k >> i & 1 == 0 { -half[i] } else { half[i] };
                let c: V3 = std::array::from_fn(|x| {
                    center[x] + axes[0][x] * s(0) + axes[1][x] * s(1) + axes[2][x] * s(2)
                });
                h = [h[0].min(height(&c)), h[1].max(height(&c))];
                r = r.max(off(&c));
            }
            let near = segment_box_dist2(&l0, &l1, center, axes, half).sqrt();
            (h, [near, r])
        }
        Shape::HalfSpace { .. } => ([f64::NEG_INFINITY, f64::INFINITY], [0.0, f64::INFINITY]),
    }
}

/// The gap between two ranges, 0 where they overlap.
fn range_gap(x: [f64; 2], y: [f64; 2]) -> f64 {
    (x[0] - y[1]).max(y[0] - x[1]).max(0.0)
}

/// Where a moving shape lies, heights along and distances from an axis ([`about_axis`]):
/// about its own link's joint axis, and about the next link's (none past the last link).
type Places = (([f64; 2], [f64; 2]), Option<([f64; 2], [f64; 2])>);

/// The [`Places`] of moving shape `m` at the link frames `frames`.
fn axial_places(chain: &ArmChain, frames: &[Frame; 6], m: &(usize, Local, bool, f64)) -> Places {
    let shape = pose(m, frames).0;
    let about = |j: usize| {
        let (o, u) = chain.joint_axis(frames, j);
        about_axis(&shape, &o, &u)
    };
    (about(m.0), (m.0 + 1 < 6).then(|| about(m.0 + 1)))
}

/// A lower bound on the distance between a moving shape of link `near.0` and one of link
/// `far.0` (metres; their [`Places`] at the link frames `frames`) at any angles of the joints
/// between the links (`−∞` for two shapes of one link). The farther shape turns about the next
/// joint's axis, which is fixed to the nearer link: heights along that axis and distances from
/// it do not change, and two points are at least as far apart as those differ (the axial and
/// radial parts of their offset). Across more joints the farther shape, turned about the last
/// axis, stays within a ball about a point of that axis, and the ball turns about the axis
/// before.
fn turned_apart(chain: &ArmChain, frames: &[Frame; 6], near: (usize, &Places), far: (usize, &Places)) -> f64 {
    let (near, far) = if near.0 < far.0 { (near, far) } else { (far, near) };
    let Some((nh, nr)) = near.1.1.filter(|_| far.0 > near.0) else {
        return f64::NEG_INFINITY;
    };
    let (mut h, mut r) = far.1.0;
    // Joint by joint towards the nearer link: the ball about the last axis's point at
    // mid-height holds every turn of what lies beyond it, and turns about the axis before.
    for j in (near.0 + 1..far.0).rev() {
        let (o, u) = chain.joint_axis(frames, j + 1);
        let centre = o + u * ((h[0] + h[1]) / 2.0);
        let radius = ((h[1] - h[0]) / 2.0).hypot(r[1]);
        let (o, u) = chain.joint_axis(frames, j);
        let d = centre - o;
        let (hc, rc) = (d.dot(&u), (d - u * d.dot(&u)).norm());
        h = [hc - radius, hc + radius];
        r = [(rc - radius).max(0.0), rc + radius];
    }
    range_gap(h, nh).hypot(range_gap(r, nr))
}

/// A capsule (in the link's frame, metres) containing every one of `shapes`, `None` when there
/// are none: its axis along whichever of the frame's three
/// axes and the direction between the two farthest shape centres gives the least volume, through
/// the shapes' mean point, from the least to the largest projection of a shape's point on it; its
/// radius the largest distance of a shape from that line. Every point of a capsule or a box lies
/// within its ends' (corners') largest distance from the axis segment, plus the capsule's radius
/// (the distance to a segment is convex), and every such point projects inside the segment.
fn link_capsule<'a>(shapes: impl Iterator<Item = &'a Local>) -> Option<Local> {
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

/// The lever-arm ratio of the pair of shapes `a` (moving) and `b` (moving or fixed, index past
/// `moving`): the largest, over the joints that move the two relative to each other, of how far
/// the distal shape's points can lie from the joint's axis over the planner's lever arm for
/// that joint ([`UR5E_LEVER_ARMS`], an upper bound for the whole moving robot and a held
/// block), at most 1.
///
/// Joint `j` moves the distal shape's points by at most their distance from its axis times the
/// angle, and that distance is bounded through the chain, whatever the joints between: the
/// shape lies within its reach of its centre in its link's frame, each link's origin within
/// `|pos| + 2 |anchor|` of its parent's (the body offset, and the rotation about the anchor),
/// and joint `j`'s axis passes within `|anchor_j|` of link `j`'s origin. A short chain (the
/// forearm against wrist 2) then moves far less than the whole arm's lever arm allows, and a
/// clearance vouches for proportionally more.
fn lever_ratio(links: &[Link; 6], moving: &[(usize, Local, bool, f64)], a: usize, b: usize) -> f64 {
    let (range, far) = if b < moving.len() {
        let (ka, kb) = (moving[a].0, moving[b].0);
        let far = if ka >= kb { a } else { b };
        (ka.min(kb) + 1..=ka.max(kb), far)
    } else {
        (0..=moving[a].0, a)
    };
    let (k, local, _, reach) = &moving[far];
    let centre = match local {
        Local::Capsule { a, b, .. } => (a + b) / 2.0,
        Local::Box { center, .. } => *center,
    };
    let mut chain = centre.norm() + reach;
    let mut ratio: f64 = 0.0;
    for j in (0..=*k).rev() {
        let anchor = links[j].anchor.norm();
        if range.contains(&j) {
            ratio = ratio.max((chain + anchor) / UR5E_LEVER_ARMS[j]);
        }
        chain += links[j].pos.norm() + 2.0 * anchor;
    }
    if ratio > 0.0 { ratio.min(1.0) } else { 1.0 }
}

impl Screen {
    /// The screen of the private model and data in `b`; `None` when some geom that can touch
    /// the arm is of a type the screen cannot bound, or the arm is not a chain of six links.
    pub(crate) fn build(b: &Build<'_>) -> Option<Self> {
        let m: &MjModel = b.data.model();
        let d = b.data;
        let ngeom = m.ffi().ngeom as usize;
        let chain = b.chain.clone();
        let link_pose: [Frame; 6] = b
            .link_bodies
            .map(|l| (mat(&d.xmat()[l]), Vector3::from(d.xpos()[l])));
        let (ct, ca) = (m.geom_contype(), m.geom_conaffinity());
        let collidable = |g: usize| ct[g] != 0 || ca[g] != 0;
        // Index of each geom's shape: moving ones first, then fixed ones.
        let mut index: Vec<Option<usize>> = vec![None; ngeom];
        let mut moving: Vec<(usize, Local, bool, f64)> = Vec::new();
        let mut fixed: Vec<Posed> = Vec::new();
        let mut fixed_geoms: Vec<usize> = Vec::new();
        for (g, slot) in index.iter_mut().enumerate() {
            if !collidable(g) {
                continue;
            }
            let shape = geom_local(m, g);
            let k = b.group[g];
            let (gr, gt) = (mat(&d.geom_xmat()[g]), Vector3::from(d.geom_xpos()[g]));
            if k == 0 {
                let s = match shape {
                    // A fixed geom of a type the screen cannot bound: fine while nothing moving
                    // can touch it (checked below through the pairs).
                    None => continue,
                    Some(GeomShape::Plane) => {
                        let n = gr.column(2).into_owned();
                        Shape::HalfSpace {
                            normal: [n.x, n.y, n.z],
                            offset: n.dot(&gt),
                        }
                    }
                    Some(GeomShape::Solid(l)) => l.posed(&gr, &gt),
                };
                fixed_geoms.push(g);
                fixed.push((s, s.bounding_sphere(), exact(m, g)));
            } else {
                let Some(GeomShape::Solid(l)) = shape else {
                    return None;
                };
                let link = &link_pose[k as usize - 1];
                let lr = link.0.transpose();
                let rel_r = lr * gr;
                let rel_t = lr * (gt - link.1);
                *slot = Some(moving.len());
                let local = moved(&l, &rel_r, &rel_t);
                moving.push((k as usize - 1, local, exact(m, g), local.reach()));
            }
        }
        for (i, &g) in fixed_geoms.iter().enumerate() {
            index[g] = Some(moving.len() + i);
        }
        let mut geoms = vec![0; moving.len() + fixed.len()];
        for (g, i) in index.iter().enumerate() {
            if let Some(i) = i {
                geoms[*i] = g;
            }
        }
        // The pairs MuJoCo tests in this model.
        let filter = PairFilter::new(m);
        let (margin, gap) = (m.geom_margin(), m.geom_gap());
        let mut pairs = Vec::new();
        let mut add = |g1: usize, g2: usize, pair_margin: f64, pair_gap: f64| -> bool {
            if b.group[g1] == 0 && b.group[g2] == 0 {
                return true;
            }
            match (index[g1], index[g2]) {
                (Some(x), Some(y)) => {
                    let (a, bb) = if x < y { (x, y) } else { (y, x) };
                    pairs.push(Pair {
                        a: a as u16,
                        b: bb as u16,
                        gap: pair_margin.max(0.0) + PAD,
                        block: (pair_margin - pair_gap.max(0.0)).min(0.0) - PAD,
                        kappa: 1.0,
                    });
                    true
                }
                // A geom that can touch the arm but has no bounding shape.
                _ => false,
            }
        };
        for g1 in 0..ngeom {
            if !collidable(g1) {
                continue;
            }
            for g2 in g1 + 1..ngeom {
                if !collidable(g2) {
                    continue;
                }
                if !filter.tested(g1, g2) {
                    continue;
                }
                if !add(g1, g2, margin[g1].max(margin[g2]), gap[g1].max(gap[g2])) {
                    return None;
                }
            }
        }
        let (pg1, pg2, pm, pgap) = (m.pair_geom1(), m.pair_geom2(), m.pair_margin(), m.pair_gap());
        for p in 0..m.ffi().npair as usize {
            if !add(pg1[p] as usize, pg2[p] as usize, pm[p], pgap[p]) {
                return None;
            }
        }
        if moving.len() + fixed.len() > u16::MAX as usize {
            return None;
        }
        // Cheapest rejections first: fixed partners before self pairs.
        pairs.sort_by_key(|p| (p.b as usize) < moving.len());
        let nm = moving.len();
        for p in &mut pairs {
            p.kappa = lever_ratio(&chain.links, &moving, p.a as usize, p.b as usize);
        }
        // The arm's own pairs that keep their gap at any angles of the joints between their
        // links: never tested.
        let places: Vec<Places> = moving
            .iter()
            .map(|m| axial_places(&chain, &link_pose, m))
            .collect();
        pairs.retain(|p| {
            let (a, bb) = (p.a as usize, p.b as usize);
            bb >= nm
                || turned_apart(
                    &chain,
                    &link_pose,
                    (moving[a].0, &places[a]),
                    (moving[bb].0, &places[bb]),
                ) < p.gap
        });
        let partner = |p: &Pair| {
            if (p.b as usize) < nm {
                Partner::Link(moving[p.b as usize].0)
            } else {
                Partner::Fixed(p.b as usize - nm)
            }
        };
        // Each link–partner group together, the groups in the order of their first pair.
        let mut order: Vec<(usize, Partner)> = Vec::new();
        for p in &pairs {
            let key = (moving[p.a as usize].0, partner(p));
            if !order.contains(&key) {
                order.push(key);
            }
        }
        let mut grouped = Vec::with_capacity(pairs.len());
        let mut groups = Vec::with_capacity(order.len());
        for &(link, with) in &order {
            let start = grouped.len() as u32;
            let (mut gap, mut kappa): (f64, f64) = (0.0, 0.0);
            for p in pairs
                .iter()
                .filter(|p| (moving[p.a as usize].0, partner(p)) == (link, with))
            {
                gap = gap.max(p.gap);
                kappa = kappa.max(p.kappa);
                grouped.push(*p);
            }
            groups.push(Group {
                link,
                partner: with,
                gap,
                kappa,
                start,
                end: grouped.len() as u32,
            });
        }
        let link_capsules =
            std::array::from_fn(|k| link_capsule(moving.iter().filter(|m| m.0 == k).map(|m| &m.1)));
        let link_spheres =
            std::array::from_fn(|k| link_sphere(moving.iter().filter(|m| m.0 == k).map(|m| &m.1)));
        Some(Self {
            chain,
            moving,
            fixed,
            pairs: grouped,
            groups,
            link_spheres,
            link_capsules,
            geoms,
            undecided: Vec::new(),
            posed: Posing::new(nm),
            shape_of: index.iter().map(|i| i.map_or(u32::MAX, |i| i as u32)).collect(),
            bound_posed: Posing::new(nm),
            bound_frames: link_pose,
        })
    }

    /// The screen's verdict at `q` (radians): `Some(true)` when every tested pair keeps its
    /// margin plus [`PAD`] (MuJoCo then reports no contact), `Some(false)` when a pair of exact
    /// shapes (no bounds) penetrates by more than [`PAD`] (MuJoCo then reports that contact),
    /// `None` otherwise.
    pub fn classify(&mut self, q: &[f64; 6]) -> Option<bool> {
        self.decide(q).0
    }

    /// The verdict at `q` and the geom pair that decided a "blocked" (geom ids).
    pub fn decide(&mut self, q: &[f64; 6]) -> (Option<bool>, Option<(usize, usize)>) {
        let (verdict, hit, _) = self.judge::<false>(q, &JointSpare::NONE);
        (verdict, hit)
    }

    /// The verdict at `q` (radians), as [`Screen::classify`], and with a "free" the spare
    /// clearance by joint range ([`JointSpare`], in each range at most `caps`' (metres: the
    /// spare worth measuring, [`JointSpare::wanted`]); none with any other verdict): for each tested pair, a lower bound on how much farther apart than its margin
    /// plus [`PAD`] its primitives are, divided by the pair's lever-arm ratio (its parts move
    /// relative to each other at most that fraction of the planner's lever-arm bound), in the
    /// range of the joints that move the pair's parts relative to each other. Geoms lie inside
    /// their primitives, so the geoms keep the margin wherever the lever-arm bound of the
    /// range's joint changes stays within its spare.
    ///
    /// With no verdict (`None`), the spare is that of the pairs the screen decided, and
    /// [`Screen::undecided`] lists the others: a checker that measures them exactly can settle
    /// the verdict and the spare ([`Undecided`]).
    pub fn free_spare(&mut self, q: &[f64; 6], caps: &JointSpare) -> (Option<bool>, JointSpare) {
        let (verdict, _, spare) = self.judge::<true>(q, caps);
        (
            verdict,
            if verdict == Some(false) {
                JointSpare::NONE
            } else {
                spare
            },
        )
    }

    /// The pairs the last [`Screen::free_spare`] could not decide (none after a verdict).
    pub fn undecided(&self) -> &[Undecided] {
        &self.undecided
    }

    /// The verdict, the pair that decided a "blocked", and with `SPARE` the spare clearance by
    /// joint range up to `caps`' (metres; only meaningful with a "free").
    fn judge<const SPARE: bool>(
        &mut self,
        q: &[f64; 6],
        caps: &JointSpare,
    ) -> (Option<bool>, Option<(usize, usize)>, JointSpare) {
        let frames = self.chain.link_poses(q);
        // Every moving shape posed again when first needed.
        self.posed.renew();
        let spheres = self.world_spheres(&frames);
        let capsules = self.world_capsules(&frames);
        let nm = self.moving.len();
        let mut unsure = false;
        let mut spare = *caps;
        self.undecided.clear();
        for g in &self.groups {
            // The joints that move the group's pair relative to each other (none: the pair
            // never moves apart or closer, and limits no spare).
            let (lo, hi) = g.joints();
            let ranged = lo <= hi;
            // The link keeps the group's gap, and with a spare wanted the range's spare found so
            // far too: nothing to learn from the group's pairs (else they may keep more than
            // the link's bound does, or not their gap).
            let keep = if SPARE && ranged {
                g.gap + g.kappa * spare.get(lo, hi)
            } else {
                g.gap
            };
            if self.group_apart(g, &spheres, &capsules, keep) {
                continue;
            }
            for p in &self.pairs[g.start as usize..g.end as usize] {
                let (a, b) = (p.a as usize, p.b as usize);
                self.posed.ensure(a, &self.moving, &frames);
                self.posed.ensure(b, &self.moving, &frames);
                let (x, y) = (self.posed.get(a, &self.fixed), self.posed.get(b, &self.fixed));
                if let (Some((c1, r1)), Some((c2, r2))) = (x.1, y.1) {
                    let t = r1 + r2 + p.gap;
                    let d = [c1[0] - c2[0], c1[1] - c2[1], c1[2] - c2[2]];
                    if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] >= t * t
                        || (b >= nm && sphere_box_apart(&c1, r1, &y.0, p.gap))
                    {
                        if SPARE && ranged {
                            let need = p.gap + p.kappa * spare.get(lo, hi);
                            let t = r1 + r2 + need;
                            let far = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] >= t * t
                                || (b >= nm && sphere_box_apart(&c1, r1, &y.0, need));
                            if !far && !beyond(&x.0, &y.0, need) {
                                // The spheres may lie far inside each other's reach (a wrist
                                // housing and the flange): the primitives' own clearance,
                                // which the spheres' gap only bounds from below.
                                let bound = sphere_shape_gap(&c1, r1, y);
                                let c = apart(&x.0, &y.0, p.gap).map_or(bound, |c| c.max(bound));
                                spare.tighten(lo, hi, (c - p.gap) / p.kappa);
                            }
                        }
                        continue;
                    }
                }
                // Near, or the clearance when it is wanted (one distance for both); nothing
                // to learn from a pair the quick bound keeps beyond what it could tighten.
                let quick = if SPARE && ranged {
                    p.gap + p.kappa * spare.get(lo, hi)
                } else {
                    p.gap
                };
                if beyond(&x.0, &y.0, quick) {
                    continue;
                }
                let kept = if SPARE && ranged {
                    apart(&x.0, &y.0, p.gap)
                } else {
                    (!near(&x.0, &y.0, p.gap)).then_some(f64::INFINITY)
                };
                match kept {
                    None => {
                        if x.2 && y.2 && within(&x.0, &y.0, p.block) {
                            self.undecided.clear();
                            return (
                                Some(false),
                                Some((self.geoms[a], self.geoms[b])),
                                JointSpare::NONE,
                            );
                        }
                        unsure = true;
                        if SPARE {
                            self.undecided.push(Undecided {
                                geoms: (self.geoms[a], self.geoms[b]),
                                gap: p.gap,
                                kappa: p.kappa,
                                range: (lo, hi),
                            });
                        }
                    }
                    Some(c) if SPARE && ranged => spare.tighten(lo, hi, (c - p.gap) / p.kappa),
                    Some(_) => {}
                }
            }
        }
        if !unsure {
            self.undecided.clear();
        }
        ((!unsure).then_some(true), None, spare)
    }

    /// How far the moving shapes reach from each joint's axis at the link frames `frames`
    /// ([`ArmChain::link_poses`]), metres, through each link's bounding sphere
    /// ([`ArmChain::axis_reach`]): every moving collidable geom lies inside them.
    pub(crate) fn reach(&self, frames: &[Frame; 6]) -> [f64; 6] {
        self.chain.axis_reach(frames, &self.world_spheres(frames))
    }

    /// Each link's bounding sphere in the world at the link frames `frames` (centre, radius,
    /// metres; radius negative for a link without shapes).
    fn world_spheres(&self, frames: &[Frame; 6]) -> [(V3, f64); 6] {
        std::array::from_fn(|k| {
            let (c, r) = &self.link_spheres[k];
            let w = frames[k].0 * c + frames[k].1;
            ([w.x, w.y, w.z], *r)
        })
    }

    /// Each link's bounding capsule in the world at the link frames `frames` (`None`: a link
    /// without shapes).
    fn world_capsules(&self, frames: &[Frame; 6]) -> [Option<Shape>; 6] {
        std::array::from_fn(|k| {
            self.link_capsules[k]
                .as_ref()
                .map(|l| l.posed(&frames[k].0, &frames[k].1))
        })
    }

    /// True when group `g`'s link keeps `gap` metres from the group's partner: its sphere
    /// (`spheres`: each link's, world frame) from the other link's sphere, or from a fixed
    /// shape's bounding sphere, its box or its half-space; else its capsule (`capsules`) from
    /// the other link's capsule, or from the fixed shape (a box by [`beyond`]).
    fn group_apart(
        &self,
        g: &Group,
        spheres: &[(V3, f64); 6],
        capsules: &[Option<Shape>; 6],
        gap: f64,
    ) -> bool {
        let (c1, r1) = spheres[g.link];
        let by_spheres = match g.partner {
            Partner::Link(m) => sphere_apart(&c1, r1, &spheres[m].0, spheres[m].1, gap),
            Partner::Fixed(f) => match &self.fixed[f] {
                (y, Some((c2, r2)), _) => {
                    sphere_apart(&c1, r1, c2, *r2, gap) || sphere_box_apart(&c1, r1, y, gap)
                }
                (Shape::HalfSpace { normal, offset }, None, _) => {
                    normal[0] * c1[0] + normal[1] * c1[1] + normal[2] * c1[2] - offset - r1 >= gap
                }
                _ => false,
            },
        };
        if by_spheres {
            return true;
        }
        let Some(capsule) = &capsules[g.link] else {
            return true;
        };
        match g.partner {
            Partner::Link(m) => capsules[m]
                .as_ref()
                .is_none_or(|other| !near(capsule, other, gap)),
            Partner::Fixed(f) => {
                let y = &self.fixed[f].0;
                match y {
                    Shape::Box { .. } => beyond(capsule, y, gap),
                    _ => !near(capsule, y, gap),
                }
            }
        }
    }

    /// Sets the link frames (`ArmChain::link_poses`) at which [`Screen::geom_clearance`]
    /// bounds the distances of geoms.
    pub(crate) fn bound_at(&mut self, frames: &[Frame; 6]) {
        self.bound_frames = *frames;
        self.bound_posed.renew();
    }

    /// A lower bound on the distance between geoms `g1` and `g2` at the frames of the last
    /// [`Screen::bound_at`], metres: the clearance of their primitives, which contain them
    /// (`shapes::clearance`; 0 where they may touch); `−∞` when either has no primitive.
    pub(crate) fn geom_clearance(&mut self, g1: usize, g2: usize) -> f64 {
        let shape = |g: usize| self.shape_of.get(g).copied().filter(|&i| i != u32::MAX);
        let (Some(a), Some(b)) = (shape(g1), shape(g2)) else {
            return f64::NEG_INFINITY;
        };
        let (a, b) = (a as usize, b as usize);
        self.bound_posed.ensure(a, &self.moving, &self.bound_frames);
        self.bound_posed.ensure(b, &self.moving, &self.bound_frames);
        let at = |i: usize| &self.bound_posed.get(i, &self.fixed).0;
        clearance(at(a), at(b))
    }

    /// True when the screen vouches that `q` (radians) is free ([`Screen::classify`]).
    pub fn free(&mut self, q: &[f64; 6]) -> bool {
        self.classify(q) == Some(true)
    }

    /// Pairs tested per configuration.
    pub fn pairs(&self) -> usize {
        self.pairs.len()
    }
}

#[cfg(test)]
impl Screen {
    /// Bounds on the spare [`Screen::free_spare`] finds at `q` (radians), pair by pair and
    /// without its shortcuts: for each joint range, the least over the range's pairs of
    /// `(c − gap) / kappa`, at most `cap` (metres), with `c` each pair's primitive clearance
    /// ([`clearance`](crate::motion::plan::shapes::clearance)) in the first spare, and the
    /// larger of that and its bounding-sphere bound in the second.
    pub(crate) fn pair_spares(&self, q: &[f64; 6], cap: f64) -> (JointSpare, JointSpare) {
        let frames = self.chain.link_poses(q);
        let nm = self.moving.len();
        let (mut low, mut high) = (JointSpare::uniform(cap), JointSpare::uniform(cap));
        for g in &self.groups {
            let (lo, hi) = g.joints();
            if lo > hi {
                continue;
            }
            for p in &self.pairs[g.start as usize..g.end as usize] {
                let (a, b) = (p.a as usize, p.b as usize);
                let x = pose(&self.moving[a], &frames);
                let y = if b < nm {
                    pose(&self.moving[b], &frames)
                } else {
                    self.fixed[b - nm]
                };
                let c = clearance(&x.0, &y.0);
                let (c1, r1) = x.1.expect("a moving shape has a sphere");
                let spheres = sphere_shape_gap(&c1, r1, &y);
                low.tighten(lo, hi, (c - p.gap) / p.kappa);
                high.tighten(lo, hi, (c.max(spheres) - p.gap) / p.kappa);
            }
        }
        (low, high)
    }

    /// For every two moving shapes on different links: the bound on their distance at any
    /// angles of the joints between them ([`turned_apart`]) from the link frames at `q`, and
    /// the two primitives posed at `q2` (radians, metres).
    pub(crate) fn turned_bounds(&self, q: &[f64; 6], q2: &[f64; 6]) -> Vec<(f64, Shape, Shape)> {
        let (f1, f2) = (self.chain.link_poses(q), self.chain.link_poses(q2));
        let mut out = Vec::new();
        let chain = &self.chain;
        let places: Vec<Places> = self.moving.iter().map(|m| axial_places(chain, &f1, m)).collect();
        for (i, x) in self.moving.iter().enumerate() {
            for (k, y) in self.moving.iter().enumerate().skip(i + 1) {
                if x.0 != y.0 {
                    let bound = turned_apart(chain, &f1, (x.0, &places[i]), (y.0, &places[k]));
                    out.push((bound, pose(x, &f2).0, pose(y, &f2).0));
                }
            }
        }
        out
    }

    /// For every pair: its lever-arm ratio, and between joints `q` and `q2` (radians) the
    /// largest displacement of a point of its distal shape's hull (box corners; capsule ends
    /// pushed out by the radius along each axis) relative to the frame of its partner's link
    /// (the world for a fixed partner), with the bound `kappa · Σ_range r_j |q2_j − q_j|`
    /// (metres) that the spare's vouching relies on.
    pub(crate) fn pair_moves(&self, q: &[f64; 6], q2: &[f64; 6]) -> Vec<(f64, f64, f64)> {
        let (f1, f2) = (self.chain.link_poses(q), self.chain.link_poses(q2));
        let nm = self.moving.len();
        let points = |l: &Local| -> Vec<Vector3<f64>> {
            match l {
                Local::Capsule { a, b, radius } => [a, b]
                    .iter()
                    .flat_map(|e| {
                        (0..3).flat_map(move |i| [-1.0, 1.0].map(|sgn| *e + Vector3::ith(i, sgn * radius)))
                    })
                    .collect(),
                Local::Box { center, axes, half } => (0..8)
                    .map(|c| {
                        let s = |i: usize| if c >> i & 1 == 1 { 1.0 } else { -1.0 };
                        center
                            + (0..3)
                                .map(|i| axes.column(i) * (s(i) * half[i]))
                                .sum::<Vector3<f64>>()
                    })
                    .collect(),
            }
        };
        self.pairs
            .iter()
            .map(|p| {
                let (a, b) = (p.a as usize, p.b as usize);
                let (far, near_link, range) = if b < nm {
                    let (ka, kb) = (self.moving[a].0, self.moving[b].0);
                    let far = if ka >= kb { a } else { b };
                    (far, Some(ka.min(kb)), ka.min(kb) + 1..=ka.max(kb))
                } else {
                    (a, None, 0..=self.moving[a].0)
                };
                let k = self.moving[far].0;
                let in_near = |f: &[Frame; 6], x: &Vector3<f64>| {
                    let w = f[k].0 * x + f[k].1;
                    match near_link {
                        Some(n) => f[n].0.transpose() * (w - f[n].1),
                        None => w,
                    }
                };
                let moved = points(&self.moving[far].1)
                    .iter()
                    .map(|x| (in_near(&f2, x) - in_near(&f1, x)).norm())
                    .fold(0.0, f64::max);
                let bound: f64 = range.map(|j| UR5E_LEVER_ARMS[j] * (q2[j] - q[j]).abs()).sum();
                (p.kappa, moved, p.kappa * bound)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::plan::shapes::near;

    #[test]
    fn a_link_sphere_contains_every_shape_of_the_link() {
        let shapes = [
            Local::Capsule {
                a: Vector3::new(0.0, 0.0, -0.1),
                b: Vector3::new(0.0, 0.0, 0.3),
                radius: 0.05,
            },
            Local::Box {
                center: Vector3::new(0.2, -0.1, 0.0),
                axes: Matrix3::identity(),
                half: [0.02, 0.03, 0.04],
            },
        ];
        let (c, r) = link_sphere(shapes.iter());
        for l in &shapes {
            let centre = match l {
                Local::Capsule { a, b, .. } => (a + b) / 2.0,
                Local::Box { center, .. } => *center,
            };
            assert!(
                (centre - c).norm() + l.reach() <= r + 1e-12,
                "{l:?} outside ({c}, {r})"
            );
        }
        // No shape: a negative radius, always apart.
        let (_, none) = link_sphere(std::iter::empty());
        assert!(none < 0.0);
        assert!(sphere_apart(&[0.0; 3], none, &[0.0; 3], 1.0, 0.01));
    }

    #[test]
    fn a_link_capsule_contains_every_shape_of_the_link() {
        let shapes = [
            Local::Capsule {
                a: Vector3::new(0.0, 0.0, -0.1),
                b: Vector3::new(0.02, 0.0, 0.3),
                radius: 0.05,
            },
            Local::Box {
                center: Vector3::new(0.05, -0.04, 0.2),
                axes: Matrix3::new(0.8, -0.6, 0.0, 0.6, 0.8, 0.0, 0.0, 0.0, 1.0),
                half: [0.02, 0.03, 0.04],
            },
        ];
        let Some(Local::Capsule { a, b, radius }) = link_capsule(shapes.iter()) else {
            panic!("a capsule");
        };
        let (a, b) = ([a.x, a.y, a.z], [b.x, b.y, b.z]);
        // Every shape's extreme points, and the capsule's surface points around its ends.
        let to_axis =
            |p: &Vector3<f64>| segment_segment_dist2(&a, &b, &[p.x, p.y, p.z], &[p.x, p.y, p.z]).sqrt();
        let mut points: Vec<(Vector3<f64>, f64)> = Vec::new();
        if let Local::Capsule { a, b, radius } = &shapes[0] {
            for k in 0..=20 {
                points.push((a + (b - a) * (k as f64 / 20.0), *radius));
            }
        }
        if let Local::Box { center, axes, half } = &shapes[1] {
            for k in 0..8 {
                let s = |i: usize| if k >> i & 1 == 0 { -half[i] } else { half[i] };
                points.push((center + axes * Vector3::new(s(0), s(1), s(2)), 0.0));
            }
        }
        for (p, r) in &points {
            assert!(to_axis(p) + r <= radius + 1e-12, "{p} ({r}) outside the capsule");
        }
        // Tighter than the sphere around the same shapes, and none for no shape.
        assert!(radius < link_sphere(shapes.iter()).1);
        assert!(link_capsule(std::iter::empty()).is_none());
    }

    #[test]
    fn sphere_box_apart_agrees_with_the_box_nearness_test() {
        let b = Shape::Box {
            center: [0.5, 0.0, 0.2],
            axes: [[0.8, 0.6, 0.0], [-0.6, 0.8, 0.0], [0.0, 0.0, 1.0]],
            half: [0.1, 0.05, 0.2],
        };
        let gap = 0.0055;
        let mut apart = 0;
        // Seeded points on a grid around the box: whenever the sphere test says apart, the
        // (conservative) nearness test of the sphere as a capsule says not near either.
        for i in 0..20 {
            for j in 0..20 {
                for k in 0..10 {
                    let c = [
                        0.2 + 0.03 * i as f64,
                        -0.3 + 0.03 * j as f64,
                        0.05 * k as f64 - 0.1,
                    ];
                    let r = 0.02;
                    let s = Shape::Capsule {
                        a: c,
                        b: c,
                        radius: r,
                    };
                    if sphere_box_apart(&c, r, &b, gap) {
                        apart += 1;
                        assert!(!near(&s, &b, gap), "{c:?}");
                    }
                }
            }
        }
        assert!(apart > 1000, "{apart}");
        // Not a box: never apart by this test.
        let h = Shape::HalfSpace {
            normal: [0.0, 0.0, 1.0],
            offset: 0.0,
        };
        assert!(!sphere_box_apart(&[0.0, 0.0, 5.0], 0.1, &h, gap));
    }
}
