//! Leaf nodes: macro actions (executed by a [`crate::runtime::LeafDriver`]), condition checks
//! (instantaneous, also answered by the driver) and `wait` (handled by the runtime itself).
//!
//! Every parameter struct rejects unknown fields, has documented units and defaults, and is
//! written in YAML as a single-key mapping, e.g. `reach: {target: cube, offset: [0, 0, 0.15]}`.
//! All leaves also accept `name:` (handled by the tree parser, not stored here).

use serde::{Deserialize, Serialize};

use schemars::JsonSchema;

use super::approach::Approach;
use super::objects::{ObjectRef, ObjectRole, opt_var_name, var_name};
use super::param_error::ParamError;
use super::targets::{PathKind, Target, Yaw};
pub use crate::kinds::{LeafCall, Params};
use crate::world::conditions::Tolerances;
use crate::world::query::{Filter, KindFilter, Order, Query};
use crate::yaml::units::{self, Angle};

fn d_zero3() -> [f64; 3] {
    [0.0, 0.0, 0.0]
}
fn d_speed() -> f64 {
    0.5
}
fn d_5() -> f64 {
    5.0
}
fn d_6() -> f64 {
    6.0
}
fn d_2() -> f64 {
    2.0
}
fn d_3() -> f64 {
    3.0
}
fn d_10() -> f64 {
    10.0
}
fn d_bowl() -> Target {
    Target::Bowl
}
fn d_lift() -> f64 {
    0.20
}
fn d_place_height() -> f64 {
    0.03
}
fn d_retreat() -> f64 {
    0.10
}
// Condition defaults live with the conditions, in `world::Tolerances`.
fn d_min_height() -> f64 {
    Tolerances::LIFT_HEIGHT
}
fn d_min_width() -> f64 {
    Tolerances::OPEN_WIDTH
}
fn d_home_tol() -> f64 {
    Tolerances::HOME_TOLERANCE
}
fn d_table_tol() -> f64 {
    Tolerances::ON_TABLE_HEIGHT
}
fn d_off_axis() -> f64 {
    Tolerances::GRASP_OFF_AXIS
}
fn d_rest_speed() -> f64 {
    Tolerances::REST_SPEED
}
/// The `at` and `cube_at` conditions default to the scene goal's `at` tolerances: one check,
/// one default ([`crate::scene::AT_TOLERANCE`], [`crate::scene::AT_YAW_TOLERANCE`]).
fn d_point_tol() -> f64 {
    crate::scene::AT_TOLERANCE
}

/// Most collision checks a leaf's `max_checks` may give one plan.
pub const MAX_PLAN_CHECKS: u64 = 10_000_000;

/// Declares the parameters of a leaf that plans: the struct as written, with the planning
/// budget's two fields appended (`max_checks`, `plan_time_cap`: declared once here, with their
/// documentation and ranges), and its [`PlanBudget`].
macro_rules! planning_leaf {
    ($(#[$meta:meta])* pub struct $name:ident { $($body:tt)* }) => {
        $(#[$meta])*
        pub struct $name {
            $($body)*
            /// Collision checks the planner may spend when the leaf's direct motion would
            /// collide (1 to 10 000 000); a search that uses them up fails with `no_path`.
            /// Default: the planner's own budget (20 000).
            #[serde(default, skip_serializing_if = "Option::is_none")]
            #[schemars(range(min = 1, max = MAX_PLAN_CHECKS))]
            pub max_checks: Option<u64>,
            /// Wall-clock seconds a plan may take before it fails with `no_path` (0.001 to 60).
            /// The only outcome that depends on the machine's speed; `max_checks` ends searches
            /// first on any machine not stalled tenfold. Default 2.
            #[serde(
                default,
                deserialize_with = "units::opt_plan_time_cap",
                skip_serializing_if = "Option::is_none"
            )]
            #[schemars(range(min = units::PLAN_TIME_CAP_RANGE.lo, max = units::PLAN_TIME_CAP_RANGE.hi))]
            pub plan_time_cap: Option<f64>,
        }

        impl $name {
            /// The leaf's planning budget (its `max_checks` and `plan_time_cap`).
            pub fn plan_budget(&self) -> PlanBudget {
                PlanBudget {
                    max_checks: self.max_checks,
                    time_cap: self.plan_time_cap,
                }
            }
        }
    };
}

