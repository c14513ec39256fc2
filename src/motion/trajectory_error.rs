//! [`TrajectoryError`]: why a trajectory could not be built or checked.

/// Why a trajectory could not be built or checked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrajectoryError {
    /// Bad input (waypoints, limits, options).
    #[error("{0}")]
    Invalid(String),
    /// A Cartesian sample the IK could not reach.
    #[error(
        "Cartesian move: sample {index} of {samples} (s = {s:.4}) is unreachable: IK {status}, \
         position error {position_error:.3e} m, rotation error {rotation_error:.3e} rad"
    )]
    Unreachable {
        /// Sample index along the line.
        index: usize,
        /// Number of samples.
        samples: usize,
        /// Path parameter of the sample.
        s: f64,
        /// IK status (`unreachable` or `best_effort`).
        status: &'static str,
        /// Position residual (m).
        position_error: f64,
        /// Rotation residual (rad).
        rotation_error: f64,
    },
    /// Two consecutive Cartesian samples on different IK branches.
    #[error(
        "Cartesian move: joint {joint} jumps by {step:.3} rad between samples {index} and {} \
         (more than {max:.3}): the IK changed branch (near a singularity or a limit); use more \
         samples or another start configuration",
        index + 1
    )]
    BranchJump {
        /// Sample index before the jump.
        index: usize,
        /// Joint name.
        joint: String,
        /// Step size (rad or m).
        step: f64,
        /// Allowed step.
        max: f64,
    },
    /// The time-optimal problem could not be solved.
    #[error("TOPP: {0}")]
    Topp(String),
    /// Output could not be written.
    #[error("{0}")]
    Output(String),
}
