//! A pose on the table as scene files write it — an object's `pose:`, a spot — `[x, y]` or
//! `[x, y, yaw]`: x and y in metres, the yaw in radians or `deg(..)`. Each element is read as
//! what it is, so a mistake is reported at the element, naming it (`x = 50 m is beyond the
//! arm's full reach …`, `yaw: `7` is more than a full turn …`), never as another kind of value.

use std::borrow::Cow;
use std::fmt;

use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::Deserialize;
use serde::de::{self, DeserializeSeed, Deserializer, SeqAccess, Visitor};

use super::units::{coordinate, named_bare_angle, parse_angle_text};

/// `[x, y]` or `[x, y, yaw]`: a centre on the table (metres) and an optional yaw (radians).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TablePose {
    /// Centre x, metres.
    pub x: f64,
    /// Centre y, metres.
    pub y: f64,
    /// Yaw about world z, radians, when written.
    pub yaw: Option<f64>,
}

/// What the sequence must be, for serde's length errors.
const EXPECTED: &str = "`[x, y]` or `[x, y, yaw]` (metres; yaw in radians or `deg(..)`)";

/// One coordinate of the pose, metres, named in its messages.
struct Metres(&'static str);

impl<'de> DeserializeSeed<'de> for Metres {
    type Value = f64;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<f64, D::Error> {
        d.deserialize_any(self)
    }
}

impl Visitor<'_> for Metres {
    type Value = f64;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{}, a number of metres", self.0)
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<f64, E> {
        self.visit_f64(v as f64)
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<f64, E> {
        self.visit_f64(v as f64)
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<f64, E> {
        if !v.is_finite() {
            return Err(E::custom(format!(
                "{} must be a finite number of metres, found `{v}`",
                self.0
            )));
        }
        coordinate(v, &format!("{} =", self.0), true)
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<f64, E> {
        let shown: String = v.chars().take(40).collect();
        Err(E::custom(format!(
            "{} is a length in metres, found the text `{shown}`{}write a number of metres; only the yaw (the third element) is an angle",
            self.0,
            super::de::HELP_SEPARATOR
        )))
    }
}

/// The pose's yaw, radians (a number, or `deg(..)`/`rad(..)` text).
struct Yaw;

impl<'de> DeserializeSeed<'de> for Yaw {
    type Value = f64;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<f64, D::Error> {
        d.deserialize_any(self)
    }
}

impl Visitor<'_> for Yaw {
    type Value = f64;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("the yaw: radians as a number, or `deg(90)` / `rad(1.57)`")
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<f64, E> {
        named_bare_angle(v as f64, true, "yaw: ")
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<f64, E> {
        named_bare_angle(v as f64, true, "yaw: ")
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<f64, E> {
        named_bare_angle(v, false, "yaw: ")
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<f64, E> {
        parse_angle_text(v).map_err(|m| {
            E::custom(format!(
                "yaw: {m}; write radians as a number, or `deg(90)` / `rad(1.57)`"
            ))
        })
    }
}

struct TablePoseVisitor;

impl<'de> Visitor<'de> for TablePoseVisitor {
    type Value = TablePose;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(EXPECTED)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<TablePose, A::Error> {
        let count = |n: usize| de::Error::custom(format!("a pose has 2 or 3 numbers, {EXPECTED}, found {n}"));
        let x = seq.next_element_seed(Metres("x"))?.ok_or_else(|| count(0))?;
        let y = seq.next_element_seed(Metres("y"))?.ok_or_else(|| count(1))?;
        let yaw = seq.next_element_seed(Yaw)?;
        let mut n = 3;
        while seq.next_element::<de::IgnoredAny>()?.is_some() {
            n += 1;
        }
        if n > 3 {
            return Err(count(n));
        }
        Ok(TablePose { x, y, yaw })
    }
}

impl<'de> Deserialize<'de> for TablePose {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_seq(TablePoseVisitor)
    }
}

impl JsonSchema for TablePose {
    fn schema_name() -> Cow<'static, str> {
        "TablePose".into()
    }
    fn json_schema(generator: &mut SchemaGenerator) -> Schema {
        let angle = generator.subschema_for::<super::units::Angle>();
        json_schema!({
            "description": "`[x, y]` or `[x, y, yaw]`: a centre on the table in metres and an optional yaw (radians, or `deg(90)`).",
            "type": "array",
            "prefixItems": [{"type": "number"}, {"type": "number"}, angle],
            "minItems": 2,
            "maxItems": 3
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::yaml::de::from_value;
    use crate::yaml::value::parse_yaml;

    /// The pose, or the error's message and help joined.
    fn read(text: &str) -> Result<TablePose, String> {
        let v = parse_yaml(text, 0).unwrap();
        from_value::<TablePose>(&v).map_err(|e| format!("{}\n{}", e.message, e.help.unwrap_or_default()))
    }

    #[test]
    fn x_and_y_are_metres_and_only_the_third_element_is_an_angle() {
        let p = read("[0.5, -0.3, deg(90)]").unwrap();
        assert_eq!((p.x, p.y), (0.5, -0.3));
        assert!((p.yaw.unwrap() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(read("[0.5, -0.3]").unwrap().yaw, None);
        // Centimetres in x: about x, in metres, not "more than a full turn".
        let e = read("[50, -30, deg(90)]").unwrap_err();
        assert!(e.starts_with("x = 50 m is beyond the arm's full reach"), "{e}");
        assert!(e.contains("write 0.5 for 50 cm"), "{e}");
        let e = read("[0.5, -30]").unwrap_err();
        assert!(e.starts_with("y = -30 m"), "{e}");
        let e = read("[0.5, 0.1, 90]").unwrap_err();
        assert!(e.starts_with("yaw: `90` is more than a full turn"), "{e}");
        let e = read("[deg(50), 0.1]").unwrap_err();
        assert!(e.starts_with("x is a length in metres"), "{e}");
        assert!(read("[0.5]").unwrap_err().contains("2 or 3 numbers"));
        assert!(read("[0.5, 0.1, 0, 0]").unwrap_err().contains("found 4"));
        assert!(read("[.nan, 0.1]").unwrap_err().contains("finite"));
    }
}
