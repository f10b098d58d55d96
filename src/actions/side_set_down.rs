//! A block held from the side, set down: refused before anything moves when the gripper itself
//! would have to go into the surface.
//!
//! Held from the side, the block is at the height of the tool axis, and the 2F-85's base reaches
//! 3.75 cm below that axis (docs/motion.md, *Side grasps*): lowered onto the table or a bin's
//! floor, a block smaller than 7.5 cm would put the gripper into the surface before the block
//! reaches it. The set-down is straight and the destination's floor is contact the set-down
//! intends, so the motion checks alone would let the gripper run into it; this check asks the
//! collision checker about the set-down's end instead, for every turn of the hand and every arm
//! configuration, and counts only the robot's own parts (not the held block) in the surface.

use nalgebra::Isometry3;

use super::planning::names;
use crate::failure::{Failure, FailureKind};
use crate::motion::plan::{Collision, CollisionChecker, GoalSet};
use crate::sim::SceneChecker;

/// Cosine of the largest angle between the tool's approach axis and the vertical for a hold
/// that counts as "from above" (45°).
const FROM_ABOVE_COS: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// True when the tool's approach axis (its z axis, `rotation` in the world frame) is nearer
/// horizontal than vertical: the block is held from the side.
pub(crate) fn held_from_side(rotation: &nalgebra::UnitQuaternion<f64>) -> bool {
    (rotation * nalgebra::Vector3::z()).z.abs() < FROM_ABOVE_COS
}

/// `Err(goal_in_collision)` when at every one of `poses` (the tool at the set-down's end, one per
/// turn of the hand) every IK branch (seeded at `from`, radians) has a robot part other than the
/// block `held` inside `surface` (the destination object, or `table`) or the table; the message
/// names the deepest pair of the configuration that goes least deep, and says what to do
/// instead.
pub(crate) fn refuse_side_set_down(
    checker: &mut SceneChecker,
    poses: &[Isometry3<f64>],
    from: &[f64; 6],
    held: &str,
    surface: &str,
) -> Result<(), Failure> {
    let mut deepest: Option<Collision> = None;
    for q in GoalSet::poses(poses, from).configs {
        let into: Vec<Collision> = checker
            .collisions(&q)
            .into_iter()
            .filter(|c| c.distance < 0.0 && !names(c, held) && (names(c, surface) || names(c, "table")))
            .collect();
        let Some(worst) = into.into_iter().min_by(|a, b| a.distance.total_cmp(&b.distance)) else {
            return Ok(());
        };
        // The configuration that goes least deep is the one to report.
        if deepest.as_ref().is_none_or(|d| worst.distance > d.distance) {
            deepest = Some(worst);
        }
    }
    let Some(d) = deepest else {
        // No arm configuration at all: the set-down's own motion says so, with its reason.
        return Ok(());
    };
    Err(Failure::new(
        FailureKind::GoalInCollision,
        format!(
            "a block held from the side cannot be set down on `{surface}`: at the set-down `{}` would be {:.1} mm inside `{}` in every arm configuration and turn of the hand; set it down on something narrower than the block (a pedestal, with `place`) and grasp it again from above",
            d.a,
            -d.distance * 1e3,
            d.b
        ),
    ))
}
