//! The built-in leaves' controllers and checks.

use super::{BindError, Factory};
use crate::actions::{
    CarryAction, GraspAction, MoveJointsAction, PlaceAction, ReachAction, ReleaseAction, object_index, spot,
};
use crate::kinds::{
    At, AtHome, Carry, CubeAt, CubeGrasped, CubeInBowl, CubeLifted, CubeOnTable, GoalMet, Grasp, Grasped,
    GripperOpen, Home, In, Lifted, MoveJoints, ObjectRef, On, OnTable, Place, Reach, Release,
};
use crate::world::conditions as cond;
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
        Box::new(MoveJointsAction::new(p.joints).with_budget(p.plan_budget()))
    })?;
    f.bind_action("home", |p: &Home| {
        Box::new(MoveJointsAction::home().with_budget(p.plan_budget()))
    })?;
    f.bind_action("grasp", |p: &Grasp| Box::new(GraspAction::new(p.clone())))?;
    f.bind_action("carry", |p: &Carry| Box::new(CarryAction::new(p.clone())))?;
    f.bind_action("release", |p: &Release| Box::new(ReleaseAction::new(p.clone())))?;
    f.bind_action("place", |p: &Place| Box::new(PlaceAction::new(p.clone())))?;
    #[cfg(feature = "policy")]
    {
        // `until:` is a built-in condition, answered by the built-in checks (the factory is
        // built by then: the closure runs when a leaf checks, never while binding).
        let check: crate::actions::policy::ConditionCheck =
            std::sync::Arc::new(|call: &crate::kinds::LeafCall, w: &World| Factory::builtin().check(call, w));
        f.bind_action("policy", move |p: &crate::kinds::Policy| {
            Box::new(crate::actions::policy::PolicyAction::new(
                p.clone(),
                check.clone(),
            ))
        })?;
    }

    // Conditions: pure functions of the world snapshot.
    f.bind_condition("grasped", |w, p: &Grasped| {
        Ok(cond::grasped(w, obj(w, &p.object)?, p.off_axis))
    })?;
    f.bind_condition("lifted", |w, p: &Lifted| {
        Ok(cond::lifted(w, obj(w, &p.object)?, p.min_height))
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
        let point = match (&p.point, &p.spot) {
            (Some(point), _) => *point,
            (None, Some(s)) => {
                let s = spot(s, &w.scene)?;
                [s.x, s.y]
            }
            (None, None) => {
                return Err(crate::failure::Failure::other(
                    "`at` has neither a point nor a spot",
                ));
            }
        };
        Ok(cond::at(
            w,
            obj(w, &p.object)?,
            point,
            p.tolerance,
            p.yaw.map(|a| a.0),
            p.yaw_tolerance,
            p.rest_speed,
        ))
    })?;
    f.bind_condition("goal_met", |w, p: &GoalMet| {
        Ok(match &p.object {
            Some(o) => goal::done(w, obj(w, o)?),
            None => goal::goal_holds(w),
        })
    })?;
    // The legacy `cube_*` conditions: the general ones on the scene's cube (and bowl).
    f.bind_condition("cube_grasped", |w, p: &CubeGrasped| {
        Ok(cond::grasped(w, w.require_cube()?, p.off_axis))
    })?;
    f.bind_condition("cube_lifted", |w, p: &CubeLifted| {
        Ok(cond::lifted(w, w.require_cube()?, p.min_height))
    })?;
    f.bind_condition("cube_in_bowl", |w, p: &CubeInBowl| {
        Ok(goal::rests_in(
            w,
            w.require_cube()?,
            w.require_bowl()?,
            p.rest_speed,
        ))
    })?;
    f.bind_condition("cube_on_table", |w, p: &CubeOnTable| {
        Ok(cond::on_table(w, w.require_cube()?, p.tolerance, p.rest_speed))
    })?;
    f.bind_condition("cube_at", |w, p: &CubeAt| {
        Ok(cond::at(
            w,
            w.require_cube()?,
            p.point,
            p.tolerance,
            p.yaw.map(|a| a.0),
            p.yaw_tolerance,
            p.rest_speed,
        ))
    })?;
    f.bind_condition("gripper_open", |w, p: &GripperOpen| {
        Ok(cond::gripper_open(w, p.min_width))
    })?;
    f.bind_condition("at_home", |w, p: &AtHome| Ok(cond::at_home(w, p.tolerance)))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use nalgebra::{UnitQuaternion, Vector3};

    use super::*;
    use crate::kinds::{Leaf, Registry};
    use crate::world::tests_support::{HALF, held, resting};

    /// The answer of the condition `yaml` (`{kind: {params}}`) in `w`.
    fn ask(w: &World, yaml: &str) -> Result<bool, crate::failure::Failure> {
        let mut sources = crate::yaml::diag::Sources::new();
        let id = sources.add("t.yaml", yaml);
        let v = crate::yaml::value::parse_yaml(yaml, id).unwrap();
        let (key, body) = &v.as_map().unwrap()[0];
        let registry = Registry::builtin();
        let ty = registry.entry(key.as_str().unwrap()).unwrap();
        let Some(Ok(Leaf::Condition(call))) = ty.parse_leaf(body) else {
            panic!("{yaml} is not a condition");
        };
        factory().check(&call, w).unwrap()
    }

    /// Worlds that tell the conditions apart: resting, held, lifted, in the bowl, in a turned
    /// bowl near its corner (inside in the bowl's frame, outside along world axes), on the rim,
    /// sliding, turned, beside the bowl.
    fn worlds() -> Vec<World> {
        let mut out = vec![resting(), held()];
        let mut in_bowl = resting();
        in_bowl.objects[0].pos = Vector3::new(0.47, 0.06, 0.01 + HALF);
        out.push(in_bowl.clone());
        let mut turned = in_bowl.clone();
        turned.objects[1].quat = UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_4);
        turned.objects[0].pos = Vector3::new(0.45, 0.08 + 0.05 * std::f64::consts::SQRT_2, 0.01 + HALF);
        out.push(turned.clone());
        turned.objects[0].pos.x += 0.03;
        out.push(turned);
        let mut rim = in_bowl.clone();
        rim.objects[0].pos.x = 0.53;
        out.push(rim);
        let mut sliding = resting();
        sliding.objects[0].linvel = Vector3::new(0.2, 0.0, 0.0);
        out.push(sliding);
        let mut yawed = resting();
        yawed.objects[0].quat = UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3);
        out.push(yawed);
        let mut beside = resting();
        beside.objects[0].pos = Vector3::new(0.45, 0.08 - 0.085 - 0.005, HALF);
        out.push(beside);
        out
    }

    #[test]
    fn the_cube_conditions_answer_exactly_as_the_general_ones_on_the_only_block_and_container() {
        let pairs = [
            ("cube_grasped: {}", "grasped: {object: cube}"),
            (
                "cube_grasped: {off_axis: 0.004}",
                "grasped: {object: cube, off_axis: 0.004}",
            ),
            ("cube_lifted: {}", "lifted: {object: cube}"),
            (
                "cube_lifted: {min_height: 0.09}",
                "lifted: {object: cube, min_height: 0.09}",
            ),
            ("cube_in_bowl: {}", "in: {object: cube, container: bowl}"),
            (
                "cube_in_bowl: {rest_speed: 0.5}",
                "in: {object: cube, container: bowl, rest_speed: 0.5}",
            ),
            ("cube_on_table: {}", "on_table: {object: cube}"),
            (
                "cube_on_table: {tolerance: 0.2}",
                "on_table: {object: cube, tolerance: 0.2}",
            ),
            (
                "cube_at: {point: [0.45, -0.18]}",
                "at: {object: cube, point: [0.45, -0.18]}",
            ),
            (
                "cube_at: {point: [0.45, -0.18], yaw: 0.3, yaw_tolerance: 0.01}",
                "at: {object: cube, point: [0.45, -0.18], yaw: 0.3, yaw_tolerance: 0.01}",
            ),
            (
                "cube_at: {point: [0.45, -0.18], yaw: 0, yaw_tolerance: 0.01}",
                "at: {object: cube, point: [0.45, -0.18], yaw: 0, yaw_tolerance: 0.01}",
            ),
        ];
        let mut answers = std::collections::BTreeSet::new();
        for (i, w) in worlds().iter().enumerate() {
            for (alias, general) in pairs {
                let a = ask(w, alias).unwrap();
                assert_eq!(
                    a,
                    ask(w, general).unwrap(),
                    "world #{i}: `{alias}` vs `{general}`"
                );
                answers.insert((alias, a));
            }
        }
        // Every alias was seen both true and false, so the comparison could fail.
        for (alias, _) in pairs {
            assert!(
                answers.contains(&(alias, true)) && answers.contains(&(alias, false)),
                "`{alias}` always answered the same"
            );
        }
    }

    #[test]
    fn cube_in_bowl_reads_the_bowls_frame_when_the_bowl_is_turned() {
        // Inside in the bowl's frame (local (0.05, 0.05) m, room 0.053 m), outside along world
        // axes (world offset 0.0707 m in y): the old world-axis check said no.
        let w = &worlds()[3];
        assert!(ask(w, "cube_in_bowl: {}").unwrap());
        assert!(!ask(&worlds()[4], "cube_in_bowl: {}").unwrap());
    }

    #[test]
    fn the_cube_conditions_fail_with_a_reason_on_a_scene_without_a_cube() {
        let mut w = resting();
        w.scene = std::sync::Arc::new(
            crate::scene::SceneSpec::from_str(
                "objects:\n  a: {block: {size: 0.044}, pose: [0.45, -0.18]}\n  b: {block: {size: 0.044}, pose: [0.45, 0.08]}\n",
                "two.yaml",
            )
            .unwrap(),
        );
        let e = ask(&w, "cube_lifted: {}").unwrap_err();
        assert_eq!(e.kind, crate::failure::FailureKind::Other);
        assert!(e.message.contains("has no cube"), "{e}");
        let e = ask(&w, "cube_in_bowl: {}").unwrap_err();
        assert!(
            e.message.contains("no cube") || e.message.contains("no bowl"),
            "{e}"
        );
    }
}
