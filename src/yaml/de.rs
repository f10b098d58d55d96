//! Typed deserialization from a spanned [`Value`], with errors that keep their location.
//!
//! This is a small serde `Deserializer` over `&Value`. Every error raised while reading a value
//! (by serde-derived code or by our own checks) is tagged with the location of the innermost
//! value being read, so `#[derive(Deserialize)]` parameter structs with `deny_unknown_fields`
//! give located "unknown field" / "missing field" / "wrong type" errors for free.

use std::fmt;

use serde::de::{
    self, DeserializeOwned, DeserializeSeed, Deserializer, EnumAccess, IntoDeserializer, MapAccess,
    SeqAccess, VariantAccess, Visitor,
};

use super::diag::{Issue, Loc};
use super::suggest::did_you_mean;
use super::value::{Value, ValueKind};

/// How a "missing parameter" message starts (the name and a backtick follow).
const MISSING: &str = "missing parameter `";

/// A typed-deserialization error: message plus (once known) the location of the value.
#[derive(Debug, Clone)]
pub struct DeError {
    /// What is wrong.
    pub message: String,
    /// What was expected (shown under the caret).
    pub label: Option<String>,
    /// What to do.
    pub help: Option<String>,
    /// Where (innermost value); `None` until a value claims it.
    pub loc: Option<Loc>,
    /// If the value came from a subtree `$param`, where that `$param` was used.
    pub via: Option<Loc>,
}

/// Separates a message from its help in a custom error's text (`"message\nhelp: what to do"`),
/// so that checks written against any serde error type can give help too.
pub const HELP_SEPARATOR: &str = "\nhelp: ";

/// A warning raised while reading a value: something accepted that is probably not what the
/// author meant (e.g. `yaw: 5`, read as 5 radians).
#[derive(Debug, Clone, PartialEq)]
pub struct DeWarning {
    /// What looks wrong.
    pub message: String,
    /// What to do.
    pub help: Option<String>,
    /// Where (the value read).
    pub loc: Loc,
    /// If the value came from a subtree `$param`, where that `$param` was used.
    pub via: Option<Loc>,
}

thread_local! {
    /// Warnings raised by the value being read, not yet located; only inside
    /// [`collect_warnings`].
    static PENDING: std::cell::RefCell<Vec<(String, Option<String>)>> = const { std::cell::RefCell::new(Vec::new()) };
    /// Located warnings of the innermost [`collect_warnings`] call.
    static LOCATED: std::cell::RefCell<Vec<DeWarning>> = const { std::cell::RefCell::new(Vec::new()) };
    /// How many [`collect_warnings`] calls are running on this thread.
    static DEPTH: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

/// Raise a warning about the value being read (located by the deserializer once it returns).
/// Only a read inside [`collect_warnings`] keeps it; elsewhere it is dropped.
pub fn warn(message: impl Into<String>, help: Option<String>) {
    if DEPTH.with(std::cell::Cell::get) > 0 {
        PENDING.with(|p| p.borrow_mut().push((message.into(), help)));
    }
}

/// Runs `read` (which reads values with [`from_value`]) and returns its result with the warnings
/// raised while it ran, located and in order. Nothing outlives the call: serde's `Deserialize`
/// cannot be handed a sink, so the warnings travel through per-thread storage that this call
/// empties before and after (and restores for an enclosing call).
pub fn collect_warnings<R>(read: impl FnOnce() -> R) -> (R, Vec<DeWarning>) {
    let outer_pending = PENDING.with(|p| std::mem::take(&mut *p.borrow_mut()));
    let outer_located = LOCATED.with(|l| std::mem::take(&mut *l.borrow_mut()));
    DEPTH.with(|d| d.set(d.get() + 1));
    struct Restore(Vec<(String, Option<String>)>, Vec<DeWarning>);
    impl Drop for Restore {
        fn drop(&mut self) {
            DEPTH.with(|d| d.set(d.get() - 1));
            PENDING.with(|p| *p.borrow_mut() = std::mem::take(&mut self.0));
            LOCATED.with(|l| *l.borrow_mut() = std::mem::take(&mut self.1));
        }
    }
    let restore = Restore(outer_pending, outer_located);
    let r = read();
    let warnings = LOCATED.with(|l| std::mem::take(&mut *l.borrow_mut()));
    drop(restore);
    (r, warnings)
}

/// Locate the pending warnings at `v`.
fn locate_warnings(v: &Value) {
    let pending = PENDING.with(|p| std::mem::take(&mut *p.borrow_mut()));
    if pending.is_empty() {
        return;
    }
    LOCATED.with(|l| {
        l.borrow_mut()
            .extend(pending.into_iter().map(|(message, help)| DeWarning {
                message,
                help,
                loc: v.loc,
                via: v.via,
            }));
    });
}

/// The first item of the list `v` that a subtree argument put there, preferring one
/// written in another file than `v` (an argument of the call rather than a default of the
/// subtree's own `params:`).
fn substituted_part(v: &Value) -> Option<&Value> {
    fn walk<'a>(v: &'a Value, out: &mut Vec<&'a Value>) {
        match &v.kind {
            ValueKind::Seq(items) => items.iter().for_each(|i| {
                if i.via.is_some() {
                    out.push(i);
                } else {
                    walk(i, out);
                }
            }),
            ValueKind::Map(entries) => entries.iter().for_each(|(_, x)| {
                if x.via.is_some() {
                    out.push(x);
                } else {
                    walk(x, out);
                }
            }),
            _ => {}
        }
    }
    let mut found = Vec::new();
    walk(v, &mut found);
    let one_argument = found.windows(2).all(|w| w[0].loc == w[1].loc);
    found
        .iter()
        .find(|p| p.loc.file != v.loc.file)
        .or_else(|| one_argument.then(|| found.first()).flatten())
        .copied()
}

