//! The discretised problem both solvers see: the path and dynamics at the grid points
//! ([`Grid`]) and the grid, limits, tightening and friction of one solve ([`Problem`]).

use crate::motion::joint_limits::JointLimits;

/// Path and dynamics at the grid points.
pub(super) struct Grid {
    pub(super) dq: Vec<f64>,
    pub(super) ddq: Vec<f64>,
    pub(super) m: Vec<f64>,
    pub(super) c: Vec<f64>,
    pub(super) g: Vec<f64>,
}

/// One discretised problem: the grid, the limits less their tightening (per knot for
/// velocity, per interval for acceleration and torque), the friction estimate per knot.
#[derive(Clone, Copy)]
pub(super) struct Problem<'a> {
    pub(super) grid: &'a Grid,
    pub(super) s: &'a [f64],
    pub(super) ds: &'a [f64],
    pub(super) limits: &'a JointLimits,
    pub(super) torque_on: &'a [bool],
    pub(super) tight_v: &'a [f64],
    pub(super) tight_a: &'a [f64],
    pub(super) tight_t: &'a [f64],
    pub(super) fric: &'a [f64],
}
