//! Real numbers from Python: an array of any real dtype and any strides (or anything numpy turns
//! into one), read as float64 values in row-major order with its shape. float64 and float32
//! arrays in the machine's byte order are read where they are, without a Python call; anything
//! else goes through `numpy.asarray` once. Complex, text or object values raise `TypeError`
//! naming what they were for, rather than losing a part.

use numpy::{
    Element, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyTypeError;
use pyo3::intern;
use pyo3::prelude::*;

/// An array of real numbers read from Python.
pub struct Reals {
    /// Its shape, numpy's.
    pub shape: Vec<usize>,
    /// Its values as float64, in row-major order.
    pub values: Vec<f64>,
}

impl Reals {
    /// The shape as Python writes it: `(7,)`, `(2, 19)`.
    pub fn shape_text(&self) -> String {
        match self.shape.as_slice() {
            [n] => format!("({n},)"),
            dims => {
                let dims: Vec<String> = dims.iter().map(usize::to_string).collect();
                format!("({})", dims.join(", "))
            }
        }
    }
}

/// `value`'s real numbers; `what` names them in the error ("setpoint actions").
///
/// # Errors
/// `TypeError` for complex, text, object or other non-real values; numpy's own error for a
/// value it cannot make an array of (ragged lists).
pub fn reals(value: &Bound<'_, PyAny>, what: &str) -> PyResult<Reals> {
    if let Some(r) = read::<f64>(value) {
        return Ok(r);
    }
    if let Some(r) = read::<f32>(value) {
        return Ok(r);
    }
    let py = value.py();
    let numpy = py.import(intern!(py, "numpy"))?;
    let array = numpy
        .call_method1(intern!(py, "asarray"), (value,))?
        .cast_into::<PyUntypedArray>()?;
    let dtype = array.dtype();
    if !b"biuf".contains(&dtype.kind()) {
        let kind = if dtype.kind() == b'c' {
            "complex".to_string()
        } else {
            dtype.str()?.to_string()
        };
        return Err(PyTypeError::new_err(format!(
            "{what} must be real numbers, got {kind} values"
        )));
    }
    let float = array.call_method1(intern!(py, "astype"), (numpy.getattr(intern!(py, "float64"))?,))?;
    read::<f64>(&float).ok_or_else(|| PyTypeError::new_err(format!("{what} must be real numbers")))
}

/// `value`'s numbers when it is an array of `T` in the machine's byte order.
fn read<T: Element + Copy + Into<f64>>(value: &Bound<'_, PyAny>) -> Option<Reals> {
    let array = value.cast::<PyArrayDyn<T>>().ok()?;
    // A copy in row-major order (any strides); the array is not borrowed past this call.
    let owned = array.to_owned_array();
    Some(Reals {
        shape: owned.shape().to_vec(),
        values: owned.iter().map(|&x| x.into()).collect(),
    })
}
