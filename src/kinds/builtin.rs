//! The built-in node kinds, declared in documentation order. The leaves go through the same
//! [`Registry::declare_action`] / [`Registry::declare_condition`] calls as a user's leaves.

use super::control as c;
use super::leaves::{
    At, AtHome, Carry, CubeAt, CubeGrasped, CubeInBowl, CubeLifted, CubeOnTable, GoalMet, Grasp, Grasped,
    GripperOpen, Home, In, Lifted, MoveJoints, On, OnTable, Reach, Release,
};
use super::registry::{Category, Imp, Registry};

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

    // Actions (their controllers are bound in `crate::factory`).
    r.declare_action::<Reach>("reach", doc!("reach"))?;
    r.declare_action::<MoveJoints>("move_joints", doc!("move_joints"))?;
    r.declare_action::<Home>("home", doc!("home"))?;
    r.declare_action::<Grasp>("grasp", doc!("grasp"))?;
    r.declare_action::<Carry>("carry", doc!("carry"))?;
    r.declare_action::<Release>("release", doc!("release"))?;

    // Leaves the runtime handles itself.
    r.add("wait", Runtime, doc!("wait"), Imp::Wait)?;
    r.add("select", Runtime, doc!("select"), Imp::Select)?;

    // Conditions: pure functions of the world snapshot (their checks are bound in
    // `crate::factory`).
    r.declare_condition::<Grasped>("grasped", doc!("grasped"))?;
    r.declare_condition::<Lifted>("lifted", doc!("lifted"))?;
    r.declare_condition::<In>("in", doc!("in"))?;
    r.declare_condition::<On>("on", doc!("on"))?;
    r.declare_condition::<OnTable>("on_table", doc!("on_table"))?;
    r.declare_condition::<At>("at", doc!("at"))?;
    r.declare_condition::<GoalMet>("goal_met", doc!("goal_met"))?;
    r.declare_condition::<CubeGrasped>("cube_grasped", doc!("cube_grasped"))?;
    r.declare_condition::<CubeLifted>("cube_lifted", doc!("cube_lifted"))?;
    r.declare_condition::<CubeInBowl>("cube_in_bowl", doc!("cube_in_bowl"))?;
    r.declare_condition::<CubeOnTable>("cube_on_table", doc!("cube_on_table"))?;
    r.declare_condition::<CubeAt>("cube_at", doc!("cube_at"))?;
    r.declare_condition::<GripperOpen>("gripper_open", doc!("gripper_open"))?;
    r.declare_condition::<AtHome>("at_home", doc!("at_home"))?;
    Ok(())
}