planning_leaf! {
#[doc = include_str!("../../docs/nodes/reach.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Reach {
    /// What to reach: an object (`red`, `cube`, `bowl`), a variable `{block}`, or `[x, y, z]`
    /// (world metres).
    pub target: Target,
    /// Offset of the tool centre point from the target, world frame, metres. Default `[0, 0, 0]`.
    #[serde(default = "d_zero3", deserialize_with = "units::vec3")]
    pub offset: [f64; 3],
    /// Final tool yaw: `object` (default: match the target object's yaw so the fingers straddle
    /// two faces), `keep`, or an angle (radians or `deg(..)`).
    #[serde(default)]
    pub yaw: Yaw,
    /// `joint` (default, joint-space interpolation) or `cartesian` (straight tool path).
    #[serde(default)]
    pub path: PathKind,
    /// `top` (default: tool pointing down), `side` (tool horizontal along a face normal of the
    /// target block, `offset` in that approach's frame) or `auto` (`top` when its pre-grasp and
    /// descent are free, else `side`); see docs/motion.md "Side grasps".
    #[serde(default, skip_serializing_if = "Approach::is_top")]
    pub approach: Approach,
    /// Tool speed along straight lines (`cartesian`, the descent), m/s (> 0); a joint move or a
    /// planned path keeps the joint limits. Default 0.5.
    #[serde(default = "d_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub speed: f64,
    /// Give up (Failure) after this many simulated seconds (> 0). Default 5.
    #[serde(default = "d_5", deserialize_with = "units::time_limit")]
    #[schemars(range(min = 0.0))]
    pub timeout: f64,
}
}

planning_leaf! {
#[doc = include_str!("../../docs/nodes/move_joints.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MoveJoints {
    /// Six joint angles, radians (numbers or `deg(..)`/`rad(..)`).
    #[serde(deserialize_with = "units::joints6")]
    #[schemars(with = "[units::Angle; 6]")]
    pub joints: [f64; 6],
    /// Give up after this many simulated seconds (> 0). Default 6.
    #[serde(default = "d_6", deserialize_with = "units::time_limit")]
    #[schemars(range(min = 0.0))]
    pub timeout: f64,
}
}

planning_leaf! {
#[doc = include_str!("../../docs/nodes/home.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Home {
    /// Give up after this many simulated seconds (> 0). Default 6.
    #[serde(default = "d_6", deserialize_with = "units::time_limit")]
    #[schemars(range(min = 0.0))]
    pub timeout: f64,
}
}

impl Default for Home {
    fn default() -> Self {
        Self {
            timeout: 6.0,
            max_checks: None,
            plan_time_cap: None,
        }
    }
}

#[doc = include_str!("../../docs/nodes/grasp.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Grasp {
    /// The block that must end up held (a name or `{var}`). Absent: any block between the pads.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object: Option<ObjectRef>,
    /// Close to this pad-to-pad width, metres (≥ 0). Absent: close until contact/stall.
    #[serde(default, deserialize_with = "units::opt_opening")]
    #[schemars(range(min = 0.0, max = units::MAX_OPENING))]
    pub width: Option<f64>,
    /// Give up after this many simulated seconds (> 0). Default 2.
    #[serde(default = "d_2", deserialize_with = "units::time_limit")]
    #[schemars(range(min = 0.0))]
    pub timeout: f64,
}

impl Default for Grasp {
    fn default() -> Self {
        Self {
            object: None,
            width: None,
            timeout: 2.0,
        }
    }
}