impl DeError {
    fn at(mut self, v: &Value) -> Self {
        if self.loc.is_none() {
            self.loc = Some(v.loc);
            self.via = v.via;
            // A check of a whole value (a point out of reach) built from a subtree argument:
            // point at the argument, with a note at the use, like a check of the argument itself.
            if v.via.is_none()
                && self.label.is_none()
                && matches!(v.kind, ValueKind::Seq(_))
                && let Some(part) = substituted_part(v)
            {
                self.loc = Some(part.loc);
                self.via = part.via;
            }
        }
        self
    }

    /// Convert to an [`Issue`], using `fallback` when no value claimed the error.
    pub fn into_issue(self, fallback: Loc, describe_via: impl Fn(Loc) -> String) -> Issue {
        let mut issue = Issue::new(self.loc.unwrap_or(fallback), self.message);
        issue.label = self.label;
        issue.help = self.help;
        if let Some(via) = self.via {
            issue.note = Some(format!(
                "this value is a subtree argument, used at {}",
                describe_via(via)
            ));
        }
        issue
    }

    /// A plain error with a message.
    pub fn msg(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            label: None,
            help: None,
            loc: None,
            via: None,
        }
    }

    /// Add a label (what was expected).
    #[must_use]
    pub fn with_label(mut self, label: impl Into<String>) -> Self {
        self.label = Some(label.into());
        self
    }

    /// Add help text.
    #[must_use]
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// For a "missing parameter" error, the parameter's name.
    pub fn missing_parameter(&self) -> Option<&str> {
        self.message.strip_prefix(MISSING)?.strip_suffix('`')
    }
}

impl fmt::Display for DeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for DeError {}

/// Serde's Rust-flavoured expectations in user words.
fn plain_expected(exp: &str) -> String {
    match exp {
        "f64" | "f32" => "a number".into(),
        "u32" | "u64" | "i64" | "i32" | "u8" | "usize" => "an integer".into(),
        "a string" | "a borrowed string" => "text".into(),
        other if other.starts_with("struct ") => "a mapping of parameters, e.g. `{}`".into(),
        other => other.to_string(),
    }
}

