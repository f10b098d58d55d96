//! `reach`: move the pinch to a pose above/at a target, tool pointing down.

use nalgebra::Vector3;

use super::cell::Cell;
use super::macro_action::{Arrival, MacroAction, Progress};
use super::targets::{resolve, target_block, tool_yaw};
use crate::motion::{CartesianMove, JointMove, MotionLimits, down_pose, ik_down};
use crate::spec::{PathKind, Reach as ReachSpec, Target, Yaw};

/// Executes a [`ReachSpec`].
pub struct Reach {
    spec: ReachSpec,
    goal_q: [f64; 6],
    arrival: Arrival,
}

impl Reach {
    /// A reach controller for `spec`.
    pub fn new(spec: ReachSpec) -> Self {
        Self {
            spec,
            goal_q: [0.0; 6],
            arrival: Arrival::default(),
        }
    }
}

impl MacroAction for Reach {
    fn start(&mut self, cell: &mut Cell) -> Result<(), String> {
        let w = cell.world();
        let offset = Vector3::from(self.spec.offset);
        let position = resolve(&self.spec.target, w)? + offset;
        let current_yaw = tool_yaw(&w.pinch_rot);
        let (yaw, quarter) = match (&self.spec.yaw, &self.spec.target) {
            (Yaw::Object, Target::Cube) => grasp_yaw(w),
            (Yaw::Object, t) => match target_block(t, w) {
                Some(b) => block_grasp_yaw(w, b),
                None => (current_yaw, false),
            },
            (Yaw::Keep, _) => (current_yaw, false),
            (Yaw::Angle(a), _) => (*a, false),
        };
        let from = cell.arm_setpoint();
        let goal_q = ik_down(&position, yaw, quarter, &from).map_err(|e| format!("unreachable: {e}"))?;
        let limits = MotionLimits {
            tool_speed: self.spec.speed,
            ..MotionLimits::default()
        };
        match self.spec.path {
            PathKind::Joint => cell.track(Box::new(JointMove::new(from, goal_q, &limits))),
            PathKind::Cartesian => {
                let pose = down_pose(&position, yaw_of_solution(&goal_q));
                let mv =
                    CartesianMove::new(from, pose, &limits).map_err(|e| format!("unreachable path: {e}"))?;
                cell.track(Box::new(mv));
            }
        }
        self.goal_q = goal_q;
        Ok(())
    }

    fn update(&mut self, cell: &mut Cell) -> Progress {
        self.arrival.progress(cell, &self.goal_q)
    }
}

/// Distance from the bowl within which the finger axis is chosen for clearance, metres: an open
/// 2F-85 reaches about 6 cm from the pinch along its finger axis.
const BOWL_CLEARANCE: f64 = 0.08;

/// Tool yaw for grasping the cube and whether its quarter turns are equivalent.
///
/// The fingers must straddle two opposite faces, so the finger axis is the cube's yaw or a quarter
/// turn from it. Far from the bowl either will do (the IK picks the one nearest the wrist); near it,
/// the one whose fingers point most across the direction to the bowl is taken, so the open
/// fingertips do not land on its wall.
fn grasp_yaw(w: &crate::world::World) -> (f64, bool) {
    let yaw = w.cube_yaw();
    let away = w.from_bowl(&w.cube_pos);
    if away.norm() >= BOWL_CLEARANCE || away.norm() == 0.0 {
        return (yaw, true);
    }
    let toward_bowl = away.normalize();
    // At tool yaw ψ the pads separate along (cos ψ, sin ψ) in the table plane.
    let along = |psi: f64| (psi.cos() * toward_bowl.x + psi.sin() * toward_bowl.y).abs();
    let other = yaw + std::f64::consts::FRAC_PI_2;
    (if along(yaw) <= along(other) { yaw } else { other }, false)
}

/// Tool yaw for grasping block `b` (any scene) and whether its quarter turns are equivalent: as
/// [`grasp_yaw`], with the nearest other object (container wall, obstacle or block) within
/// [`BOWL_CLEARANCE`] of the block in place of the bowl.
fn block_grasp_yaw(w: &crate::world::World, b: usize) -> (f64, bool) {
    let yaw = w.yaw(b);
    let p = w.objects[b].pos;
    let nearest = (0..w.objects.len())
        .filter(|&j| j != b)
        .map(|j| {
            // The offset from object j's footprint, turned back into the world frame.
            let local = w.from_footprint(j, &p);
            let (s, c) = crate::world::snapshot::yaw_of(&w.objects[j].quat).sin_cos();
            nalgebra::Vector2::new(c * local.x - s * local.y, s * local.x + c * local.y)
        })
        .filter(|away| away.norm() > 0.0)
        .min_by(|a, b| a.norm().total_cmp(&b.norm()));
    let Some(away) = nearest.filter(|a| a.norm() < BOWL_CLEARANCE) else {
        return (yaw, true);
    };
    let toward = away.normalize();
    let along = |psi: f64| (psi.cos() * toward.x + psi.sin() * toward.y).abs();
    let other = yaw + std::f64::consts::FRAC_PI_2;
    (if along(yaw) <= along(other) { yaw } else { other }, false)
}

/// The tool yaw that joint solution `q` gives, radians.
fn yaw_of_solution(q: &[f64; 6]) -> f64 {
    tool_yaw(crate::motion::fk(q).rotation.to_rotation_matrix().matrix())
}