planning_leaf! {
#[doc = include_str!("../../docs/nodes/carry.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Carry {
    /// Where to: an object (a container: onto its floor; a block: on top of it, for stacking),
    /// a variable `{dest}`, or `[x, y, z]` (world metres). Default `bowl`.
    #[serde(default = "d_bowl")]
    pub to: Target,
    /// Height of the cube's bottom above the table during the transfer, metres (≥ 0). Default 0.20.
    #[serde(default = "d_lift", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub lift: f64,
    /// Height of the cube's bottom above the target when the carry ends, metres (≥ 0). Default 0.03.
    #[serde(default = "d_place_height", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub place_height: f64,
    /// Speed of the held block, m/s (> 0), along the lift, the set-down and the transfer,
    /// straight or planned (the joint move a transfer falls back to where no straight line can
    /// be made keeps the joint limits). Default 0.5.
    #[serde(default = "d_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub speed: f64,
    /// Give up after this many simulated seconds (> 0). Default 10.
    #[serde(default = "d_10", deserialize_with = "units::time_limit")]
    #[schemars(range(min = 0.0))]
    pub timeout: f64,
}
}

fn d_15() -> f64 {
    15.0
}

/// `point: [x, y]` for an optional field (range-checked like any point on the table).
fn opt_point<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
    units::vec2(d).map(Some)
}

planning_leaf! {
#[doc = include_str!("../../docs/nodes/place.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Place {
    /// Where the block's centre goes, `[x, y]` on the table, world metres (give `point` or
    /// `spot`). It is set down on whatever is under the point: the table, the top of a block or
    /// an obstacle, a container's floor.
    #[serde(
        default,
        deserialize_with = "opt_point",
        skip_serializing_if = "Option::is_none"
    )]
    pub point: Option<[f64; 2]>,
    /// A named spot of the scene (`spots:`) or a variable holding one (`{where}`, e.g. written
    /// by `select … goal_as` for an `at` goal), instead of `point`; its yaw is the default `yaw`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spot: Option<ObjectRef>,
    /// The block's yaw when set down: an angle (radians or `deg(..)`, modulo 90°) or `keep`.
    /// Default: the spot's yaw for a `spot`, `keep` for a `point`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yaw: Option<Yaw>,
    /// Height of the block's bottom above the table during the transfer, metres (≥ 0). Default 0.20.
    #[serde(default = "d_lift", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub lift: f64,
    /// Vertical retreat after the fingers open, metres (≥ 0). Default 0.10.
    #[serde(default = "d_retreat", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub retreat: f64,
    /// Speed of the held block, m/s (> 0), along the lift, the set-down and the transfer,
    /// straight or planned (the joint move a transfer falls back to where no straight line can
    /// be made keeps the joint limits). Default 0.5.
    #[serde(default = "d_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub speed: f64,
    /// Give up after this many simulated seconds (> 0). Default 15.
    #[serde(default = "d_15", deserialize_with = "units::time_limit")]
    #[schemars(range(min = 0.0))]
    pub timeout: f64,
}
}

#[doc = include_str!("../../docs/nodes/release.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Release {
    /// Opening to go to, metres (pad face to pad face, 0 … 0.085). Default: fully open (≈ 0.085).
    #[serde(default, deserialize_with = "units::opt_opening")]
    #[schemars(range(min = 0.0, max = units::MAX_OPENING))]
    pub width: Option<f64>,
    /// Vertical retreat after opening, metres (≥ 0). Default 0.10.
    #[serde(default = "d_retreat", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub retreat: f64,
    /// Give up after this many simulated seconds (> 0). Default 3.
    #[serde(default = "d_3", deserialize_with = "units::time_limit")]
    #[schemars(range(min = 0.0))]
    pub timeout: f64,
}

#[doc = include_str!("../../docs/nodes/wait.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Wait {
    /// Simulated seconds (≥ 0).
    #[serde(deserialize_with = "units::duration")]
    #[schemars(range(min = 0.0))]
    pub seconds: f64,
}

#[doc = include_str!("../../docs/nodes/cube_grasped.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CubeGrasped {
    /// Largest distance of the cube's centre from the line between the pad centres, metres
    /// (≥ 0). Default 0.03.
    #[serde(default = "d_off_axis", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub off_axis: f64,
}

