//! [`is_object_name`]: the rule for the names of a scene's objects.

/// True for object names: `[a-z][a-z0-9_]*`, at most 32 characters.
pub fn is_object_name(s: &str) -> bool {
    let mut c = s.chars();
    matches!(c.next(), Some(f) if f.is_ascii_lowercase())
        && c.all(|x| x.is_ascii_lowercase() || x.is_ascii_digit() || x == '_')
        && s.len() <= 32
}
