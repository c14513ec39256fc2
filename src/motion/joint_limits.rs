//! [`JointLimits`]: the velocity, acceleration, effort and jerk limits of the joints, and
//! their check.

use crate::model::Model;
use crate::motion::trajectory_error::TrajectoryError;

/// Joint velocity, acceleration and effort limits, one value per coordinate. An effort of
/// `+∞` means "no torque limit" (TOPP then leaves that joint's torque free).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JointLimits {
    /// Velocity limit (rad/s or m/s), > 0.
    pub velocity: Vec<f64>,
    /// Acceleration limit (rad/s² or m/s²), > 0.
    pub acceleration: Vec<f64>,
    /// Effort limit (N m or N), > 0 or `+∞`.
    pub effort: Vec<f64>,
    /// Jerk limit (rad/s³ or m/s³), > 0 (`+∞`: none for that joint), one value per
    /// coordinate; `None` (the default) for no jerk limit. Only [`topp`](fn@super::topp) applies it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jerk: Option<Vec<f64>>,
}

impl JointLimits {
    /// Velocity and effort limits from the model, the given accelerations (the model file
    /// has none).
    pub fn from_model(model: &Model, acceleration: Vec<f64>) -> Self {
        JointLimits {
            velocity: model.velocity_limit.clone(),
            acceleration,
            effort: model.effort_limit.clone(),
            jerk: None,
        }
    }

    /// The same limits for every one of `n` coordinates.
    pub fn uniform(n: usize, velocity: f64, acceleration: f64, effort: f64) -> Self {
        JointLimits {
            velocity: vec![velocity; n],
            acceleration: vec![acceleration; n],
            effort: vec![effort; n],
            jerk: None,
        }
    }

    /// Checks lengths and values: velocity and acceleration finite and positive, effort
    /// and jerk (if any) positive (infinite allowed). `names` label the joints in messages.
    pub fn validate(&self, names: &[String]) -> Result<(), TrajectoryError> {
        let n = names.len();
        if let Some(jerk) = &self.jerk {
            if jerk.len() != n {
                return Err(TrajectoryError::Invalid(format!(
                    "jerk limits: {} values for {n} joints",
                    jerk.len()
                )));
            }
            if let Some(k) = jerk.iter().position(|x| x.is_nan() || *x <= 0.0) {
                return Err(TrajectoryError::Invalid(format!(
                    "joint {}: the jerk limit must be positive or inf (got {})",
                    names[k], jerk[k]
                )));
            }
        }
        for (what, v) in [
            ("velocity", &self.velocity),
            ("acceleration", &self.acceleration),
            ("effort", &self.effort),
        ] {
            if v.len() != n {
                return Err(TrajectoryError::Invalid(format!(
                    "{what} limits: {} values for {n} joints",
                    v.len()
                )));
            }
        }
        for (k, name) in names.iter().enumerate() {
            for (what, x, inf_ok) in [
                ("velocity", self.velocity[k], false),
                ("acceleration", self.acceleration[k], false),
                ("effort", self.effort[k], true),
            ] {
                let good = x > 0.0 && (x.is_finite() || (inf_ok && x == f64::INFINITY));
                if !good {
                    return Err(TrajectoryError::Invalid(format!(
                        "joint {name}: the {what} limit must be {} (got {x})",
                        if inf_ok {
                            "positive or inf"
                        } else {
                            "finite and positive (the model gives none: set one)"
                        }
                    )));
                }
            }
        }
        Ok(())
    }
}