impl Default for CubeGrasped {
    fn default() -> Self {
        Self {
            off_axis: d_off_axis(),
        }
    }
}

#[doc = include_str!("../../docs/nodes/cube_lifted.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CubeLifted {
    /// Metres above the table (≥ 0). Default 0.03.
    #[serde(default = "d_min_height", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub min_height: f64,
}

impl Default for CubeLifted {
    fn default() -> Self {
        Self {
            min_height: d_min_height(),
        }
    }
}

#[doc = include_str!("../../docs/nodes/cube_in_bowl.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CubeInBowl {
    /// Cube speed below which it counts as at rest, m/s (> 0). Default 0.05.
    #[serde(default = "d_rest_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub rest_speed: f64,
}

impl Default for CubeInBowl {
    fn default() -> Self {
        Self {
            rest_speed: d_rest_speed(),
        }
    }
}

#[doc = include_str!("../../docs/nodes/cube_on_table.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CubeOnTable {
    /// Allowed height of the cube's bottom above the table top, metres (≥ 0). Default 0.01.
    #[serde(default = "d_table_tol", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub tolerance: f64,
    /// Cube speed below which it counts as at rest, m/s (> 0). Default 0.05.
    #[serde(default = "d_rest_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub rest_speed: f64,
}

impl Default for CubeOnTable {
    fn default() -> Self {
        Self {
            tolerance: d_table_tol(),
            rest_speed: d_rest_speed(),
        }
    }
}

#[doc = include_str!("../../docs/nodes/cube_at.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CubeAt {
    /// Where the cube's centre should rest, `[x, y]` on the table, world metres.
    #[serde(deserialize_with = "units::vec2")]
    pub point: [f64; 2],
    /// Largest horizontal distance of the cube's centre from `point`, metres (≥ 0). Default 0.01.
    #[serde(default = "d_point_tol", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub tolerance: f64,
    /// The yaw the cube's faces should have (radians or `deg(..)`, modulo 90°). Absent: any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yaw: Option<Angle>,
    /// Largest yaw error when `yaw` is given, radians (or `deg(..)`). Default 5°, as the scene
    /// goal's `at`.
    #[serde(default = "d_yaw_tol", deserialize_with = "units::angle_tolerance")]
    #[schemars(with = "units::Angle")]
    pub yaw_tolerance: f64,
    /// Cube speed below which it counts as at rest, m/s (> 0). Default 0.05.
    #[serde(default = "d_rest_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub rest_speed: f64,
}

#[doc = include_str!("../../docs/nodes/gripper_open.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GripperOpen {
    /// Metres (≥ 0). Default 0.08.
    #[serde(default = "d_min_width", deserialize_with = "units::opening")]
    #[schemars(range(min = 0.0, max = units::MAX_OPENING))]
    pub min_width: f64,
}

impl Default for GripperOpen {
    fn default() -> Self {
        Self {
            min_width: d_min_width(),
        }
    }
}

#[doc = include_str!("../../docs/nodes/at_home.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AtHome {
    /// Joint-space distance to home (Euclidean norm over the six joints), radians (≥ 0;
    /// `deg(..)` accepted). Default 0.04.
    #[serde(default = "d_home_tol", deserialize_with = "units::angle_tolerance")]
    #[schemars(with = "units::Angle")]
    pub tolerance: f64,
}

impl Default for AtHome {
    fn default() -> Self {
        Self {
            tolerance: d_home_tol(),
        }
    }
}

fn d_yaw_tol() -> f64 {
    crate::scene::AT_YAW_TOLERANCE
}

#[doc = include_str!("../../docs/nodes/grasped.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Grasped {
    /// The block (a name or `{var}`).
    pub object: ObjectRef,
    /// Largest distance of the block's centre from the line between the pad centres, metres
    /// (≥ 0). Default 0.03.
    #[serde(default = "d_off_axis", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub off_axis: f64,
}

