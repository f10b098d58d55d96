//! Real numbers from Python: an array of any real dtype and any strides (or anything numpy turns
//! into one), read as float64 values in row-major order. float64 and float32 arrays in the
//! machine's byte order are read where they are, without a Python call; anything else goes
//! through `numpy.asarray` once. Complex, text or object values raise `TypeError` naming what
//! they were for, rather than losing a part; the shape is checked before any value is copied.

use numpy::{
    Element, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyTypeError;
use pyo3::intern;
use pyo3::prelude::*;

/// An array's shape, numpy's.
pub struct Shape<'a>(pub &'a [usize]);

impl Shape<'_> {
    /// The shape as Python writes it: `(7,)`, `(2, 19)`.
    pub fn text(&self) -> String {
        match self.0 {
            [n] => format!("({n},)"),
            dims => {
                let dims: Vec<String> = dims.iter().map(usize::to_string).collect();
                format!("({})", dims.join(", "))
            }
        }
    }

    /// How many values an array of this shape holds.
    pub fn count(&self) -> usize {
        self.0.iter().product()
    }
}

/// `value`'s real numbers as float64, row-major, once `check` has accepted its shape; `what`
/// names them in errors ("setpoint actions").
///
/// # Errors
/// `TypeError` for complex, text, object or other non-real values; `check`'s error; numpy's own
/// error for a value it cannot make an array of (ragged lists).
pub fn reals(
    value: &Bound<'_, PyAny>,
    what: &str,
    check: impl Fn(&Shape<'_>) -> PyResult<()>,
) -> PyResult<Vec<f64>> {
    if let Some(r) = read::<f64>(value, &check) {
        return r;
    }
    if let Some(r) = read::<f32>(value, &check) {
        return r;
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
    check(&Shape(array.shape()))?;
    let float = array.call_method1(intern!(py, "astype"), (numpy.getattr(intern!(py, "float64"))?,))?;
    read::<f64>(&float, &check)
        .unwrap_or_else(|| Err(PyTypeError::new_err(format!("{what} must be real numbers"))))
}

/// `value`'s numbers when it is an array of `T` in the machine's byte order (`check`ed first).
fn read<T: Element + Copy + Into<f64>>(
    value: &Bound<'_, PyAny>,
    check: &dyn Fn(&Shape<'_>) -> PyResult<()>,
) -> Option<PyResult<Vec<f64>>> {
    let array = value.cast::<PyArrayDyn<T>>().ok()?;
    if let Err(e) = check(&Shape(array.shape())) {
        return Some(Err(e));
    }
    // A copy in row-major order (any strides); the array is not borrowed past this call.
    Some(Ok(array.to_owned_array().iter().map(|&x| x.into()).collect()))
}
