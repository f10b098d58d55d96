//! Checked scalar parameters: lengths (m), durations (s), speeds (m/s), angles (rad), targets.
//!
//! Parameters are stored as plain `f64` in SI units; these helpers are used with
//! `#[serde(deserialize_with = ...)]` so that a bad value (non-finite, negative duration, zero
//! speed, …) is reported at its own line and column.

use std::borrow::Cow;
use std::fmt;

use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};

use super::bounds::Bounds;
use crate::motion::kinematics::TOOL_LENGTH;
use crate::motion::ur5e::{FOREARM, JOINT_LIMITS, LATERAL_OFFSET, SHOULDER_HEIGHT, UPPER_ARM, WRIST_2_TO_3};
use crate::motion::{ARM_JOINTS, gripper};

/// Upper bound on any length a tree names, metres (≈ 1.31): the UR5e's links laid end to end
/// from the shoulder to the pinch point. No point farther than this from the shoulder can be
/// reached, so a larger distance is a unit slip (centimetres for metres), reported before a
/// simulation starts. Points inside it may still be unreachable; the IK says so with a reason.
pub const MAX_REACH: f64 = UPPER_ARM + FOREARM + LATERAL_OFFSET + WRIST_2_TO_3 + TOOL_LENGTH;

/// The 2F-85's full opening between the pad faces, metres (the calibration's open end).
pub const MAX_OPENING: f64 = gripper::CALIBRATION[0].1;

/// `Ok(length)` when `length` (metres) is at most [`MAX_REACH`]; otherwise an error that
/// starts with `what` (e.g. "a distance of 5 m").
pub(crate) fn within_reach<E: de::Error>(length: f64, what: impl FnOnce() -> String) -> Result<f64, E> {
    if length > MAX_REACH {
        return Err(E::custom(format!(
            "{} exceeds the arm's full reach of {MAX_REACH:.2} m (lengths are in metres)",
            what()
        )));
    }
    Ok(length)
}

fn finite<E: de::Error>(x: f64, what: &str) -> Result<f64, E> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(E::custom(format!("{what} must be a finite number, found `{x}`")))
    }
}

fn number<'de, D: Deserializer<'de>>(d: D, what: &str) -> Result<f64, D::Error> {
    let x = f64::deserialize(d)?;
    finite(x, what)
}

/// A finite length in metres (any sign).
pub fn length<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    number(d, "a length (m)")
}

/// A finite, non-negative distance in metres, at most [`MAX_REACH`].
pub fn distance<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let x = number(d, "a distance (m)")?;
    if x < 0.0 {
        return Err(de::Error::custom(format!(
            "a distance (m) must be ≥ 0, found `{x}`"
        )));
    }
    within_reach(x, || format!("a distance of {x} m"))
}

/// An optional gripper opening between the pad faces, metres, 0 … [`MAX_OPENING`]
/// (`~` or absent = `None`).
pub fn opt_opening<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    struct Opening(f64);
    impl<'de> Deserialize<'de> for Opening {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            opening(d).map(Opening)
        }
    }
    Ok(Option::<Opening>::deserialize(d)?.map(|x| x.0))
}

/// A gripper opening between the pad faces, metres, 0 … [`MAX_OPENING`].
pub fn opening<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let x = number(d, "a gripper opening (m)")?;
    if !(0.0..=MAX_OPENING).contains(&x) {
        return Err(de::Error::custom(format!(
            "a gripper opening must be between 0 and {MAX_OPENING} m (the 2F-85 fully open), found `{x}`"
        )));
    }
    Ok(x)
}

/// A finite, non-negative duration in (simulated) seconds.
pub fn duration<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let x = number(d, "a duration (s)")?;
    if x < 0.0 {
        return Err(de::Error::custom(format!(
            "a duration (s) must be ≥ 0, found `{x}`"
        )));
    }
    Ok(x)
}

/// A finite, strictly positive time limit in (simulated) seconds.
pub fn time_limit<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let x = number(d, "a time limit (s)")?;
    if x <= 0.0 {
        return Err(de::Error::custom(format!(
            "a time limit (s) must be > 0, found `{x}`"
        )));
    }
    Ok(x)
}

/// Shortest and longest wall-clock cap of one plan a tree may set, seconds (the planner's own
/// range for `PlannerConfig::time_cap`).
pub const PLAN_TIME_CAP_RANGE: Bounds = Bounds::new(0.001, 60.0);