#[doc = include_str!("../../docs/nodes/lifted.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Lifted {
    /// The block (a name or `{var}`).
    pub object: ObjectRef,
    /// Height of the block's lowest point above the table, metres (≥ 0). Default 0.03.
    #[serde(default = "d_min_height", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub min_height: f64,
}

#[doc = include_str!("../../docs/nodes/in.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct In {
    /// The block (a name or `{var}`).
    pub object: ObjectRef,
    /// The container (a name or `{var}`).
    pub container: ObjectRef,
    /// Speed below which the block counts as at rest, m/s (> 0). Default 0.05.
    #[serde(default = "d_rest_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub rest_speed: f64,
}

#[doc = include_str!("../../docs/nodes/on.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct On {
    /// The block on top (a name or `{var}`).
    pub object: ObjectRef,
    /// What it rests on: a block, or an obstacle's top (a shelf board, a pedestal) (a name or
    /// `{var}`).
    pub support: ObjectRef,
    /// Speed below which the block counts as at rest, m/s (> 0). Default 0.05.
    #[serde(default = "d_rest_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub rest_speed: f64,
}

#[doc = include_str!("../../docs/nodes/on_table.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OnTable {
    /// The block (a name or `{var}`).
    pub object: ObjectRef,
    /// Allowed height of the block's bottom above the table top, metres (≥ 0). Default 0.01.
    #[serde(default = "d_table_tol", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub tolerance: f64,
    /// Speed below which the block counts as at rest, m/s (> 0). Default 0.05.
    #[serde(default = "d_rest_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub rest_speed: f64,
}

#[doc = include_str!("../../docs/nodes/at.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct At {
    /// The block (a name or `{var}`).
    pub object: ObjectRef,
    /// Where its centre should rest, `[x, y]` on the table, world metres (give `point` or
    /// `spot`).
    #[serde(
        default,
        deserialize_with = "opt_point",
        skip_serializing_if = "Option::is_none"
    )]
    pub point: Option<[f64; 2]>,
    /// A named spot of the scene (`spots:`) or a variable holding one (`{where}`), instead of
    /// `point`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spot: Option<ObjectRef>,
    /// Largest horizontal distance of its centre from the point, metres (≥ 0). Default 0.01.
    #[serde(default = "d_point_tol", deserialize_with = "units::distance")]
    #[schemars(range(min = 0.0, max = units::MAX_REACH))]
    pub tolerance: f64,
    /// The yaw its faces should have (radians or `deg(..)`, compared modulo 90°). Absent: any
    /// (also for a `spot`: its yaw is checked only when `yaw` is given, as in the scene goal).
    #[serde(default)]
    pub yaw: Option<Angle>,
    /// Largest yaw error when `yaw` is given, radians (or `deg(..)`). Default 5°, as the scene
    /// goal's `at`.
    #[serde(default = "d_yaw_tol", deserialize_with = "units::angle_tolerance")]
    #[schemars(with = "units::Angle")]
    pub yaw_tolerance: f64,
    /// Speed below which the block counts as at rest, m/s (> 0). Default 0.05.
    #[serde(default = "d_rest_speed", deserialize_with = "units::speed")]
    #[schemars(range(min = 0.0))]
    pub rest_speed: f64,
}

#[doc = include_str!("../../docs/nodes/goal_met.md")]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema, Default)]
#[serde(deny_unknown_fields)]
pub struct GoalMet {
    /// Only this block's goal predicate (a name or `{var}`). Absent: the whole goal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub object: Option<ObjectRef>,
}

#[doc = include_str!("../../docs/nodes/select.md")]
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Select {
    /// The variable the selected object's name is written to (`block` → read it as `{block}`).
    #[serde(rename = "as", deserialize_with = "var_name")]
    pub var: String,
    /// Also write where the object's goal sends it (a container or a block) to this variable.
    #[serde(
        default,
        rename = "goal_as",
        deserialize_with = "opt_var_name",
        skip_serializing_if = "Option::is_none"
    )]
    pub goal_var: Option<String>,
    /// `block` (default), `container` or `obstacle`.
    #[serde(default)]
    pub kind: KindFilter,
    /// Only objects of this colour name (`red`, …).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<String>,
    /// Conditions every selected object meets: `pending`, `done`, `on_table`, `free`.
    #[serde(default, rename = "where", skip_serializing_if = "Vec::is_empty")]
    pub filters: Vec<Filter>,
    /// Which match is taken: `nearest` (default) to the gripper, first by `name`, or in `scene` order.
    #[serde(default)]
    pub order: Order,
}

