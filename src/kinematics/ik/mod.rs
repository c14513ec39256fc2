//! Inverse kinematics: numeric (Levenberg–Marquardt with limits and restarts), analytic
//! (closed forms returning every branch), and a velocity-level QP step.

pub mod analytic;
pub mod benchmark;
pub mod numeric;
pub mod qp;

pub use numeric::{rotation_log, solve_batch, IkOptions, IkResult, IkSolver, IkStatus};

/// Targets farther than this from the world origin in any coordinate (m) are refused by
/// the readers of targets (CLI, Python) and unreachable for the analytic solvers: their
/// squared distances would overflow long before, and no arm reaches them.
pub const MAX_TARGET_DISTANCE: f64 = 1e9;
