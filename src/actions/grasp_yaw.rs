//! [`block_grasp_yaw`]: the tool yaw for grasping a block, chosen for the fingers' clearance
//! from the objects near it.

/// Distance from another object's footprint within which the finger axis is chosen for
/// clearance, metres: an open 2F-85 reaches about 6 cm from the pinch along its finger axis.
const NEAR_CLEARANCE: f64 = 0.08;

/// Tool yaw for grasping block `b` and whether its quarter turns are equivalent.
///
/// The fingers must straddle two opposite faces, so the finger axis is the block's yaw or a
/// quarter turn from it. Far from other objects either will do (the IK picks the one nearest the
/// wrist); within [`NEAR_CLEARANCE`] of one (a container's wall, an obstacle, another block), the
/// one whose fingers point most across the direction to the nearest is taken, so the open
/// fingertips do not land on it.
pub(super) fn block_grasp_yaw(w: &crate::world::World, b: usize) -> (f64, bool) {
    let yaw = w.yaw(b);
    let p = w.objects[b].pos;
    let nearest = (0..w.objects.len())
        .filter(|&j| j != b)
        .map(|j| {
            // The offset from object j's footprint, turned back into the world frame.
            let local = w.from_footprint(j, &p);
            let (s, c) = crate::world::angles::yaw_of(&w.objects[j].quat).sin_cos();
            nalgebra::Vector2::new(c * local.x - s * local.y, s * local.x + c * local.y)
        })
        .filter(|away| away.norm() > 0.0)
        .min_by(|a, b| a.norm().total_cmp(&b.norm()));
    let Some(away) = nearest.filter(|a| a.norm() < NEAR_CLEARANCE) else {
        return (yaw, true);
    };
    let toward = away.normalize();
    // At tool yaw ψ the pads separate along (cos ψ, sin ψ) in the table plane.
    let along = |psi: f64| (psi.cos() * toward.x + psi.sin() * toward.y).abs();
    let other = yaw + std::f64::consts::FRAC_PI_2;
    (if along(yaw) <= along(other) { yaw } else { other }, false)
}
