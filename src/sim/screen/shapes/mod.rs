//! Convex primitives for the conservative collision screen: capsules (a sphere is a capsule of
//! zero length), oriented boxes and half-spaces, and how far apart two of them are.
//!
//! Each pair of primitive types has one measure of separation ([`Separation`], from
//! [`separation`]): the squared distance between the two cores (segment–segment for two
//! capsules, segment–box for a capsule and a box) with the radii around them, the height of the
//! lowest point above a half-space, or, for two boxes, the boxes themselves (their separating
//! axes). The screen's questions are asked of that one measure: whether two primitives may come
//! closer than a distance ([`Separation::near`], erring towards "near"), whether they surely do
//! ([`Separation::within`], erring towards "not"), and a lower bound on their distance
//! ([`Separation::clearance`]). Component-wise arithmetic on nalgebra's `Vector3` (the one
//! vector type of the screen and the arm chain), no allocation.

mod boxes;
mod segment_box;
mod segments;
#[cfg(test)]
mod tests;

pub(crate) use segment_box::segment_box_dist2;
pub(crate) use segments::segment_segment_dist2;

/// A point or direction in metres (world or local frame, as documented at each use).
pub(crate) type V3 = nalgebra::Vector3<f64>;

#[inline]
fn sub(a: &V3, b: &V3) -> V3 {
    V3::new(a.x - b.x, a.y - b.y, a.z - b.z)
}

#[inline]
fn dot(a: &V3, b: &V3) -> f64 {
    a.x * b.x + a.y * b.y + a.z * b.z
}

#[inline]
fn axpy(s: f64, a: &V3, b: &V3) -> V3 {
    V3::new(b.x + s * a.x, b.y + s * a.y, b.z + s * a.z)
}

/// A convex primitive posed in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Shape {
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

/// A sphere: every point within `radius` metres of `centre` (world or link frame, as documented
/// at each use).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Sphere {
    /// Centre, metres.
    pub(crate) centre: V3,
    /// Radius, metres (non-negative).
    pub(crate) radius: f64,
}

impl Shape {
    /// A sphere around the shape; `None` for a half-space.
    pub(crate) fn bounding_sphere(&self) -> Option<Sphere> {
        match self {
            Shape::Capsule { a, b, radius } => {
                let c = V3::new((a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0, (a[2] + b[2]) / 2.0);
                let h = dot(&sub(b, a), &sub(b, a)).sqrt() / 2.0;
                Some(Sphere {
                    centre: c,
                    radius: h + radius,
                })
            }
            Shape::Box { center, half, .. } => Some(Sphere {
                centre: *center,
                radius: dot(half, half).sqrt(),
            }),
            Shape::HalfSpace { .. } => None,
        }
    }
}

/// How far apart two primitives are: one measure per pair of primitive types ([`separation`]).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Separation<'a> {
    /// Two capsules, or a capsule and a box: `d2` the squared distance between their cores
    /// (the capsules' segments, the box), metres², and `radii` what surrounds the cores (the
    /// capsules' radii summed), metres. Exact: the distance is `√d2 − radii`.
    Cores {
        /// Squared distance between the cores, metres².
        d2: f64,
        /// The radii around the cores, metres.
        radii: f64,
    },
    /// A capsule or a box against a half-space: `above` the height of the solid's lowest core
    /// point above the plane (a capsule's nearer end; a box's lowest corner), metres, and
    /// `radius` the capsule's (0 for a box). Exact: the signed distance is `above − radius`.
    Above {
        /// Height of the lowest core point above the plane, metres.
        above: f64,
        /// The radius around the core, metres.
        radius: f64,
    },
    /// Two oriented boxes, asked through their separating axes.
    Boxes {
        /// The first box's centre, axes and half extents (metres).
        x: (&'a V3, &'a [V3; 3], &'a V3),
        /// The second box's.
        y: (&'a V3, &'a [V3; 3], &'a V3),
    },
    /// Two half-spaces: they always meet.
    Overlapping,
}

/// The separation of `x` and `y` (in either order).
#[inline]
pub(crate) fn separation<'a>(x: &'a Shape, y: &'a Shape) -> Separation<'a> {
    use Shape::*;
    match (x, y) {
        (
            Capsule { a, b, radius },
            Capsule {
                a: c,
                b: d,
                radius: r2,
            },
        ) => Separation::Cores {
            d2: segment_segment_dist2(a, b, c, d),
            radii: radius + r2,
        },
        (Capsule { a, b, radius }, Box { center, axes, half })
        | (Box { center, axes, half }, Capsule { a, b, radius }) => Separation::Cores {
            d2: segment_box_dist2(a, b, center, axes, half),
            radii: *radius,
        },
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
        ) => Separation::Boxes {
            x: (c1, a1, h1),
            y: (c2, a2, h2),
        },
        (Capsule { a, b, radius }, HalfSpace { normal, offset })
        | (HalfSpace { normal, offset }, Capsule { a, b, radius }) => Separation::Above {
            above: dot(normal, a).min(dot(normal, b)) - offset,
            radius: *radius,
        },
        (Box { center, axes, half }, HalfSpace { normal, offset })
        | (HalfSpace { normal, offset }, Box { center, axes, half }) => {
            let reach: f64 = (0..3).map(|i| half[i] * dot(&axes[i], normal).abs()).sum();
            Separation::Above {
                above: dot(normal, center) - reach - offset,
                radius: 0.0,
            }
        }
        (HalfSpace { .. }, HalfSpace { .. }) => Separation::Overlapping,
    }
}

impl Separation<'_> {
    /// True when the two may come closer than `gap` metres (`gap` ≥ 0): always true when they
    /// are that close, possibly true when a box's corner region makes two boxes look closer
    /// than they are (the first box is inflated by `gap` along its axes).
    #[inline]
    pub(crate) fn near(&self, gap: f64) -> bool {
        match *self {
            Separation::Cores { d2, radii } => {
                let t = radii + gap;
                d2 < t * t
            }
            Separation::Above { above, radius } => above < radius + gap,
            Separation::Boxes {
                x: (c1, a1, h1),
                y: (c2, a2, h2),
            } => {
                let inflated = V3::new(h1[0] + gap, h1[1] + gap, h1[2] + gap);
                boxes::boxes_overlap(c1, a1, &inflated, c2, a2, h2)
            }
            Separation::Overlapping => true,
        }
    }