impl Select {
    /// The query part.
    pub fn query(&self) -> Query {
        Query {
            kind: self.kind,
            color: self.color.clone(),
            filters: self.filters.clone(),
            order: self.order,
        }
    }
}

/// A leaf of the tree, with all parameters resolved.
///
/// Drivers see only [`Leaf::Action`] and [`Leaf::Condition`]; [`Leaf::Wait`] and
/// [`Leaf::Select`] are handled by the runtime. Actions and conditions are [`LeafCall`]s of a
/// registered kind (see [`crate::kinds`]): read their parameters with
/// [`Leaf::params`], e.g. `leaf.params::<Reach>()`.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Leaf {
    /// A macro action (multi-tick).
    Action(LeafCall),
    /// A condition (instantaneous).
    Condition(LeafCall),
    /// `wait: {seconds}` (runtime-internal).
    Wait(Wait),
    /// `select: {as, …}`: picks an object through the driver and writes the blackboard
    /// (runtime-internal).
    Select(Select),
}

impl Leaf {
    /// The YAML node kind (`reach`, `cube_grasped`, `wait`, …).
    pub fn kind(&self) -> &'static str {
        match self {
            Leaf::Action(c) | Leaf::Condition(c) => c.kind(),
            Leaf::Wait(_) => "wait",
            Leaf::Select(_) => "select",
        }
    }

    /// The parameters of an action or condition, if they are of type `P` (e.g. [`Reach`]).
    pub fn params<P: Params>(&self) -> Option<&P> {
        match self {
            Leaf::Action(c) | Leaf::Condition(c) => c.params::<P>(),
            _ => None,
        }
    }

    /// The action or condition call (`None` for `wait` and `select`).
    pub fn call(&self) -> Option<&LeafCall> {
        match self {
            Leaf::Action(c) | Leaf::Condition(c) => Some(c),
            _ => None,
        }
    }

    /// Every object reference of the leaf (targets, `object:`, `container:`, `support:`).
    pub fn object_refs(&self) -> Vec<ObjectRef> {
        self.call().map(LeafCall::object_refs).unwrap_or_default()
    }

    /// The leaf with object references replaced where `f` answers `Some`; `None` when nothing
    /// was replaced (the leaf is cloned only when it reads a variable).
    pub fn map_objects(&self, f: &mut dyn FnMut(&ObjectRef) -> Option<ObjectRef>) -> Option<Leaf> {
        if !self.has_vars() {
            return None;
        }
        match self {
            Leaf::Action(c) => c.map_objects(f).map(Leaf::Action),
            Leaf::Condition(c) => c.map_objects(f).map(Leaf::Condition),
            _ => None,
        }
    }

    /// True when the leaf reads a blackboard variable.
    pub fn has_vars(&self) -> bool {
        self.object_refs().iter().any(|o| matches!(o, ObjectRef::Var(_)))
    }

    /// True for condition leaves (instantaneous checks).
    pub fn is_condition(&self) -> bool {
        matches!(self, Leaf::Condition(_))
    }

    /// Compact one-line rendering of the parameters (JSON), for logs and diagrams.
    pub fn params_json(&self) -> String {
        match self {
            Leaf::Action(c) | Leaf::Condition(c) => c.params_json().to_string(),
            Leaf::Wait(w) => serde_json::to_string(w).unwrap_or_else(|_| "{}".into()),
            Leaf::Select(s) => serde_json::to_string(s).unwrap_or_else(|_| "{}".into()),
        }
    }
}

