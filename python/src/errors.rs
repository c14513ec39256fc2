//! Python exceptions and warnings: `armsim.ArmsimError` (a `ValueError`) carries the
//! crate's located messages (`file:line: element: message`); a missing file is a
//! `FileNotFoundError`; the model loader's warnings are `armsim.LoaderWarning` (a
//! `UserWarning`).

use pyo3::exceptions::{PyFileNotFoundError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use std::ffi::CString;
use std::path::Path;

pyo3::create_exception!(
    armsim,
    ArmsimError,
    PyValueError,
    "A refused input or a failed computation; the message names the file, the line, the element and the problem."
);

pyo3::create_exception!(
    armsim,
    LoaderWarning,
    PyUserWarning,
    "A model file loaded, with a problem worth knowing (a floating joint modelled as six one-axis joints, a non-physical inertia clamped, ...); the message names the file, the line and the element. `strict=True` makes it an error."
);

/// Issues `msg` as a Python `LoaderWarning` (an error when the warning filters say so).
pub fn loader_warning(py: Python<'_>, msg: &str) -> PyResult<()> {
    let text = CString::new(msg.replace('\0', " ")).expect("NUL bytes replaced");
    PyErr::warn(py, &py.get_type::<LoaderWarning>(), &text, 1)
}

/// An `ArmsimError` with `msg`.
pub fn err(msg: impl std::fmt::Display) -> PyErr {
    ArmsimError::new_err(msg.to_string())
}

/// `FileNotFoundError` unless `path` is an existing file.
pub fn require_file(path: &Path) -> PyResult<()> {
    if path.is_file() {
        Ok(())
    } else if path.exists() {
        Err(err(format!("{}: not a regular file", path.display())))
    } else {
        Err(PyFileNotFoundError::new_err(format!(
            "{}: no such file",
            path.display()
        )))
    }
}
