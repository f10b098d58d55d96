//! `policy`: a learned controller (an ONNX model) as a leaf — what the kind *is*. How it runs
//! (ONNX Runtime, the features, the commands) is `crate::actions::policy`.

use std::sync::{Arc, OnceLock};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::leaf_call::LeafCall;
use super::leaves::{At, AtHome, GoalMet, Grasped, GripperOpen, In, Lifted, On, OnTable, fmt_num};
use super::objects::{ObjectRef, ObjectRole};
use super::params::{DynParams, Params};
use super::registry::Registry;
use crate::yaml::units;

/// The failure kind of a model whose output is not finite or asks for joint angles outside the
/// UR5e's limits.
pub const POLICY_OUTPUT_INVALID: &str = "policy_output_invalid";

/// Longest time between two model calls a tree may set, seconds.
pub const MAX_POLICY_PERIOD: f64 = 1.0;

/// Most actions of a chunk a tree may execute before the model runs again.
pub const MAX_ACTION_STEPS: u32 = 1000;

fn d_timeout() -> f64 {
    10.0
}

fn d_max_joint_speed() -> f64 {
    crate::motion::MotionLimits::default().max_joint_speed
}

#[doc = include_str!("../../docs/nodes/policy.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Policy {
    /// The ONNX model file, relative to the tree file that names it and inside its folder (the
    /// rule of `include:`). The loader replaces it with the file's canonical path, and the
    /// file is one of the tree's inputs (its digest, `--resume`, `report`).
    pub model: String,
    /// The object the model's `observation.object` input describes (a name or `{var}`), so one
    /// learned skill serves whichever block the blackboard selects.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object: Option<ObjectRef>,
    /// The condition that ends the leaf with success, checked after every control period (one of
    /// the built-in conditions, e.g. `{grasped: {object: "{block}"}}`). Without it the leaf runs
    /// until its `timeout` (a failure) or until a decorator or a reactive parent halts it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub until: Option<Until>,
    /// Give up (failure `timeout`) after this many simulated seconds (> 0). Default 10.
    #[serde(default = "d_timeout", deserialize_with = "units::time_limit")]
    #[schemars(range(min = 0.0))]
    pub timeout: f64,
    /// Seconds between two model calls, each action reached linearly over one period (0 to 1;
    /// a whole number of control periods). Default: the model's `macrotree.period` metadata,
    /// else one control period.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "opt_period"
    )]
    #[schemars(range(min = 0.0, max = MAX_POLICY_PERIOD))]
    pub period: Option<f64>,
    /// For a model that outputs a chunk of actions (`[1, k, n]`): how many of them run before
    /// the model runs again (1 to k). Default: the whole chunk.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 1, max = MAX_ACTION_STEPS))]
    pub n_action_steps: Option<u32>,
    /// Fastest joint motion the leaf commands, rad/s (> 0, at most the UR5e's rated π); faster
    /// set points are clamped. Default 3, the scripted leaves' limit.
    #[serde(default = "d_max_joint_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0, max = crate::motion::ur5e::RATED_JOINT_SPEED))]
    pub max_joint_speed: f64,
}

fn opt_period<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    let x = units::time_limit(d)?;
    if x > MAX_POLICY_PERIOD {
        return Err(serde::de::Error::custom(format!(
            "a policy period is at most {MAX_POLICY_PERIOD} s, found `{x}`"
        )));
    }
    Ok(Some(x))
}

/// The built-in condition that ends a `policy` leaf with success (`until:`), written as the
/// condition leaf itself: `{grasped: {object: "{block}"}}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Until {
    /// `grasped`: the gripper holds the block.
    Grasped(Grasped),
    /// `lifted`: the block is off the table.
    Lifted(Lifted),
    /// `in`: the block rests in the container.
    In(In),
    /// `on`: the block rests on the support.
    On(On),
    /// `on_table`: the block rests on the table.
    OnTable(OnTable),
    /// `at`: the block rests at a point or spot.
    At(At),
    /// `gripper_open`: the fingers are open.
    GripperOpen(GripperOpen),
    /// `at_home`: the arm is at its home configuration.
    AtHome(AtHome),
    /// `goal_met`: the scene's goal holds.
    GoalMet(GoalMet),
}

