//! Where a motion goes and how: the [`Target`], [`Yaw`] and [`PathKind`] parameters of the motion
//! leaves.

use std::borrow::Cow;
use std::fmt;

use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize};

use crate::motion::ur5e::SHOULDER_HEIGHT;
use crate::yaml::suggest::did_you_mean;
use crate::yaml::units::{Angle, Coordinate, bare_angle, parse_angle_text, within_reach};

/// Where a motion goes: one of the scene's objects, or a fixed point.
///
/// YAML: an object's name (`red`, `bin`), a blackboard variable (`{block}`), or `[x, y, z]` in
/// world metres. `cube` and `bowl` are the legacy names of the `cube_bowl` scene: the block called
/// `cube` (else the scene's only block) and the container called `bowl` (else its only container).
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// The legacy `cube`: its current pose.
    Cube,
    /// The legacy `bowl`: its current pose.
    Bowl,
    /// A scene object (by name or blackboard variable): its current pose.
    Object(super::objects::ObjectRef),
    /// A fixed point in the world frame, metres.
    Point([f64; 3]),
}

struct TargetVisitor;

impl<'de> Visitor<'de> for TargetVisitor {
    type Value = Target;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(
            "an object (`red`, `cube`, `bowl`), a variable (`{block}`) or a point `[x, y, z]` in metres",
        )
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Target, E> {
        match v {
            "cube" => Ok(Target::Cube),
            "bowl" => Ok(Target::Bowl),
            _ => super::objects::ObjectRef::parse(v)
                .map(Target::Object)
                .map_err(|e| E::custom(format!("{e}; a target is an object, a variable or `[x, y, z]`"))),
        }
    }
    fn visit_map<A: de::MapAccess<'de>>(self, map: A) -> Result<Target, A::Error> {
        super::objects::var_from_map(map).map(Target::Object)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Target, A::Error> {
        let mut p = [0.0; 3];
        for (i, slot) in p.iter_mut().enumerate() {
            let x: Coordinate<true> = seq
                .next_element()?
                .ok_or_else(|| de::Error::invalid_length(i, &"a point [x, y, z] in metres"))?;
            *slot = x.0;
        }
        if seq.next_element::<de::IgnoredAny>()?.is_some() {
            return Err(de::Error::invalid_length(4, &"a point [x, y, z] in metres"));
        }
        if p[2] < 0.0 {
            return Err(de::Error::custom(format!(
                "the point [{}, {}, {}] is below the table top (z = 0 m)",
                p[0], p[1], p[2]
            )));
        }
        let from_shoulder = (p[0] * p[0] + p[1] * p[1] + (p[2] - SHOULDER_HEIGHT).powi(2)).sqrt();
        within_reach(from_shoulder, || {
            format!(
                "the point [{}, {}, {}], {from_shoulder:.2} m from the shoulder,",
                p[0], p[1], p[2]
            )
        })?;
        Ok(Target::Point(p))
    }
}

impl<'de> Deserialize<'de> for Target {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TargetVisitor)
    }
}

impl JsonSchema for Target {
    fn schema_name() -> Cow<'static, str> {
        "Target".into()
    }
    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        json_schema!({
            "description": "An object of the scene (`red`; `cube` and `bowl` name the scene's only block and container), a blackboard variable (`{block}`), or a fixed point `[x, y, z]` in world metres.",
            "anyOf": [
                {"type": "string", "pattern": "^([a-z][a-z0-9_]*|\\{\\s*[A-Za-z_][A-Za-z0-9_]*\\s*\\})$"},
                {"type": "object", "minProperties": 1, "maxProperties": 1, "additionalProperties": {"type": "null"}},
                {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}
            ]
        })
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Target::Cube => f.write_str("cube"),
            Target::Bowl => f.write_str("bowl"),
            Target::Object(o) => write!(f, "{o}"),
            Target::Point([x, y, z]) => write!(f, "[{x}, {y}, {z}]"),
        }
    }
}

/// The gripper's yaw (rotation about the world vertical) at the end of a `reach`.
///
/// YAML: `object` (default), `keep`, or an angle (`1.57`, `deg(90)`).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Yaw {
    /// Match the target object's yaw (modulo 90°) so the fingers straddle two opposite faces.
    #[default]
    Object,
    /// Keep the current tool yaw.
    Keep,
    /// This absolute yaw in the world frame, radians.
    Angle(f64),
}

struct YawVisitor;

impl Visitor<'_> for YawVisitor {
    type Value = Yaw;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("`object`, `keep`, or an angle (radians, or `deg(90)`)")
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Yaw, E> {
        bare_angle(v as f64, true).map(Yaw::Angle)
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Yaw, E> {
        bare_angle(v as f64, true).map(Yaw::Angle)
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Yaw, E> {
        bare_angle(v, false).map(Yaw::Angle)
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Yaw, E> {
        match v {
            "object" => Ok(Yaw::Object),
            "keep" => Ok(Yaw::Keep),
            _ => parse_angle_text(v).map(Yaw::Angle).map_err(|_| {
                let mut msg =
                    format!("unknown yaw `{v}`: expected `object`, `keep` or an angle like `deg(90)`");
                if let Some(h) = did_you_mean(v, ["object", "keep"]) {
                    msg.push_str(&format!(" ({h})"));
                }
                E::custom(msg)
            }),
        }
    }
}

impl<'de> Deserialize<'de> for Yaw {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(YawVisitor)
    }
}

impl JsonSchema for Yaw {
    fn schema_name() -> Cow<'static, str> {
        "Yaw".into()
    }
    fn json_schema(g: &mut SchemaGenerator) -> Schema {
        let angle = g.subschema_for::<Angle>();
        json_schema!({
            "description": "`object` (match the target object's yaw so the fingers straddle two faces), `keep` (keep the current tool yaw), or an absolute yaw angle.",
            "anyOf": [
                {"type": "string", "enum": ["object", "keep"]},
                angle
            ]
        })
    }
}

/// How a `reach` moves the arm.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema, Default)]
#[serde(rename_all = "snake_case")]
pub enum PathKind {
    /// Interpolate in joint space (fast, the tool path is curved).
    #[default]
    Joint,
    /// Straight line of the tool centre point in Cartesian space (for the final approach).
    Cartesian,
}