    /// True only when the two certainly come closer than `d` metres (`d` may be negative: a
    /// depth): exact for every pair but two boxes, which count only when they overlap and `d`
    /// is positive (beyond 1 µm).
    #[inline]
    pub(crate) fn within(&self, d: f64) -> bool {
        match *self {
            Separation::Cores { d2, radii } => {
                let t = radii + d;
                t > 0.0 && d2 < t * t
            }
            Separation::Above { .. } => self.near(d),
            Separation::Boxes {
                x: (c1, a1, h1),
                y: (c2, a2, h2),
            } => d > 1e-6 && boxes::boxes_overlap(c1, a1, h1, c2, a2, h2),
            Separation::Overlapping => false,
        }
    }

    /// A lower bound on the distance, metres (0 when they may touch, and for two half-spaces):
    /// exact but for two boxes, bounded there by the widest gap of their projections on the six
    /// face axes (every separating projection bounds the distance from below).
    #[inline(always)]
    pub(crate) fn clearance(&self) -> f64 {
        let d = match *self {
            Separation::Cores { d2, radii } => d2.sqrt() - radii,
            Separation::Above { above, radius } => above - radius,
            Separation::Boxes {
                x: (c1, a1, h1),
                y: (c2, a2, h2),
            } => boxes::boxes_face_gap(c1, a1, h1, c2, a2, h2),
            Separation::Overlapping => 0.0,
        };
        d.max(0.0)
    }

    /// `None` when the two may come closer than `gap` metres ([`Separation::near`]), else their
    /// [`clearance`](Separation::clearance) (at least `gap` but for two boxes).
    #[inline]
    pub(crate) fn apart(&self, gap: f64) -> Option<f64> {
        (!self.near(gap)).then(|| self.clearance())
    }
}

/// True when `x` and `y` surely lie more than `d` metres apart by a quick bound, false when it
/// cannot tell: a capsule against a box only ([`segment_box::axis_box_out2`]), a few products
/// against the exact distance's walk. A lower bound on [`Separation::clearance`].
#[inline]
pub(crate) fn surely_beyond(x: &Shape, y: &Shape, d: f64) -> bool {
    use Shape::*;
    match (x, y) {
        (Capsule { a, b, radius }, Box { center, axes, half })
        | (Box { center, axes, half }, Capsule { a, b, radius }) => {
            let t = radius + d;
            t < 0.0 || segment_box::axis_box_out2(a, b, center, axes, half) > t * t
        }
        _ => false,
    }
}
