//! Why the analytic solvers give no solution: [`IkError`] for the caller, and the
//! [`Unreachable`] reason the fixed-size solvers return.

/// Why the analytic solver gives no solution.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IkError {
    /// The model (or the chosen link) is not one of the supported families.
    #[error("analytic IK does not support this model: {0}")]
    Unsupported(String),
    /// The target is outside the workspace (no solution, limits aside).
    #[error("unreachable target: {0}")]
    Unreachable(String),
    /// Solutions exist, but none within the joint limits.
    #[error("no solution inside the joint limits ({candidates} solutions outside them)")]
    OutsideLimits {
        /// How many solutions the limits rejected.
        candidates: usize,
    },
    /// A non-finite target or a malformed seed.
    #[error("invalid input: {0}")]
    InvalidInput(String),
}

/// The reason the fixed-size solvers give for an unreachable target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unreachable(pub &'static str);
