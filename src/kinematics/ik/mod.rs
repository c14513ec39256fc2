//! Inverse kinematics: numeric (Levenberg–Marquardt with limits and restarts), analytic
//! (closed forms returning every branch), and a velocity-level QP step.

pub mod analytic;
pub mod benchmark;
pub mod numeric;
pub mod qp;

pub use numeric::{rotation_log, solve_batch, IkOptions, IkResult, IkSolver, IkStatus};