/// `expected` as a label says it: `` `a` ``, or `` one of `a`, `b` ``, or `nothing`.
pub fn list(expected: &[&str]) -> String {
    let items: Vec<String> = expected.iter().map(|e| format!("`{e}`")).collect();
    match items.len() {
        0 => "nothing".to_string(),
        1 => items[0].clone(),
        _ => format!("one of {}", items.join(", ")),
    }
}

impl de::Error for DeError {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        let text = msg.to_string();
        match text.split_once(HELP_SEPARATOR) {
            Some((message, help)) => Self::msg(message).with_help(help),
            None => Self::msg(text),
        }
    }

    fn invalid_type(unexp: de::Unexpected, exp: &dyn de::Expected) -> Self {
        Self::msg(format!("wrong type: found {unexp}"))
            .with_label(format!("expected {}", plain_expected(&exp.to_string())))
    }

    fn invalid_value(unexp: de::Unexpected, exp: &dyn de::Expected) -> Self {
        Self::msg(format!("invalid value: {unexp}")).with_label(format!("expected {exp}"))
    }

    fn invalid_length(len: usize, exp: &dyn de::Expected) -> Self {
        Self::msg(format!("wrong number of items: found {len}")).with_label(format!("expected {exp}"))
    }

    fn unknown_variant(variant: &str, expected: &'static [&'static str]) -> Self {
        let mut e = Self::msg(format!("unknown value `{variant}`"))
            .with_label(format!("expected {}", list(expected)));
        e.help = did_you_mean(variant, expected.iter().copied());
        e
    }

    fn unknown_field(field: &str, expected: &'static [&'static str]) -> Self {
        let mut e = Self::msg(format!("unknown parameter `{field}`"));
        e.label = Some(if expected.is_empty() {
            "this node takes no parameters (except `name`)".to_string()
        } else {
            format!("expected {} or `name`", list(expected))
        });
        e.help = did_you_mean(field, expected.iter().copied().chain(["name"])).or_else(|| {
            Some("remove this parameter; see docs/tree_format.md for the node's parameters".into())
        });
        e
    }

    fn missing_field(field: &'static str) -> Self {
        Self::msg(format!("{MISSING}{field}`"))
            .with_label(format!("add `{field}: ...` here"))
            .with_help("see docs/tree_format.md for the node's parameters")
    }

    fn duplicate_field(field: &'static str) -> Self {
        Self::msg(format!("parameter `{field}` is given twice")).with_help("remove one of them")
    }
}

/// The name a [`RawValue`] asks the deserializer for; [`ValueDe`] answers it with the value
/// itself (through [`RAW`]) instead of reading it.
const RAW_TOKEN: &str = "$macrotree::RawValue";

thread_local! {
    /// The value a [`RawValue`] is being read from, handed over by [`ValueDe`].
    static RAW: std::cell::RefCell<Option<Value>> = const { std::cell::RefCell::new(None) };
}

/// A part of a typed struct kept as located YAML, read later (a control node's children are
/// read as nodes by the tree reader). Only [`from_value`] can read it.
#[derive(Clone, Debug, PartialEq)]
pub struct RawValue(pub Value);

impl<'de> serde::Deserialize<'de> for RawValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Raw;
        impl Visitor<'_> for Raw {
            type Value = RawValue;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a YAML value")
            }
            fn visit_unit<E: de::Error>(self) -> Result<RawValue, E> {
                RAW.with(|r| r.borrow_mut().take())
                    .map(RawValue)
                    .ok_or_else(|| E::custom("a YAML value can only be kept from a YAML file"))
            }
        }
        d.deserialize_newtype_struct(RAW_TOKEN, Raw)
    }
}

/// Read a `T` from a spanned value.
pub fn from_value<T: DeserializeOwned>(v: &Value) -> Result<T, DeError> {
    T::deserialize(ValueDe(v)).map_err(|e| e.at(v))
}

/// The deserializer over a borrowed [`Value`].
#[derive(Clone, Copy)]
pub struct ValueDe<'a>(pub &'a Value);

