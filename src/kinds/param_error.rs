//! The error of a leaf's own parameter check ([`super::Params::validate_fields`]): a message, and
//! optionally the parameter it is about, so that the error points at that value in the file.

use std::fmt;

/// Parameters that do not fit together, or one that is out of its range: what is wrong, and
/// which parameter (a key of the node's body) it is about, if one.
///
/// ```
/// use macrotree::ParamError;
/// let e = ParamError::at("max_tilt", "must be between 0 and 45°, found 60.0°");
/// assert_eq!(e.field(), Some("max_tilt"));
/// assert_eq!(e.to_string(), "`max_tilt` must be between 0 and 45°, found 60.0°");
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParamError {
    field: Option<String>,
    message: String,
}

impl ParamError {
    /// An error about the parameters together; reported at the node.
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            field: None,
            message: message.into(),
        }
    }

    /// An error about the parameter `field` (its key in the node's YAML body); reported at its
    /// value (at the node when the body does not write it, e.g. a default). The message says
    /// what is wrong with it; the field's name is put before it.
    pub fn at(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            field: Some(field.into()),
            message: message.into(),
        }
    }

    /// The parameter the error is about, if one.
    pub fn field(&self) -> Option<&str> {
        self.field.as_deref()
    }

    /// What is wrong, as given.
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.field {
            Some(field) => write!(f, "`{field}` {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl std::error::Error for ParamError {}

impl From<String> for ParamError {
    fn from(message: String) -> Self {
        Self::new(message)
    }
}

impl From<&str> for ParamError {
    fn from(message: &str) -> Self {
        Self::new(message)
    }
}
