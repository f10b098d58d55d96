//! [`field_names`]: the keys a section of a file takes, read from the struct that declares it.
//!
//! A reader that checks keys by hand (to locate each unknown key and suggest the nearest one)
//! takes its list from here, so the keys are written once — on the `#[derive(Deserialize)]`
//! struct the JSON Schema is generated from — and a new field is accepted everywhere at once.

use serde::de::{self, Deserialize, Deserializer, Visitor};

/// The field names (as written in files, after `rename`) that serde's derived `Deserialize` of
/// the struct `T` declares; empty when `T` is not a struct with named fields.
pub fn field_names<T: for<'de> Deserialize<'de>>() -> &'static [&'static str] {
    let mut fields = None;
    // The derived impl hands its field list to `deserialize_struct`, which records it and stops.
    let _ = T::deserialize(FieldProbe(&mut fields));
    fields.unwrap_or(&[])
}

/// A deserializer that records the field list a struct asks for and then fails.
struct FieldProbe<'a>(&'a mut Option<&'static [&'static str]>);

impl<'de> Deserializer<'de> for FieldProbe<'_> {
    type Error = de::value::Error;

    fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Self::Error> {
        Err(de::Error::custom("not a struct"))
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Self::Error> {
        *self.0 = Some(fields);
        Err(de::Error::custom("field names recorded"))
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string bytes byte_buf
        option unit unit_struct newtype_struct seq tuple tuple_struct map enum identifier
        ignored_any
    }
}

#[cfg(test)]
mod tests {
    use super::field_names;

    #[derive(serde::Deserialize)]
    #[allow(dead_code)]
    struct Section {
        first: u32,
        #[serde(rename = "second_key")]
        second: Option<String>,
    }

    #[test]
    fn the_field_names_are_the_structs_keys_as_written_in_files() {
        assert_eq!(field_names::<Section>(), ["first", "second_key"]);
    }

    #[test]
    fn a_type_that_is_not_a_struct_has_no_field_names() {
        assert!(field_names::<u32>().is_empty());
        assert!(field_names::<Vec<String>>().is_empty());
    }
}