impl<'de> Deserializer<'de> for ValueDe<'_> {
    type Error = DeError;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, DeError> {
        let v = self.0;
        let r = match &v.kind {
            ValueKind::Null => visitor.visit_unit(),
            ValueKind::Bool(b) => visitor.visit_bool(*b),
            ValueKind::Int(i) => visitor.visit_i64(*i),
            ValueKind::Float(x) => visitor.visit_f64(*x),
            ValueKind::Str(s) => visitor.visit_str(s),
            ValueKind::Seq(items) => visitor.visit_seq(SeqAcc {
                items: items.iter(),
                parent: v,
            }),
            ValueKind::Map(entries) => visitor.visit_map(MapAcc {
                entries: entries.iter(),
                pending: None,
            }),
        };
        locate_warnings(v);
        r.map_err(|e| e.at(v))
    }

    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, DeError> {
        let v = self.0;
        match v.kind {
            ValueKind::Null => visitor.visit_none(),
            _ => visitor.visit_some(self),
        }
        .map_err(|e| e.at(v))
    }

    fn deserialize_f64<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, DeError> {
        let v = self.0;
        let r = match &v.kind {
            ValueKind::Int(i) => visitor.visit_f64(*i as f64),
            ValueKind::Float(x) => visitor.visit_f64(*x),
            _ => return self.deserialize_any(visitor),
        };
        locate_warnings(v);
        r.map_err(|e: DeError| e.at(v))
    }

    fn deserialize_f32<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, DeError> {
        self.deserialize_f64(visitor)
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, DeError> {
        let v = self.0;
        match &v.kind {
            // `grasp:` with nothing after it means "all defaults".
            ValueKind::Null => visitor.visit_map(MapAcc {
                entries: [].iter(),
                pending: None,
            }),
            ValueKind::Map(_) => return self.deserialize_any(visitor),
            _ => Err(DeError::msg(format!("wrong type: found {}", v.describe()))
                .with_label("expected a mapping of parameters, e.g. `{}`")),
        }
        .map_err(|e| e.at(v))
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        visitor: V,
    ) -> Result<V::Value, DeError> {
        let v = self.0;
        if name == RAW_TOKEN {
            RAW.with(|r| *r.borrow_mut() = Some(v.clone()));
            return visitor.visit_unit().map_err(|e: DeError| e.at(v));
        }
        visitor.visit_newtype_struct(self).map_err(|e| e.at(v))
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, DeError> {
        let v = self.0;
        match &v.kind {
            ValueKind::Str(_) => visitor.visit_enum(EnumAcc {
                tag: v,
                payload: None,
            }),
            ValueKind::Map(entries) if entries.len() == 1 => visitor.visit_enum(EnumAcc {
                tag: &entries[0].0,
                payload: Some(&entries[0].1),
            }),
            _ => Err(DeError::msg(format!("wrong type: found {}", v.describe()))
                .with_label(format!("expected {}", list(variants)))),
        }
        .map_err(|e| e.at(v))
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 char str string
        bytes byte_buf unit unit_struct seq tuple tuple_struct map identifier ignored_any
    }
}

struct SeqAcc<'a> {
    items: std::slice::Iter<'a, Value>,
    parent: &'a Value,
}

impl<'de> SeqAccess<'de> for SeqAcc<'_> {
    type Error = DeError;

    fn next_element_seed<T: DeserializeSeed<'de>>(&mut self, seed: T) -> Result<Option<T::Value>, DeError> {
        match self.items.next() {
            Some(item) => seed.deserialize(ValueDe(item)).map(Some).map_err(|e| e.at(item)),
            None => Ok(None),
        }
    }

    fn size_hint(&self) -> Option<usize> {
        let _ = self.parent;
        Some(self.items.len())
    }
}

struct MapAcc<'a> {
    entries: std::slice::Iter<'a, (Value, Value)>,
    pending: Option<&'a Value>,
}