/// An optional wall-clock cap on one plan, seconds, within [`PLAN_TIME_CAP_RANGE`] (absent =
/// `None`).
pub fn opt_plan_time_cap<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    let x = number(d, "a planning time cap (s)")?;
    if !PLAN_TIME_CAP_RANGE.contains(x) {
        let Bounds { lo, hi } = PLAN_TIME_CAP_RANGE;
        return Err(de::Error::custom(format!(
            "a planning time cap is wall-clock seconds between {lo} and {hi}, found `{x}`"
        )));
    }
    Ok(Some(x))
}

/// A finite, strictly positive speed in m/s.
pub fn speed<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let x = number(d, "a speed (m/s)")?;
    if x <= 0.0 {
        return Err(de::Error::custom(format!(
            "a speed (m/s) must be > 0, found `{x}`"
        )));
    }
    Ok(x)
}

/// A finite, non-negative angular tolerance in radians (accepts `deg(2)` etc.).
pub fn angle_tolerance<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let x = Angle::deserialize(d)?.0;
    if x < 0.0 {
        return Err(de::Error::custom(format!(
            "an angular tolerance must be ≥ 0 rad, found `{x}`"
        )));
    }
    Ok(x)
}

/// One coordinate of a point or an offset, metres: finite and at most `limit` from 0, checked
/// while it is read so that an error points at the number itself (or at the subtree argument it
/// came from).
pub(crate) struct Coordinate<const POINT: bool>(pub(crate) f64);

impl<'de, const POINT: bool> Deserialize<'de> for Coordinate<POINT> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let x = number(d, "a coordinate (m)")?;
        coordinate(x, "a coordinate of", POINT).map(Coordinate)
    }
}

/// Checks one coordinate `x` (metres) that `what` names in a message (`a coordinate of`,
/// `x =`): at most the arm's reach from 0 — plus the shoulder's height for a `point`'s
/// coordinate, beyond which it is out of reach whatever the others are; an offset's beyond
/// the reach is too long.
pub(crate) fn coordinate<E: de::Error>(x: f64, what: &str, point: bool) -> Result<f64, E> {
    let limit = if point {
        MAX_REACH + SHOULDER_HEIGHT
    } else {
        MAX_REACH
    };
    if x.abs() > limit {
        return Err(E::custom(format!(
            "{what} {x} m is beyond the arm's full reach of {MAX_REACH:.2} m{}lengths are in metres: write {} for {x} cm",
            super::de::HELP_SEPARATOR,
            x / 100.0
        )));
    }
    Ok(x)
}

/// Three finite lengths `[x, y, z]` in metres.
pub fn vec3<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
    let v = <[Coordinate<false>; 3]>::deserialize(d)?.map(|c| c.0);
    let length = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    within_reach(length, || format!("an offset of {length:.3} m"))?;
    Ok(v)
}

/// A point on the table, `[x, y]` in world metres (finite).
pub fn vec2<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let v = <[f64; 2]>::deserialize(d)?;
    for x in v {
        finite::<D::Error>(x, "a coordinate (m)")?;
    }
    Ok(v)
}

/// Six joint angles in radians (each a number or `deg(..)`/`rad(..)`).
pub fn joints6<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 6], D::Error> {
    let v = <[Angle; 6]>::deserialize(d)?.map(|a| a.0);
    for (i, (q, (lo, hi))) in v.iter().zip(JOINT_LIMITS).enumerate() {
        if !(lo..=hi).contains(q) {
            return Err(de::Error::custom(format!(
                "joint {} (`{}`) must be within [{lo}, {hi}] rad, found `{q}`",
                i + 1,
                ARM_JOINTS[i]
            )));
        }
    }
    Ok(v)
}

/// Parse an angle written as text: `deg(90)`, `rad(1.57)`, `pi/2`, `deg(-45)`; plain numbers are
/// radians. Uses serde-saphyr's `robotics` angle evaluator. Returns radians. A `deg(x)` whose `x`
/// looks like radians raises a warning (inside a reading that collects them).
pub fn parse_angle_text(s: &str) -> Result<f64, String> {
    let t = s.trim();
    if t.is_empty() || t.len() > 200 {
        return Err(format!("`{s}` is not an angle"));
    }
    let options = serde_saphyr::options! { angle_conversions: true };
    match serde_saphyr::from_str_with_options::<f64>(t, options) {
        Ok(x) if x.is_finite() => {
            warn_degrees_like_radians(t);
            Ok(x)
        }
        Ok(x) => Err(format!("an angle must be finite, found `{x}`")),
        Err(_) => Err(format!("`{s}` is not an angle")),
    }
}

