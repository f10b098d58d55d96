//! Object colours: a name from a small palette, or RGBA in 0…1.

use std::borrow::Cow;
use std::fmt;

use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};

use crate::yaml::suggest::did_you_mean;

/// The named colours, with their RGB (0…1).
pub const COLOR_NAMES: &[(&str, [f64; 3])] = &[
    ("red", [0.85, 0.15, 0.15]),
    ("green", [0.15, 0.65, 0.25]),
    ("blue", [0.15, 0.35, 0.85]),
    ("yellow", [0.95, 0.8, 0.15]),
    ("orange", [0.95, 0.35, 0.15]),
    ("purple", [0.55, 0.25, 0.7]),
    ("cyan", [0.2, 0.75, 0.85]),
    ("teal", [0.25, 0.65, 0.55]),
    ("pink", [0.95, 0.5, 0.7]),
    ("brown", [0.5, 0.33, 0.2]),
    ("white", [0.92, 0.92, 0.92]),
    ("gray", [0.5, 0.5, 0.5]),
    ("black", [0.12, 0.12, 0.12]),
];

/// A colour: RGBA in 0…1, with the palette name it was given by, if any (queries and goals match
/// blocks and containers by that name).
#[derive(Clone, Debug, PartialEq)]
pub struct Color {
    /// Red, green, blue, alpha in 0…1.
    pub rgba: [f64; 4],
    /// The palette name (`red`, …), when written as a name.
    pub name: Option<String>,
}

impl Color {
    /// The palette colour called `name`.
    pub fn named(name: &str) -> Option<Self> {
        COLOR_NAMES.iter().find(|(n, _)| *n == name).map(|(n, rgb)| Self {
            rgba: [rgb[0], rgb[1], rgb[2], 1.0],
            name: Some((*n).to_string()),
        })
    }
}

impl fmt::Display for Color {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.name {
            Some(n) => f.write_str(n),
            None => {
                let [r, g, b, a] = self.rgba;
                write!(f, "[{r}, {g}, {b}, {a}]")
            }
        }
    }
}

impl Serialize for Color {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match &self.name {
            Some(n) => s.serialize_str(n),
            None => self.rgba.serialize(s),
        }
    }
}

struct ColorVisitor;

impl<'de> Visitor<'de> for ColorVisitor {
    type Value = Color;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a colour name (`red`, `green`, …) or `[r, g, b, a]` in 0…1")
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Color, E> {
        Color::named(v).ok_or_else(|| {
            let names: Vec<&str> = COLOR_NAMES.iter().map(|(n, _)| *n).collect();
            let mut msg = format!("unknown colour `{v}`: expected one of {}", names.join(", "));
            if let Some(h) = did_you_mean(v, names.iter().copied()) {
                msg.push_str(&format!(" ({h})"));
            }
            E::custom(msg)
        })
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Color, A::Error> {
        let mut rgba = [1.0; 4];
        let mut n = 0;
        while let Some(x) = seq.next_element::<f64>()? {
            if n == 4 {
                return Err(de::Error::invalid_length(5, &"[r, g, b] or [r, g, b, a]"));
            }
            if !(0.0..=1.0).contains(&x) {
                return Err(de::Error::custom(format!(
                    "colour components are in 0…1, found `{x}`"
                )));
            }
            rgba[n] = x;
            n += 1;
        }
        if n < 3 {
            return Err(de::Error::invalid_length(n, &"[r, g, b] or [r, g, b, a]"));
        }
        Ok(Color { rgba, name: None })
    }
}

impl<'de> Deserialize<'de> for Color {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ColorVisitor)
    }
}

impl JsonSchema for Color {
    fn schema_name() -> Cow<'static, str> {
        "Color".into()
    }
    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        let names: Vec<&str> = COLOR_NAMES.iter().map(|(n, _)| *n).collect();
        json_schema!({
            "description": "A colour name, or [r, g, b] / [r, g, b, a] with components in 0…1.",
            "anyOf": [
                {"type": "string", "enum": names},
                {"type": "array", "items": {"type": "number", "minimum": 0, "maximum": 1}, "minItems": 3, "maxItems": 4}
            ]
        })
    }
}
