//! The built-in leaves' controllers and checks.

use super::{BindError, Factory};
use crate::actions::{CarryAction, GraspAction, MoveJointsAction, ReachAction, ReleaseAction, object_index};
use crate::kinds::{
    At, AtHome, Carry, CubeAt, CubeGrasped, CubeInBowl, CubeLifted, CubeOnTable, GoalMet, Grasp, Grasped,
    GripperOpen, Home, In, Lifted, MoveJoints, ObjectRef, On, OnTable, Reach, Release,
};
use crate::world::conditions::{self as cond, Tolerances};
use crate::world::{World, goal};

fn obj(w: &World, o: &ObjectRef) -> Result<usize, crate::failure::Failure> {
    object_index(o, w)
}

/// Every built-in binding.
pub(super) fn factory() -> Factory {
    let mut f = Factory::default();
    bind(&mut f).expect("the built-in leaves bind once each");
    f
}

fn bind(f: &mut Factory) -> Result<(), BindError> {
    // Actions.
    f.bind_action("reach", |p: &Reach| Box::new(ReachAction::new(p.clone())))?;
    f.bind_action("move_joints", |p: &MoveJoints| {
        Box::new(MoveJointsAction::new(p.joints))
    })?;
    f.bind_action("home", |_: &Home| Box::new(MoveJointsAction::home()))?;
    f.bind_action("grasp", |p: &Grasp| Box::new(GraspAction::new(p.clone())))?;
    f.bind_action("carry", |p: &Carry| Box::new(CarryAction::new(p.clone())))?;
    f.bind_action("release", |p: &Release| Box::new(ReleaseAction::new(p.clone())))?;

    // Conditions: pure functions of the world snapshot.
    f.bind_condition("grasped", |w, p: &Grasped| {
        Ok(w.holds(obj(w, &p.object)?, p.off_axis))
    })?;
    f.bind_condition("lifted", |w, p: &Lifted| {
        Ok(w.bottom(obj(w, &p.object)?) >= p.min_height)
    })?;
    f.bind_condition("in", |w, p: &In| {
        Ok(goal::rests_in(
            w,
            obj(w, &p.object)?,
            obj(w, &p.container)?,
            p.rest_speed,
        ))
    })?;
    f.bind_condition("on", |w, p: &On| {
        Ok(goal::rests_on(
            w,
            obj(w, &p.object)?,
            obj(w, &p.support)?,
            p.rest_speed,
        ))
    })?;
    f.bind_condition("on_table", |w, p: &OnTable| {
        Ok(cond::on_table(w, obj(w, &p.object)?, p.tolerance, p.rest_speed))
    })?;
    f.bind_condition("at", |w, p: &At| {
        let i = obj(w, &p.object)?;
        let pos = w.objects[i].pos;
        let near = (pos.x - p.point[0]).hypot(pos.y - p.point[1]) <= p.tolerance;
        let turned = p.yaw.is_none_or(|target| {
            crate::world::snapshot::fold_quarter_turn(w.yaw(i) - target.0).abs() <= p.yaw_tolerance
        });
        Ok(cond::on_table(w, i, Tolerances::ON_TABLE_HEIGHT, p.rest_speed) && near && turned)
    })?;
    f.bind_condition("goal_met", |w, p: &GoalMet| {
        Ok(match &p.object {
            Some(o) => goal::done(w, obj(w, o)?),
            None => goal::goal_holds(w),
        })
    })?;
    f.bind_condition("cube_grasped", |w, p: &CubeGrasped| {
        Ok(cond::cube_grasped(w, p.off_axis))
    })?;
    f.bind_condition("cube_lifted", |w, p: &CubeLifted| {
        Ok(cond::cube_lifted(w, p.min_height))
    })?;
    f.bind_condition("cube_in_bowl", |w, p: &CubeInBowl| {
        Ok(cond::cube_in_bowl(w, p.rest_speed))
    })?;
    f.bind_condition("cube_on_table", |w, p: &CubeOnTable| {
        Ok(cond::cube_on_table(w, p.tolerance, p.rest_speed))
    })?;
    f.bind_condition("cube_at", |w, p: &CubeAt| {
        let turned = p.yaw.is_none_or(|target| {
            crate::world::snapshot::fold_quarter_turn(w.cube_yaw() - target.0).abs() <= p.yaw_tolerance
        });
        Ok(turned && cond::cube_at(w, p.point, p.tolerance, Tolerances::ON_TABLE_HEIGHT, p.rest_speed))
    })?;
    f.bind_condition("gripper_open", |w, p: &GripperOpen| {
        Ok(cond::gripper_open(w, p.min_width))
    })?;
    f.bind_condition("at_home", |w, p: &AtHome| Ok(cond::at_home(w, p.tolerance)))?;
    Ok(())
}