/// Largest bare angle accepted, radians (one full turn): a plain number beyond ±2π is almost
/// certainly degrees written without `deg(..)`.
pub const MAX_BARE_ANGLE: f64 = std::f64::consts::TAU;

/// Smallest whole number of radians that warns: `yaw: 3` is 171.9°, almost certainly meant as
/// degrees (radians are written as fractions of π: 1.5708, 0.785).
pub const MIN_WARNED_WHOLE_RADIANS: f64 = 2.0;

/// How close to a multiple of 15° (π/12 rad) a number written as degrees must be to look like
/// radians (`deg(1.5708)`, `--cube …,0.785`), radians.
const RADIAN_LOOK: f64 = 0.002;

/// The degrees `x` would be if it were radians, when it looks like radians although written where
/// degrees are read: not a whole number, within a full turn, and within 0.002 of a non-zero
/// multiple of π/12 (1.5708 ≈ π/2, 0.785 ≈ π/4, 3.14 ≈ π). `None` otherwise.
pub fn looks_like_radians(x: f64) -> Option<f64> {
    let step = std::f64::consts::PI / 12.0;
    let k = (x / step).round();
    (x.is_finite()
        && x.fract() != 0.0
        && x.abs() <= MAX_BARE_ANGLE
        && k != 0.0
        && (x - k * step).abs() < RADIAN_LOOK)
        .then_some(k * 15.0)
}

/// A plain number read as an angle in radians: an error beyond ±2π (with help to write `deg(..)`),
/// and a warning for a whole number of at least [`MIN_WARNED_WHOLE_RADIANS`] (`yaw: 3` is 172°,
/// probably meant as degrees).
pub(crate) fn bare_angle<E: de::Error>(x: f64, integer: bool) -> Result<f64, E> {
    named_bare_angle(x, integer, "")
}

/// [`bare_angle`] with its messages starting with `field` (e.g. `yaw: `; empty for none).
pub(crate) fn named_bare_angle<E: de::Error>(x: f64, integer: bool, field: &str) -> Result<f64, E> {
    let x = finite(x, "an angle (rad)").map_err(|e: E| E::custom(format!("{field}{e}")))?;
    if x.abs() > MAX_BARE_ANGLE {
        return Err(E::custom(format!(
            "{field}`{x}` is more than a full turn as an angle in radians ({:.0}°){}write deg({x}) for degrees, or rad({x}) if you really mean radians",
            x.to_degrees(),
            super::de::HELP_SEPARATOR
        )));
    }
    if integer && x.abs() >= MIN_WARNED_WHOLE_RADIANS {
        super::de::warn(
            format!(
                "{field}`{x}` is read as {x} rad ({:.1}°): plain numbers are radians",
                x.to_degrees()
            ),
            Some(format!(
                "write deg({x}) if you meant degrees; write rad({x}) or {x}.0 to keep radians and silence this warning"
            )),
        );
    }
    Ok(x)
}

/// Warns when `text` is `deg(x)` with an `x` that looks like radians ([`looks_like_radians`]):
/// `deg(1.5708)` is 1.57°, almost certainly meant as 90°.
fn warn_degrees_like_radians(text: &str) {
    let inner = text
        .trim()
        .strip_prefix("deg(")
        .and_then(|r| r.strip_suffix(')'))
        .and_then(|n| n.trim().parse::<f64>().ok());
    if let Some((x, deg)) = inner.and_then(|x| looks_like_radians(x).map(|d| (x, d))) {
        super::de::warn(
            format!("`{}` is {x}°, but {x} looks like radians ({deg}°)", text.trim()),
            Some(format!(
                "write {x} (a plain number is radians) or deg({deg}) for {deg}°"
            )),
        );
    }
}

/// An angle in radians. YAML accepts a plain number (radians, within ±2π) or `deg(x)` / `rad(x)`
/// (and simple expressions such as `rad(pi/2)`).
#[derive(Copy, Clone, Debug, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Angle(pub f64);

struct AngleVisitor;

