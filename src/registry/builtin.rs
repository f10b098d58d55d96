//! The built-in node kinds, registered in documentation order. The leaves go through the same
//! [`Registry::register_action`] / [`Registry::register_condition`] calls as a user's leaves.

use super::control as c;
use super::{Category, Imp, Registry};
use crate::actions::{CarryAction, GraspAction, MoveJointsAction, ReachAction, ReleaseAction, object_index};
use crate::spec::leaves::{
    At, AtHome, Carry, CubeAt, CubeGrasped, CubeInBowl, CubeLifted, CubeOnTable, GoalMet, Grasp, Grasped,
    GripperOpen, Home, In, Lifted, MoveJoints, On, OnTable, Reach, Release,
};
use crate::world::conditions::{self as cond, Tolerances};
use crate::world::{World, goal};

macro_rules! doc {
    ($kind:literal) => {
        include_str!(concat!("../../docs/nodes/", $kind, ".md"))
    };
}

macro_rules! control {
    ($reg:expr, $kind:literal, $category:expr, $params:path, $schema:path) => {
        $reg.add(
            $kind,
            $category,
            doc!($kind),
            Imp::Control {
                params: $params,
                schema: $schema,
            },
        )
    };
}

fn obj(w: &World, o: &crate::spec::ObjectRef) -> Result<usize, String> {
    object_index(o, w)
}

/// Every built-in kind.
pub(super) fn registry() -> Registry {
    let mut r = Registry::empty();
    register(&mut r).expect("the built-in node kinds register (names unique, docs complete)");
    r
}

fn register(r: &mut Registry) -> Result<(), crate::error::Error> {
    use Category::{Composite, Decorator, Runtime};
    control!(r, "sequence", Composite, c::composite_params, c::composite_schema)?;
    control!(r, "fallback", Composite, c::composite_params, c::composite_schema)?;
    control!(
        r,
        "reactive_sequence",
        Composite,
        c::composite_params,
        c::composite_schema
    )?;
    control!(
        r,
        "reactive_fallback",
        Composite,
        c::composite_params,
        c::composite_schema
    )?;
    control!(r, "parallel", Composite, c::composite_params, c::composite_schema)?;
    control!(r, "race", Composite, c::composite_params, c::composite_schema)?;
    control!(r, "guard", Decorator, c::guard_params, c::guard_schema)?;
    control!(r, "retry", Decorator, c::retry_params, c::retry_schema)?;
    control!(r, "repeat", Decorator, c::repeat_params, c::repeat_schema)?;
    control!(r, "for_each", Decorator, c::for_each_params, c::for_each_schema)?;
    control!(r, "timeout", Decorator, c::timeout_params, c::timeout_schema)?;
    control!(r, "inverter", Decorator, c::child_params, c::child_schema)?;
    control!(r, "force_success", Decorator, c::child_params, c::child_schema)?;
    control!(r, "force_failure", Decorator, c::child_params, c::child_schema)?;
    control!(r, "subtree", Decorator, c::subtree_params, c::subtree_schema)?;

    // Actions.
    r.register_action("reach", doc!("reach"), |p: &Reach| {
        Box::new(ReachAction::new(p.clone()))
    })?;
    r.register_action("move_joints", doc!("move_joints"), |p: &MoveJoints| {
        Box::new(MoveJointsAction::new(p.joints))
    })?;
    r.register_action(
        "home",
        doc!("home"),
        |_: &Home| Box::new(MoveJointsAction::home()),
    )?;
    r.register_action("grasp", doc!("grasp"), |p: &Grasp| {
        Box::new(GraspAction::new(p.clone()))
    })?;
    r.register_action("carry", doc!("carry"), |p: &Carry| {
        Box::new(CarryAction::new(p.clone()))
    })?;
    r.register_action("release", doc!("release"), |p: &Release| {
        Box::new(ReleaseAction::new(p.clone()))
    })?;

    // Leaves the runtime handles itself.
    r.add("wait", Runtime, doc!("wait"), Imp::Wait)?;
    r.add("select", Runtime, doc!("select"), Imp::Select)?;

    // Conditions: pure functions of the world snapshot.
    r.register_condition("grasped", doc!("grasped"), |w, p: &Grasped| {
        Ok(w.holds(obj(w, &p.object)?, p.off_axis))
    })?;
    r.register_condition("lifted", doc!("lifted"), |w, p: &Lifted| {
        Ok(w.bottom(obj(w, &p.object)?) >= p.min_height)
    })?;
    r.register_condition("in", doc!("in"), |w, p: &In| {
        Ok(goal::rests_in(
            w,
            obj(w, &p.object)?,
            obj(w, &p.container)?,
            p.rest_speed,
        ))
    })?;
    r.register_condition("on", doc!("on"), |w, p: &On| {
        Ok(goal::rests_on(
            w,
            obj(w, &p.object)?,
            obj(w, &p.support)?,
            p.rest_speed,
        ))
    })?;
    r.register_condition("on_table", doc!("on_table"), |w, p: &OnTable| {
        Ok(cond::on_table(w, obj(w, &p.object)?, p.tolerance, p.rest_speed))
    })?;
    r.register_condition("at", doc!("at"), |w, p: &At| {
        let i = obj(w, &p.object)?;
        let pos = w.objects[i].pos;
        let near = (pos.x - p.point[0]).hypot(pos.y - p.point[1]) <= p.tolerance;
        let turned = p.yaw.is_none_or(|target| {
            crate::world::snapshot::fold_quarter_turn(w.yaw(i) - target.0).abs() <= p.yaw_tolerance
        });
        Ok(cond::on_table(w, i, Tolerances::ON_TABLE_HEIGHT, p.rest_speed) && near && turned)
    })?;
    r.register_condition("goal_met", doc!("goal_met"), |w, p: &GoalMet| {
        Ok(match &p.object {
            Some(o) => goal::done(w, obj(w, o)?),
            None => goal::goal_holds(w),
        })
    })?;
    r.register_condition("cube_grasped", doc!("cube_grasped"), |w, p: &CubeGrasped| {
        Ok(cond::cube_grasped(w, p.off_axis))
    })?;
    r.register_condition("cube_lifted", doc!("cube_lifted"), |w, p: &CubeLifted| {
        Ok(cond::cube_lifted(w, p.min_height))
    })?;
    r.register_condition("cube_in_bowl", doc!("cube_in_bowl"), |w, p: &CubeInBowl| {
        Ok(cond::cube_in_bowl(w, p.rest_speed))
    })?;
    r.register_condition("cube_on_table", doc!("cube_on_table"), |w, p: &CubeOnTable| {
        Ok(cond::cube_on_table(w, p.tolerance, p.rest_speed))
    })?;
    r.register_condition("cube_at", doc!("cube_at"), |w, p: &CubeAt| {
        let turned = p.yaw.is_none_or(|target| {
            crate::world::snapshot::fold_quarter_turn(w.cube_yaw() - target.0).abs() <= p.yaw_tolerance
        });
        Ok(turned && cond::cube_at(w, p.point, p.tolerance, Tolerances::ON_TABLE_HEIGHT, p.rest_speed))
    })?;
    r.register_condition("gripper_open", doc!("gripper_open"), |w, p: &GripperOpen| {
        Ok(cond::gripper_open(w, p.min_width))
    })?;
    r.register_condition("at_home", doc!("at_home"), |w, p: &AtHome| {
        Ok(cond::at_home(w, p.tolerance))
    })?;
    Ok(())
}
