//! The screen's primitives in a body's frame: what bounds each geom.

use mujoco_rs::prelude::*;
use nalgebra::{Matrix3, Vector3};

use super::shapes::{Shape, V3};

/// A primitive in a body frame (metres).
#[derive(Clone, Copy, Debug)]
pub(super) enum Local {
    /// Every point within `radius` of the segment `a`–`b`.
    Capsule {
        a: Vector3<f64>,
        b: Vector3<f64>,
        radius: f64,
    },
    /// `center + axes · s`, `|s_i| ≤ half[i]` (the axes are the columns).
    Box {
        center: Vector3<f64>,
        axes: Matrix3<f64>,
        half: V3,
    },
}

impl Local {
    /// Radius of a sphere about [`Local::centre`] that contains the shape, metres.
    pub(super) fn reach(&self) -> f64 {
        match self {
            Local::Capsule { a, b, radius } => (b - a).norm() / 2.0 + radius,
            Local::Box { half, .. } => (half[0] * half[0] + half[1] * half[1] + half[2] * half[2]).sqrt(),
        }
    }

    /// The shape's centre: a capsule's mid-axis, a box's centre (metres).
    pub(super) fn centre(&self) -> Vector3<f64> {
        match self {
            Local::Capsule { a, b, .. } => (a + b) / 2.0,
            Local::Box { center, .. } => *center,
        }
    }

    /// The shape in the world, its frame at rotation `r` and translation `t` (metres).
    #[inline]
    pub(super) fn posed(&self, r: &Matrix3<f64>, t: &Vector3<f64>) -> Shape {
        match self {
            Local::Capsule { a, b, radius } => {
                let (a, b) = (r * a + t, r * b + t);
                Shape::Capsule {
                    a,
                    b,
                    radius: *radius,
                }
            }
            Local::Box { center, axes, half } => {
                let c = r * center + t;
                let m = r * axes;
                Shape::Box {
                    center: c,
                    axes: [
                        m.column(0).into_owned(),
                        m.column(1).into_owned(),
                        m.column(2).into_owned(),
                    ],
                    half: *half,
                }
            }
        }
    }

    /// The shape expressed in another frame: `r`, `t` map the shape's frame into it.
    pub(super) fn moved(&self, r: &Matrix3<f64>, t: &Vector3<f64>) -> Local {
        match self {
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
}

/// What bounds a geom: its half-space or a solid primitive in its own frame.
pub(super) enum GeomShape {
    /// A plane: the half-space below it.
    Plane,
    /// A capsule or a box.
    Solid(Local),
}

/// The geom's bounding primitive in its own frame: capsules and spheres exactly, a cylinder by
/// the capsule of its radius and half-height, a box exactly, a plane as its half-space, a mesh or
/// an ellipsoid by MuJoCo's bounding box of it (`geom_aabb`, which contains its convex hull);
/// `None` for a type the screen cannot bound (a height field, an SDF).
pub(super) fn geom_local(m: &MjModel, g: usize) -> Option<GeomShape> {
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
            half: Vector3::from(size),
        }),
        MjtGeomBase::mjGEOM_MESH | MjtGeomBase::mjGEOM_ELLIPSOID => GeomShape::Solid(Local::Box {
            center: Vector3::new(aabb[0], aabb[1], aabb[2]),
            axes: Matrix3::identity(),
            half: Vector3::new(aabb[3], aabb[4], aabb[5]),
        }),
        _ => return None,
    })
}

/// True when the screen's shape of the geom is the geom itself (a sphere, capsule, box or
/// plane), not a bound of it.
pub(super) fn exact(m: &MjModel, g: usize) -> bool {
    matches!(
        m.geom_type()[g],
        MjtGeomBase::mjGEOM_PLANE
            | MjtGeomBase::mjGEOM_SPHERE
            | MjtGeomBase::mjGEOM_CAPSULE
            | MjtGeomBase::mjGEOM_BOX
    )
}
