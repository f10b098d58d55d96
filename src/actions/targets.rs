//! Resolving named targets (`cube`, `bowl`, a point) against the current world, and reading the
//! tool's yaw.

use nalgebra::{Matrix3, Vector3};

use crate::failure::Failure;
use crate::kinds::ObjectRef;
use crate::scene::ObjectKind;
use crate::world::World;

/// Where a target is now, metres: a block's centre, the centre of a container floor's top
/// surface (the legacy `bowl`: the bowl target), the centre of an obstacle's top, or a fixed
/// point. Fails for a name the scene does not have (or a variable the runtime did not resolve).
pub fn resolve(target: &crate::kinds::Target, w: &World) -> Result<Vector3<f64>, Failure> {
    use crate::kinds::Target;
    match target {
        Target::Cube => Ok(w.objects[w.require_cube()?].pos),
        Target::Bowl => Ok(object_point(w, w.require_bowl()?)),
        Target::Point(p) => Ok(Vector3::new(p[0], p[1], p[2])),
        Target::Object(o) => {
            let i = object_index(o, w)?;
            Ok(object_point(w, i))
        }
    }
}

/// The point a motion aims at on object `i`: a block's centre, a container floor's top centre, an
/// obstacle's top centre, metres.
pub fn object_point(w: &World, i: usize) -> Vector3<f64> {
    let p = w.objects[i].pos;
    match w.spec(i).kind() {
        ObjectKind::Block => p,
        _ => Vector3::new(p.x, p.y, w.support_height(i)),
    }
}

/// The index of the object `o` names; a failure of kind `other` for a name the scene does not
/// have or a variable the runtime did not resolve.
pub fn object_index(o: &ObjectRef, w: &World) -> Result<usize, Failure> {
    match o {
        ObjectRef::Name(n) => w
            .index_of(n.as_str())
            .ok_or_else(|| Failure::other(format!("scene `{}` has no object `{n}`", w.scene.name))),
        ObjectRef::Var(v) => Err(Failure::other(format!("the variable `{{{v}}}` was not resolved"))),
    }
}

/// The block a target names, if it names one (the legacy `cube` is the scene's cube).
pub fn target_block(target: &crate::kinds::Target, w: &World) -> Option<usize> {
    use crate::kinds::Target;
    match target {
        Target::Cube => w.cube(),
        Target::Object(o) => object_index(o, w)
            .ok()
            .filter(|&i| w.spec(i).kind() == ObjectKind::Block),
        _ => None,
    }
}

/// The object a target names (the legacy names included), if any.
pub fn target_object(target: &crate::kinds::Target, w: &World) -> Option<usize> {
    use crate::kinds::Target;
    match target {
        Target::Cube => w.cube(),
        Target::Bowl => w.bowl(),
        Target::Object(o) => object_index(o, w).ok(),
        Target::Point(_) => None,
    }
}

/// Yaw of the tool about world z, in the convention of [`crate::motion::ik_down`] (0 at home,
/// where the pinch x axis points along world +y), radians.
pub fn tool_yaw(pinch_rot: &Matrix3<f64>) -> f64 {
    let x = pinch_rot.column(0);
    (-x[0]).atan2(x[1])
}

/// Distance from `p` to the segment `a`–`b` in the table plane, metres.
pub(crate) fn segment_distance(
    p: nalgebra::Vector2<f64>,
    a: nalgebra::Vector2<f64>,
    b: nalgebra::Vector2<f64>,
) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 < 1e-12 {
        0.0
    } else {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    };
    (p - (a + ab * t)).norm()
}
