//! Resolving named targets (`cube`, `bowl`, a point) against the current world, and reading the
//! tool's yaw.

use nalgebra::{Matrix3, Vector3};

use crate::world::World;

/// Where a named target is now, metres: the cube's centre, the bowl target (centre of the bowl
/// floor's top surface), or a fixed point.
pub fn resolve(target: &crate::spec::Target, w: &World) -> Vector3<f64> {
    use crate::spec::Target;
    match target {
        Target::Cube => w.cube_pos,
        Target::Bowl => w.bowl_target,
        Target::Point(p) => Vector3::new(p[0], p[1], p[2]),
    }
}

/// Yaw of the tool about world z, in the convention of [`crate::motion::ik_down`] (0 at home,
/// where the pinch x axis points along world +y), radians.
pub fn tool_yaw(pinch_rot: &Matrix3<f64>) -> f64 {
    let x = pinch_rot.column(0);
    (-x[0]).atan2(x[1])
}