fn target_mut(t: &mut Target) -> Vec<&mut ObjectRef> {
    match t {
        Target::Object(o) => vec![o],
        _ => vec![],
    }
}

fn fmt_target(t: &Target) -> String {
    match t {
        Target::Point(p) => fmt_vec(p),
        other => other.to_string(),
    }
}

/// A number with at most 3 decimals, trailing zeros dropped (for labels).
pub(crate) fn fmt_num(x: f64) -> String {
    let s = format!("{x:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

/// `[a, b, c]` with [`fmt_num`] numbers.
pub(crate) fn fmt_vec(v: &[f64]) -> String {
    format!(
        "[{}]",
        v.iter().map(|x| fmt_num(*x)).collect::<Vec<_>>().join(", ")
    )
}

impl Params for Reach {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("target", ObjectRole::Any)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        target_mut(&mut self.target)
    }
    fn label(&self, _: &str) -> Option<String> {
        let mut s = format!("reach {}", fmt_target(&self.target));
        if self.offset != [0.0; 3] {
            s.push_str(&format!(" +{}", fmt_vec(&self.offset)));
        }
        if self.path == PathKind::Cartesian {
            s.push_str(" cartesian");
        }
        if !self.approach.is_top() {
            s.push_str(&format!(" from {}", self.approach.name()));
        }
        match self.yaw {
            Yaw::Object => {}
            Yaw::Keep => s.push_str(" yaw=keep"),
            Yaw::Angle(a) => s.push_str(&format!(" yaw={}°", fmt_num(a.to_degrees()))),
        }
        Some(s)
    }
    fn timeout(&self) -> Option<f64> {
        Some(self.timeout)
    }
    fn validate_fields(&self) -> Result<(), ParamError> {
        super::approach::check_reach(self.approach, &self.target, &self.offset, &self.yaw)?;
        check_max_checks(self.max_checks)
    }
}

impl Params for MoveJoints {
    fn label(&self, _: &str) -> Option<String> {
        Some(format!("move_joints {}", fmt_vec(&self.joints)))
    }
    fn timeout(&self) -> Option<f64> {
        Some(self.timeout)
    }
    fn validate_fields(&self) -> Result<(), ParamError> {
        check_max_checks(self.max_checks)
    }
}

/// What a leaf that plans lets its plans spend: its `max_checks` and `plan_time_cap`
/// parameters (`None`: the defaults of the leaves, 20 000 checks and 2 s).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanBudget {
    /// Collision checks per plan, 1 to 10 000 000.
    pub max_checks: Option<u64>,
    /// Wall-clock seconds per plan, 0.001 to 60.
    pub time_cap: Option<f64>,
}

/// The `max_checks` parameter of a leaf that plans: 1 to 10 000 000 collision checks.
fn check_max_checks(max_checks: Option<u64>) -> Result<(), ParamError> {
    match max_checks {
        Some(n) if !(1..=MAX_PLAN_CHECKS).contains(&n) => Err(ParamError::at(
            "max_checks",
            format!("`max_checks` must be between 1 and {MAX_PLAN_CHECKS} collision checks, found {n}"),
        )),
        _ => Ok(()),
    }
}

impl Params for Home {
    fn timeout(&self) -> Option<f64> {
        Some(self.timeout)
    }
    fn validate_fields(&self) -> Result<(), ParamError> {
        check_max_checks(self.max_checks)
    }
}

impl Params for Grasp {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        self.object.iter_mut().collect()
    }
    fn label(&self, _: &str) -> Option<String> {
        self.width.map(|w| format!("grasp width={} m", fmt_num(w)))
    }
    fn timeout(&self) -> Option<f64> {
        Some(self.timeout)
    }
}

impl Params for Carry {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("to", ObjectRole::Any)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        target_mut(&mut self.to)
    }
    fn label(&self, _: &str) -> Option<String> {
        Some(format!(
            "carry to {} lift={} m",
            fmt_target(&self.to),
            fmt_num(self.lift)
        ))
    }
    fn timeout(&self) -> Option<f64> {
        Some(self.timeout)
    }
    fn validate_fields(&self) -> Result<(), ParamError> {
        check_max_checks(self.max_checks)
    }
}

