//! [`MeshError`]: what is wrong with mesh data, before the file it came from is known —
//! the format read, the line where the format is text and the place is known, and the
//! problem — and its [`LocatedError`] once the file is known ([`MeshError::in_file`]).

use crate::core::diag::LocatedError;
use std::fmt;

/// A mesh that cannot be read. Displayed as the reader's message (`FORMAT: MESSAGE`, e.g.
/// `OBJ: line 5: index 0 of a vertex is out of range (3 in the file, from 1)`); the line,
/// when known, is also kept apart for [`MeshError::in_file`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct MeshError {
    /// The format read (`STL`, `binary STL`, `ASCII STL`, `OBJ`, `DAE`), or empty when the
    /// message names it itself.
    pub format: &'static str,
    /// 1-based line of the problem in a text format, where known.
    pub line: Option<usize>,
    /// What is wrong (after the format).
    pub message: String,
}

impl MeshError {
    /// Builds an error.
    pub fn new(format: &'static str, line: Option<usize>, message: impl Into<String>) -> Self {
        Self {
            format,
            line,
            message: message.into(),
        }
    }

    /// The same error with `prefix: ` put before its message (the format stays in front).
    pub fn context(mut self, prefix: impl fmt::Display) -> Self {
        self.message = format!("{prefix}: {}", self.message);
        self
    }

    /// The located error of this problem in mesh file `file`: the line, the format as the
    /// element (`mesh` when the message names it), the message.
    pub fn in_file(self, file: &str) -> LocatedError {
        let element = if self.format.is_empty() {
            "mesh"
        } else {
            self.format
        };
        LocatedError::new(file, self.line, element, self.message)
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.format.is_empty() {
            f.write_str(&self.message)
        } else {
            write!(f, "{}: {}", self.format, self.message)
        }
    }
}

/// A triangle corner with a coordinate that is not finite (a mesh-loader f32 overflow, or
/// a DAE placement that overflows).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("vertex ({}, {}, {}) is not finite", .0[0], .0[1], .0[2])]
pub struct NonFiniteVertex(pub [f64; 3]);