impl Until {
    fn kind(&self) -> &'static str {
        match self {
            Until::Grasped(_) => "grasped",
            Until::Lifted(_) => "lifted",
            Until::In(_) => "in",
            Until::On(_) => "on",
            Until::OnTable(_) => "on_table",
            Until::At(_) => "at",
            Until::GripperOpen(_) => "gripper_open",
            Until::AtHome(_) => "at_home",
            Until::GoalMet(_) => "goal_met",
        }
    }

    fn params(&self) -> Arc<dyn DynParams> {
        match self {
            Until::Grasped(p) => Arc::new(p.clone()),
            Until::Lifted(p) => Arc::new(p.clone()),
            Until::In(p) => Arc::new(p.clone()),
            Until::On(p) => Arc::new(p.clone()),
            Until::OnTable(p) => Arc::new(p.clone()),
            Until::At(p) => Arc::new(p.clone()),
            Until::GripperOpen(p) => Arc::new(p.clone()),
            Until::AtHome(p) => Arc::new(p.clone()),
            Until::GoalMet(p) => Arc::new(p.clone()),
        }
    }

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        match self {
            Until::Grasped(p) => p.objects_mut(),
            Until::Lifted(p) => p.objects_mut(),
            Until::In(p) => p.objects_mut(),
            Until::On(p) => p.objects_mut(),
            Until::OnTable(p) => p.objects_mut(),
            Until::At(p) => p.objects_mut(),
            Until::GripperOpen(p) => p.objects_mut(),
            Until::AtHome(p) => p.objects_mut(),
            Until::GoalMet(p) => p.objects_mut(),
        }
    }

    /// The condition as a leaf of the built-in kind it names (what a condition check takes).
    pub fn call(&self) -> LeafCall {
        static BUILTIN: OnceLock<Registry> = OnceLock::new();
        let registry = BUILTIN.get_or_init(Registry::builtin);
        let ty = registry
            .entry(self.kind())
            .expect("every `until:` variant is a built-in condition")
            .clone();
        LeafCall {
            ty,
            params: self.params(),
        }
    }
}

impl Params for Policy {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[
        ("object", ObjectRole::Any),
        ("until.grasped.object", ObjectRole::Block),
        ("until.lifted.object", ObjectRole::Block),
        ("until.in.object", ObjectRole::Block),
        ("until.in.container", ObjectRole::Container),
        ("until.on.object", ObjectRole::Block),
        ("until.on.support", ObjectRole::Block),
        ("until.on_table.object", ObjectRole::Block),
        ("until.at.object", ObjectRole::Block),
        ("until.at.spot", ObjectRole::Spot),
        ("until.goal_met.object", ObjectRole::Block),
    ];
    const FILE_PARAMS: &'static [&'static str] = &["model"];

    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        let mut refs: Vec<&mut ObjectRef> = self.object.iter_mut().collect();
        if let Some(until) = &mut self.until {
            refs.extend(until.objects_mut());
        }
        refs
    }

    fn label(&self, _: &str) -> Option<String> {
        let model = std::path::Path::new(&self.model)
            .file_name()
            .map_or_else(|| self.model.clone(), |n| n.to_string_lossy().into_owned());
        let mut label = format!("policy {model}");
        if let Some(o) = &self.object {
            label.push_str(&format!(" {o}"));
        }
        if let Some(u) = &self.until {
            label.push_str(&format!(" until {}", u.call().label()));
        }
        label.push_str(&format!(" ≤{} s", fmt_num(self.timeout)));
        Some(label)
    }

    fn timeout(&self) -> Option<f64> {
        Some(self.timeout)
    }

    fn failure_kinds() -> &'static [&'static str] {
        &[POLICY_OUTPUT_INVALID]
    }
}