impl<'de> MapAccess<'de> for MapAcc<'_> {
    type Error = DeError;

    fn next_key_seed<K: DeserializeSeed<'de>>(&mut self, seed: K) -> Result<Option<K::Value>, DeError> {
        match self.entries.next() {
            Some((k, v)) => {
                self.pending = Some(v);
                seed.deserialize(ValueDe(k)).map(Some).map_err(|e| e.at(k))
            }
            None => Ok(None),
        }
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, DeError> {
        match self.pending.take() {
            Some(v) => seed.deserialize(ValueDe(v)).map_err(|e| e.at(v)),
            None => Err(DeError::msg("internal error: value requested before key")),
        }
    }
}

struct EnumAcc<'a> {
    tag: &'a Value,
    payload: Option<&'a Value>,
}

impl<'de, 'a> EnumAccess<'de> for EnumAcc<'a> {
    type Error = DeError;
    type Variant = VariantAcc<'a>;

    fn variant_seed<T: DeserializeSeed<'de>>(self, seed: T) -> Result<(T::Value, VariantAcc<'a>), DeError> {
        let tag = self.tag;
        let name = match &tag.kind {
            ValueKind::Str(s) => s.as_str(),
            _ => {
                return Err(DeError::msg(format!("wrong type: found {}", tag.describe()))
                    .with_label("expected a name"))
                .map_err(|e| e.at(tag));
            }
        };
        let value = seed
            .deserialize(name.into_deserializer())
            .map_err(|e: DeError| e.at(tag))?;
        Ok((
            value,
            VariantAcc {
                tag,
                payload: self.payload,
            },
        ))
    }
}

struct VariantAcc<'a> {
    tag: &'a Value,
    payload: Option<&'a Value>,
}

impl<'de> VariantAccess<'de> for VariantAcc<'_> {
    type Error = DeError;

    fn unit_variant(self) -> Result<(), DeError> {
        match self.payload {
            None => Ok(()),
            Some(p) if p.kind == ValueKind::Null => Ok(()),
            Some(p) => Err(DeError::msg("this value takes no parameters").at(p)),
        }
    }

    fn newtype_variant_seed<T: DeserializeSeed<'de>>(self, seed: T) -> Result<T::Value, DeError> {
        match self.payload {
            Some(p) => seed.deserialize(ValueDe(p)).map_err(|e| e.at(p)),
            None => Err(DeError::msg("missing value for this option").at(self.tag)),
        }
    }

    fn tuple_variant<V: Visitor<'de>>(self, _len: usize, visitor: V) -> Result<V::Value, DeError> {
        match self.payload {
            Some(p) => ValueDe(p).deserialize_any(visitor),
            None => Err(DeError::msg("missing value for this option").at(self.tag)),
        }
    }

    fn struct_variant<V: Visitor<'de>>(
        self,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, DeError> {
        match self.payload {
            Some(p) => ValueDe(p).deserialize_struct("", &[], visitor),
            None => Err(DeError::msg("missing value for this option").at(self.tag)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::yaml::value::parse_yaml;
    use serde::Deserialize;

    #[derive(Deserialize, Debug, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct P {
        speed: f64,
        #[serde(default)]
        width: Option<f64>,
        #[serde(default)]
        offset: [f64; 3],
    }

    #[test]
    fn reads_struct_and_locates_errors() {
        let v = parse_yaml(
            "a: {speed: 1, offset: [0, 0, 0.5]}\nb: {speed: 1, spede: 2}\nc: {speed: x}\n",
            0,
        )
        .unwrap();
        let a: P = from_value(v.get("a").unwrap()).unwrap();
        assert_eq!(
            a,
            P {
                speed: 1.0,
                width: None,
                offset: [0.0, 0.0, 0.5]
            }
        );
        let e = from_value::<P>(v.get("b").unwrap()).unwrap_err();
        let loc = e.loc.unwrap();
        assert_eq!((loc.line, loc.col), (2, 15), "{e:?}");
        assert!(e.message.contains("spede"));
        assert_eq!(e.help.as_deref(), Some("did you mean `speed`?"));
        let e = from_value::<P>(v.get("c").unwrap()).unwrap_err();
        let loc = e.loc.unwrap();
        assert_eq!((loc.line, loc.col), (3, 12), "{e:?}");
    }
}
