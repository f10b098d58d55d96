//! Resolving named targets (`cube`, `bowl`, an object, a spot, a point) against the current
//! world, and reading the tool's yaw.

use nalgebra::Vector3;

use crate::failure::Failure;
use crate::kinds::ObjectRef;
use crate::scene::{ObjectKind, SceneSpec, Spot};
use crate::world::World;

/// Where a target is now, metres: a block's centre, the centre of a container floor's top
/// surface (the legacy `bowl`: the bowl target), the centre of an obstacle's top, a spot's point
/// on the table top (z = 0), or a fixed point. Fails for a name the scene does not have (or a
/// variable the runtime did not resolve).
pub fn resolve(target: &crate::kinds::Target, w: &World) -> Result<Vector3<f64>, Failure> {
    use crate::kinds::Target;
    match target {
        Target::Cube => Ok(w.objects[w.require_cube()?].pos),
        Target::Bowl => Ok(object_point(w, w.require_bowl()?)),
        Target::Point(p) => Ok(Vector3::new(p[0], p[1], p[2])),
        Target::Object(o) => match target_spot(target, &w.scene) {
            Some(s) => Ok(Vector3::new(s.x, s.y, 0.0)),
            None => Ok(object_point(w, object_index(o, w)?)),
        },
    }
}

/// The spot a target names, if it names a spot of `scene` rather than an object.
pub fn target_spot<'s>(target: &crate::kinds::Target, scene: &'s SceneSpec) -> Option<&'s Spot> {
    match target {
        crate::kinds::Target::Object(ObjectRef::Name(n)) if scene.object(n).is_none() => scene.spot(n),
        _ => None,
    }
}

/// The spot `o` names: a failure of kind `other` that lists the scene's spots for a name that
/// is not one of them (or a variable the runtime did not resolve).
pub fn spot<'s>(o: &ObjectRef, scene: &'s SceneSpec) -> Result<&'s Spot, Failure> {
    let name = match o {
        ObjectRef::Name(n) => n.as_str(),
        ObjectRef::Var(v) => {
            return Err(Failure::other(format!("the variable `{{{v}}}` was not resolved")));
        }
    };
    scene.spot(name).ok_or_else(|| {
        let names: Vec<&str> = scene.spots.iter().map(|s| s.name.as_str()).collect();
        let has = if names.is_empty() {
            "it has none".to_string()
        } else {
            format!("its spots: {}", names.join(", "))
        };
        Failure::other(format!("scene `{}` has no spot `{name}` ({has})", scene.name))
    })
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

pub use crate::world::angles::tool_yaw;

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
