//! Naming objects in trees: an object of the scene by name (`red`, `bin`) or a blackboard
//! variable (`{block}`) that a `select` or `for_each` wrote. Names are checked against the scene
//! and variables against their writers when the tree is loaded (`crate::spec::check`).

use std::borrow::Cow;
use std::fmt;

use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};

use crate::scene::ObjectKind;
use crate::yaml::is_identifier;

/// A short name (object or variable, at most [`Ident::MAX`] bytes) stored inline, so that the
/// leaf parameters holding it stay `Copy`.
#[derive(Copy, Clone, PartialEq, Eq, Hash)]
pub struct Ident {
    len: u8,
    bytes: [u8; Ident::MAX],
}

impl Ident {
    /// Longest name, bytes.
    pub const MAX: usize = 64;

    /// `s` as an identifier, if it fits.
    pub fn new(s: &str) -> Option<Ident> {
        (s.len() <= Self::MAX).then(|| {
            let mut bytes = [0; Self::MAX];
            bytes[..s.len()].copy_from_slice(s.as_bytes());
            Ident {
                len: s.len() as u8,
                bytes,
            }
        })
    }

    /// The name.
    pub fn as_str(&self) -> &str {
        // Built from a `&str` only, so the bytes are valid UTF-8.
        std::str::from_utf8(&self.bytes[..self.len as usize]).unwrap_or_default()
    }
}

impl std::ops::Deref for Ident {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl fmt::Debug for Ident {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

impl fmt::Display for Ident {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// An object of the scene, named or read from the blackboard.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum ObjectRef {
    /// The object with this name in the scene.
    Name(Ident),
    /// The object whose name the blackboard variable holds (written `{var}`).
    Var(Ident),
}

impl ObjectRef {
    /// A reference to the object called `name` (`None` when longer than [`Ident::MAX`]).
    pub fn name(name: &str) -> Option<ObjectRef> {
        Ident::new(name).map(ObjectRef::Name)
    }

    /// Reads `{var}` or a name.
    pub fn parse(s: &str) -> Result<ObjectRef, String> {
        if let Some(inner) = s.strip_prefix('{').and_then(|r| r.strip_suffix('}')) {
            let inner = inner.trim();
            return if is_identifier(inner) {
                Ok(ObjectRef::Var(
                    Ident::new(inner).expect("identifiers are at most 64 bytes"),
                ))
            } else {
                Err(format!(
                    "`{s}` is not a variable: write `{{name}}` with a name of letters, digits and `_`"
                ))
            };
        }
        if crate::scene::is_object_name(s) {
            Ok(ObjectRef::Name(
                Ident::new(s).expect("object names are at most 32 bytes"),
            ))
        } else {
            Err(format!(
                "`{s}` is not a name of an object or a spot: names are lower-case letters, digits and `_` (or `{{var}}` for a blackboard variable)"
            ))
        }
    }
}

impl fmt::Display for ObjectRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ObjectRef::Name(n) => f.write_str(n),
            ObjectRef::Var(v) => write!(f, "{{{v}}}"),
        }
    }
}

impl Serialize for ObjectRef {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// Visits an object reference; `{var}` written bare in YAML is a one-key mapping with a null
/// value, which reads as the variable too.
pub(crate) struct ObjectRefVisitor;

impl<'de> Visitor<'de> for ObjectRefVisitor {
    type Value = ObjectRef;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an object name (`red`) or a blackboard variable (`{block}`)")
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<ObjectRef, E> {
        ObjectRef::parse(v).map_err(E::custom)
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<ObjectRef, A::Error> {
        var_from_map(map)
    }
}

/// `{var}` in YAML flow style: a mapping with one key and no value.
pub(crate) fn var_from_map<'de, A: MapAccess<'de>>(mut map: A) -> Result<ObjectRef, A::Error> {
    let key: Option<String> = map.next_key()?;
    let value: Option<de::IgnoredAny> = match key {
        Some(_) => map.next_value::<Option<de::IgnoredAny>>()?,
        None => None,
    };
    match (key, value, map.next_key::<de::IgnoredAny>()?) {
        (Some(k), None, None) if is_identifier(&k) => Ok(ObjectRef::Var(
            Ident::new(&k).expect("identifiers are at most 64 bytes"),
        )),
        _ => Err(de::Error::custom(
            "expected an object name or a variable `{name}`, found a mapping",
        )),
    }
}

impl<'de> Deserialize<'de> for ObjectRef {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ObjectRefVisitor)
    }
}

impl JsonSchema for ObjectRef {
    fn schema_name() -> Cow<'static, str> {
        "ObjectRef".into()
    }
    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        json_schema!({
            "description": "An object of the scene by name (`red`), or a blackboard variable written by `select`/`for_each` (`{block}`; bare `{block}` in YAML flow style works too).",
            "anyOf": [
                {"type": "string", "pattern": "^([a-z][a-z0-9_]*|\\{\\s*[A-Za-z_][A-Za-z0-9_]*\\s*\\})$"},
                {"type": "object", "minProperties": 1, "maxProperties": 1, "additionalProperties": {"type": "null"}}
            ]
        })
    }
}

/// A blackboard variable name (`[A-Za-z_][A-Za-z0-9_]*`) as written after `as:`/`goal_as:`.
pub fn var_name<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let s = String::deserialize(d)?;
    let s = s.trim_start_matches('{').trim_end_matches('}').to_string();
    if is_identifier(&s) {
        Ok(s)
    } else {
        Err(de::Error::custom(format!(
            "`{s}` is not a variable name: use letters, digits and `_`, starting with a letter"
        )))
    }
}

/// An optional [`var_name`].
pub fn opt_var_name<'de, D: Deserializer<'de>>(d: D) -> Result<Option<String>, D::Error> {
    var_name(d).map(Some)
}

/// What kind of object a parameter must name (see [`Params::OBJECT_PARAMS`](super::Params::OBJECT_PARAMS)).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectRole {
    /// A block (e.g. `object:`, `support:`).
    Block,
    /// A container (e.g. `container:`).
    Container,
    /// Any object or a spot of the scene (e.g. `target:`, `to:`).
    Any,
    /// A spot of the scene (`spots:` in the scene file; e.g. `place`'s `spot:`).
    Spot,
}

impl ObjectRole {
    /// Whether an object of `kind` fits.
    pub fn accepts(self, kind: ObjectKind) -> bool {
        match self {
            ObjectRole::Block => kind == ObjectKind::Block,
            ObjectRole::Container => kind == ObjectKind::Container,
            ObjectRole::Any => true,
            ObjectRole::Spot => false,
        }
    }

    /// Whether a spot of the scene fits (a motion's target, `place`'s spot).
    pub fn accepts_spot(self) -> bool {
        matches!(self, ObjectRole::Any | ObjectRole::Spot)
    }

    /// How messages name what fits (`a block`, `a container`, `an object or a spot`, `a spot`).
    pub fn name(self) -> &'static str {
        match self {
            ObjectRole::Block => "a block",
            ObjectRole::Container => "a container",
            ObjectRole::Any => "an object or a spot",
            ObjectRole::Spot => "a spot",
        }
    }
}
