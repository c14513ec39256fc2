//! One recorded simulation sample ([`SimSample`]): what the simulation step records, the
//! output files and the simulation plot read, and [`super::Outcome`] returns.

/// One recorded simulation sample.
#[derive(Clone, Debug)]
pub struct SimSample {
    /// Time (s).
    pub t: f64,
    /// Joint positions (rad or m).
    pub q: Vec<f64>,
    /// Joint velocities (rad/s or m/s).
    pub qd: Vec<f64>,
    /// Applied joint torques (N·m or N).
    pub tau: Vec<f64>,
    /// The reference the controller tracks (rad or m).
    pub q_ref: Vec<f64>,
}
