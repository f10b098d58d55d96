//! Errors across the boundary: every `macrotree::Error` becomes a `MacrotreeError` carrying the
//! library's located message (`file:line:column: …`) and its stable kind.

use pyo3::create_exception;
use pyo3::prelude::*;

create_exception!(
    _native,
    MacrotreeError,
    pyo3::exceptions::PyException,
    "Invalid input (a tree, scene or leaf mapping that does not check, a number out of range): the message is located and says what to do."
);

/// A library error as a Python exception; `kind` (e.g. `invalid_tree`) is kept as an attribute.
pub fn to_py(e: macrotree::Error) -> PyErr {
    let err = MacrotreeError::new_err(e.to_string());
    Python::attach(|py| {
        let _ = err.value(py).setattr("kind", e.kind());
    });
    err
}

/// A `ValueError` for a malformed argument caught on this side.
pub fn value(message: impl Into<String>) -> PyErr {
    pyo3::exceptions::PyValueError::new_err(message.into())
}
