//! Load errors and warnings: every message names the file, the element and the problem,
//! and the line where the loader knows it.

use std::fmt;

/// An error found while loading a model file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct ModelError {
    /// The file being read (as the user named it).
    pub file: String,
    /// 1-based line of the offending element, where known.
    pub line: Option<usize>,
    /// The element, e.g. `joint 'j3'`, `link 'l2'`, `DH row 4`.
    pub element: String,
    /// What is wrong.
    pub message: String,
}

impl ModelError {
    /// Builds an error.
    pub fn new(
        file: impl Into<String>,
        line: Option<usize>,
        element: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            file: file.into(),
            line,
            element: element.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}: {}", self.file, l, self.element, self.message),
            None => write!(f, "{}: {}: {}", self.file, self.element, self.message),
        }
    }
}

/// A problem that does not stop loading (e.g. an inertia breaking the triangle
/// inequality, as real files such as iCub's do). `--strict` turns warnings into errors.
pub type ModelWarning = ModelError;