impl Visitor<'_> for AngleVisitor {
    type Value = Angle;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an angle: radians as a number, or `deg(90)` / `rad(1.57)`")
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Angle, E> {
        bare_angle(v as f64, true).map(Angle)
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Angle, E> {
        bare_angle(v as f64, true).map(Angle)
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Angle, E> {
        bare_angle(v, false).map(Angle)
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Angle, E> {
        parse_angle_text(v).map(Angle).map_err(|m| {
            E::custom(format!(
                "{m}; write radians as a number, or `deg(90)` / `rad(1.57)`"
            ))
        })
    }
}

impl<'de> Deserialize<'de> for Angle {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(AngleVisitor)
    }
}

impl JsonSchema for Angle {
    fn schema_name() -> Cow<'static, str> {
        "Angle".into()
    }
    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        json_schema!({
            "description": "An angle: radians as a number, or a string `deg(90)` / `rad(1.57)` (expressions like `rad(pi/2)` work).",
            "anyOf": [
                {"type": "number"},
                {"type": "string", "pattern": "^\\s*(deg|rad)\\(.*\\)\\s*$|pi"}
            ]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[allow(clippy::approx_constant)] // rounded radians are what these tests are about
    fn a_number_looks_like_radians_near_a_multiple_of_fifteen_degrees_only() {
        assert_eq!(looks_like_radians(1.5708), Some(90.0));
        assert_eq!(looks_like_radians(0.785), Some(45.0));
        assert_eq!(looks_like_radians(-3.14), Some(-180.0));
        for x in [0.0, 1.5, 30.0, 45.0, 0.5, 90.0, 7.0, f64::NAN] {
            assert_eq!(looks_like_radians(x), None, "{x}");
        }
    }

    #[test]
    #[allow(clippy::approx_constant)] // rounded radians are what these tests are about
    fn degrees_that_look_like_radians_and_whole_radians_warn_with_the_other_reading() {
        use crate::yaml::de::{collect_warnings, from_value};
        use crate::yaml::value::parse_yaml;
        let read = |text: &str| {
            let v = parse_yaml(text, 0).unwrap();
            collect_warnings(|| from_value::<std::collections::BTreeMap<String, Angle>>(&v))
        };
        let (r, w) = read("yaw: deg(1.5708)");
        assert!((r.unwrap()["yaw"].0 - 1.5708f64.to_radians()).abs() < 1e-12);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].message.contains("looks like radians (90°)"), "{w:?}");
        assert!(w[0].help.as_deref().unwrap().contains("deg(90)"), "{w:?}");
        let (_, w) = read("yaw: 3");
        assert!(w.len() == 1 && w[0].message.contains("171.9°"), "{w:?}");
        for quiet in [
            "yaw: deg(90)",
            "yaw: 1.5708",
            "yaw: 1",
            "yaw: 3.0",
            "yaw: deg(1.5)",
        ] {
            let (r, w) = read(quiet);
            assert!(r.is_ok() && w.is_empty(), "{quiet}: {w:?}");
        }
    }

    #[test]
    fn angles() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        assert!(close(
            parse_angle_text("deg(90)").unwrap(),
            std::f64::consts::FRAC_PI_2
        ));
        assert!(close(parse_angle_text("rad(1.5)").unwrap(), 1.5));
        assert!(close(
            parse_angle_text("rad(pi/2)").unwrap(),
            std::f64::consts::FRAC_PI_2
        ));
        assert!(close(
            parse_angle_text("deg(-45)").unwrap(),
            -std::f64::consts::FRAC_PI_4
        ));
        assert!(parse_angle_text("object").is_err());
        assert!(parse_angle_text("deg(").is_err());
        assert!(parse_angle_text("[1, 2]").is_err());
        assert!(parse_angle_text(".inf").is_err());
    }

    /// Bug (issue 18): read warnings lived in per-thread storage until the next tree load took
    /// them, so a scene file read between two trees leaked its warnings into the next tree, and
    /// reads outside a tree load piled up for the life of the thread.
    #[test]
    fn warnings_belong_to_the_read_that_raised_them() {
        use crate::yaml::de::{collect_warnings, from_value};
        use crate::yaml::value::{Value, parse_yaml};
        let v = parse_yaml("yaw: 5", 0).unwrap();
        let yaw = |v: &Value| from_value::<std::collections::BTreeMap<String, Angle>>(v);
        // Outside a collecting call: dropped, not kept for later.
        assert!(yaw(&v).is_ok());
        let ((), w) = collect_warnings(|| ());
        assert!(w.is_empty(), "{w:?}");
        // Inside: collected, and a nested call keeps its own.
        let ((inner, r), outer) = collect_warnings(|| {
            let _ = yaw(&v);
            let (r, inner) = collect_warnings(|| yaw(&v));
            (inner, r)
        });
        assert!(r.is_ok());
        assert_eq!(inner.len(), 1, "{inner:?}");
        assert_eq!(outer.len(), 1, "{outer:?}");
        assert_eq!(outer[0].loc, inner[0].loc);
    }
}
