//! Python exceptions: `armsim.ArmsimError` (a `ValueError`) carries the crate's located
//! messages (`file:line: element: message`); a missing file is a `FileNotFoundError`.

use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use std::path::Path;

pyo3::create_exception!(
    armsim,
    ArmsimError,
    PyValueError,
    "A refused input or a failed computation; the message names the file, the line, the element and the problem."
);

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