impl Params for Place {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("spot", ObjectRole::Spot)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        self.spot.iter_mut().collect()
    }
    fn label(&self, _: &str) -> Option<String> {
        let mut s = match (&self.point, &self.spot) {
            (Some(p), _) => format!("place at {}", fmt_vec(p)),
            (None, Some(spot)) => format!("place at {spot}"),
            (None, None) => "place".to_string(),
        };
        match self.yaw {
            Some(Yaw::Angle(a)) => s.push_str(&format!(" yaw={}°", fmt_num(a.to_degrees()))),
            Some(Yaw::Keep) => s.push_str(" yaw=keep"),
            _ => {}
        }
        Some(s)
    }
    fn timeout(&self) -> Option<f64> {
        Some(self.timeout)
    }
    fn validate_fields(&self) -> Result<(), ParamError> {
        match (&self.point, &self.spot) {
            (Some(_), Some(_)) => {
                return Err(ParamError::at("spot", "give `point` or `spot`, not both"));
            }
            (None, None) => {
                return Err(ParamError::new(
                    "`place` needs where: `point: [x, y]` (metres) or `spot: NAME` (a spot of the scene)",
                ));
            }
            _ => {}
        }
        if self.yaw == Some(Yaw::Object) {
            return Err(ParamError::at(
                "yaw",
                "`object` is not a place yaw: give an angle (`deg(90)`) or `keep`",
            ));
        }
        check_max_checks(self.max_checks)
    }
}

impl Params for Release {
    fn label(&self, _: &str) -> Option<String> {
        Some(format!("release retreat={} m", fmt_num(self.retreat)))
    }
    fn timeout(&self) -> Option<f64> {
        Some(self.timeout)
    }
}

impl Params for CubeGrasped {}
impl Params for CubeInBowl {}
impl Params for CubeOnTable {}
impl Params for AtHome {}

impl Params for CubeLifted {
    fn label(&self, _: &str) -> Option<String> {
        Some(format!("cube_lifted ≥{} m", fmt_num(self.min_height)))
    }
}

impl Params for GripperOpen {
    fn label(&self, _: &str) -> Option<String> {
        Some(format!("gripper_open ≥{} m", fmt_num(self.min_width)))
    }
}

impl Params for CubeAt {
    fn label(&self, _: &str) -> Option<String> {
        Some(format!(
            "cube_at? [{}, {}] ±{} m",
            fmt_num(self.point[0]),
            fmt_num(self.point[1]),
            fmt_num(self.tolerance)
        ))
    }
}

impl Params for Grasped {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }
}

impl Params for Lifted {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }
}

impl Params for In {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[
        ("object", ObjectRole::Block),
        ("container", ObjectRole::Container),
    ];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object, &mut self.container]
    }
}

impl Params for On {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] =
        &[("object", ObjectRole::Block), ("support", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object, &mut self.support]
    }
}

impl Params for OnTable {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        vec![&mut self.object]
    }
}

impl Params for At {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] =
        &[("object", ObjectRole::Block), ("spot", ObjectRole::Spot)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        let mut refs = vec![&mut self.object];
        refs.extend(self.spot.iter_mut());
        refs
    }
    fn validate_fields(&self) -> Result<(), ParamError> {
        match (&self.point, &self.spot) {
            (Some(_), Some(_)) => Err(ParamError::at("spot", "give `point` or `spot`, not both")),
            (None, None) => Err(ParamError::new(
                "`at` needs where: `point: [x, y]` (metres) or `spot: NAME` (a spot of the scene)",
            )),
            _ => Ok(()),
        }
    }
}

impl Params for GoalMet {
    const OBJECT_PARAMS: &'static [(&'static str, ObjectRole)] = &[("object", ObjectRole::Block)];
    fn objects_mut(&mut self) -> Vec<&mut ObjectRef> {
        self.object.iter_mut().collect()
    }
}
