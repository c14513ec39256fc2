//! Trajectories through joint waypoints, time-optimal path parameterisation, and the
//! torque-requirement check. One file per algorithm, each citing its equations:
//!
//! - [`Trapezoidal`] (`trapezoidal.rs`): trapezoidal velocity per segment, stop at every
//!   waypoint, joints synchronised on the slowest one;
//! - [`Quintic`] (`quintic.rs`): the rest-to-rest quintic `10u³ − 15u⁴ + 6u⁵` per segment;
//! - [`MinJerk`] (`min_jerk.rs`): the minimum-jerk quintic spline through via points (C⁴
//!   at interior knots), segment times scaled to the limits;
//! - [`CartesianMove`] (`cartesian.rs`): a straight tool line (linear position, slerp
//!   rotation) solved by IK sample by sample;
//! - [`topp`] (`topp/`): time-optimal path parameterisation under joint velocity,
//!   acceleration and torque limits, by reachability analysis (TOPP-RA, Pham & Pham 2018;
//!   `reachability.rs`, its two-variable LPs in `lp2.rs`) or, as [`ToppMethod::Conic`],
//!   the second-order-cone program of Verscheure et al. (2009) with clarabel (`socp.rs`);
//!   verified by a dense check with repairs (`check.rs`); optional jerk limits by
//!   smoothing and slowing down (`jerk.rs`);
//! - [`check_torques`] (`torque_check.rs`): peak / RMS torque, peak speed and power, margins
//!   and the first violation time of every limit along any trajectory, with a text table,
//!   JSON rows and a PNG/SVG plot (`plot.rs`), whose axis labels come from [`ticks`]
//!   (nice tick positions, labels with a common power of ten);
//! - [`panels`] (`panels.rs`): line panels and bar charts shared by the trade-offs report
//!   and the machine scenarios' pictures.
//!
//! Also [`TimeScaled`] (uniform slow-down of any trajectory), [`LinearPath`] and
//! [`SplinePath`] (paths for TOPP), and [`AsReference`] (any trajectory as the simulator's
//! reference).
//!
//! A [`Trajectory`] is sampled in time, `t ↦ (q, q̇, q̈)`, clamped to `[0, duration]`; a
//! [`Path`] is a geometric curve `s ↦ (q, q', q'')` for `s ∈ [0, 1]` (what TOPP times).
//! Sampling allocates nothing.

mod cartesian;
mod joint_limits;
mod min_jerk;
mod motion_traits;
mod quintic;
mod topp;
pub mod torque_check;
mod trajectory_error;
mod trapezoidal;
mod waypoints;
pub use crate::motion::cartesian::{
    cartesian_line, CartesianMove, CartesianOptions, CartesianReport, SplinePath,
};
pub use crate::motion::joint_limits::JointLimits;
pub use crate::motion::min_jerk::MinJerk;
pub use crate::motion::motion_traits::{AsReference, Path, TimeScaled, Trajectory};
pub use crate::motion::quintic::Quintic;
pub use crate::motion::topp::{
    topp, LinearPath, ToppMethod, ToppOptions, ToppStats, ToppTrajectory,
};
pub use crate::motion::torque_check::{
    check_torques, check_torques_switched, JointCheck, TorqueCheckOptions, TorqueReport,
};
pub use crate::motion::trajectory_error::TrajectoryError;
pub use crate::motion::trapezoidal::Trapezoidal;
