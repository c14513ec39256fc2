//! Errors and warnings of the planning inputs (MoveIt scenes and requests, SRDF, benchmark
//! lists): every message names the file, the line where it is known, the element and the
//! problem, as `FILE:LINE: ELEMENT: MESSAGE`.

use std::fmt;

/// A problem found while reading a planning input file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct PlanningInputError {
    /// The file being read (as the caller named it).
    pub file: String,
    /// 1-based line of the offending element, where known.
    pub line: Option<usize>,
    /// The element, e.g. `world.collision_objects[2] 'table'.primitives[0].dimensions`.
    pub element: String,
    /// What is wrong.
    pub message: String,
}

impl PlanningInputError {
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

impl fmt::Display for PlanningInputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}: {}", self.file, l, self.element, self.message),
            None => write!(f, "{}: {}: {}", self.file, self.element, self.message),
        }
    }
}

/// A problem that does not stop reading (an SRDF pair naming an unknown link, a request
/// naming a joint the model does not move); same fields as an error.
pub type PlanningInputWarning = PlanningInputError;
