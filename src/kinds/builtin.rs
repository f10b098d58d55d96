//! The built-in node kinds, declared in documentation order. The leaves go through the same
//! [`Registry::declare_action`] / [`Registry::declare_condition`] calls as a user's leaves.
//!
//! This is the one declaration of each built-in kind: its name, its doc, its parameter type
//! (`super::leaves` for the leaves, `super::control` for the composites and decorators) and,
//! for an action, the [`ActionRole`] it plays. The leaves' parameter types live here in `kinds`
//! rather than beside their controllers in `actions`, because what a kind *is* (layer 4: read,
//! checked, documented and diagrammed without MuJoCo) must not depend on how it runs (layer 9);
//! `crate::factory` binds each action's controller and each condition's check to the declared
//! name.

use std::sync::OnceLock;

use super::control::{
    ChildParams, CompositeParams, ControlKind, ForEachParams, GuardParams, RepeatParams, RetryParams,
    SubtreeParams, TimeoutParams,
};
use super::leaves::{
    At, AtHome, Carry, CubeAt, CubeGrasped, CubeInBowl, CubeLifted, CubeOnTable, GoalMet, Grasp, Grasped,
    GripperOpen, Home, In, Lifted, MoveJoints, On, OnTable, Place, Reach, Release,
};
use super::registry::{Category, ControlImp, Imp, Registry};
use super::role::ActionRole;

macro_rules! doc {
    ($kind:literal) => {
        include_str!(concat!("../../docs/nodes/", $kind, ".md"))
    };
}

macro_rules! control {
    ($reg:expr, $kind:literal, $category:ident, $tag:ident, $params:ty) => {
        $reg.add(
            $kind,
            Category::$category,
            doc!($kind),
            Imp::Control(ControlImp::of::<$params>(ControlKind::$tag)),
        )
    };
}

/// Every built-in kind.
pub(super) fn registry() -> Registry {
    let mut r = Registry::empty();
    register(&mut r).expect("the built-in node kinds register (names unique, docs complete)");
    r
}

impl Registry {
    /// The built-in node kinds (composites, decorators, actions, conditions, `wait`, `select`).
    pub fn builtin() -> Registry {
        static BUILTIN: OnceLock<Registry> = OnceLock::new();
        BUILTIN.get_or_init(registry).clone()
    }
}

impl Default for Registry {
    /// The built-in node kinds.
    fn default() -> Self {
        Self::builtin()
    }
}

fn register(r: &mut Registry) -> Result<(), crate::error::Error> {
    use Category::Runtime;
    control!(r, "sequence", Composite, Sequence, CompositeParams)?;
    control!(r, "fallback", Composite, Fallback, CompositeParams)?;
    control!(
        r,
        "reactive_sequence",
        Composite,
        ReactiveSequence,
        CompositeParams
    )?;
    control!(
        r,
        "reactive_fallback",
        Composite,
        ReactiveFallback,
        CompositeParams
    )?;
    control!(r, "parallel", Composite, Parallel, CompositeParams)?;
    control!(r, "race", Composite, Race, CompositeParams)?;
    control!(r, "guard", Decorator, Guard, GuardParams)?;
    control!(r, "retry", Decorator, Retry, RetryParams)?;
    control!(r, "repeat", Decorator, Repeat, RepeatParams)?;
    control!(r, "for_each", Decorator, ForEach, ForEachParams)?;
    control!(r, "timeout", Decorator, Timeout, TimeoutParams)?;
    control!(r, "inverter", Decorator, Inverter, ChildParams)?;
    control!(r, "force_success", Decorator, ForceSuccess, ChildParams)?;
    control!(r, "force_failure", Decorator, ForceFailure, ChildParams)?;
    control!(r, "subtree", Decorator, Subtree, SubtreeParams)?;

    // Actions (their controllers are bound in `crate::factory`).
    r.declare_action_as::<Reach>("reach", doc!("reach"), ActionRole::Reach)?;
    r.declare_action::<MoveJoints>("move_joints", doc!("move_joints"))?;
    r.declare_action::<Home>("home", doc!("home"))?;
    r.declare_action_as::<Grasp>("grasp", doc!("grasp"), ActionRole::Grasp)?;
    r.declare_action_as::<Carry>("carry", doc!("carry"), ActionRole::Carry)?;
    r.declare_action_as::<Release>("release", doc!("release"), ActionRole::Release)?;
    r.declare_action_as::<Place>("place", doc!("place"), ActionRole::Carry)?;
    r.declare_action::<super::policy::Policy>("policy", doc!("policy"))?;

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
