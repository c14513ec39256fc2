//! IK options from Python keywords and `armsim.IkResult` (q, status, residual, reason).

use crate::errors::err;
use armsim::{IkOptions, IkSolution};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::time::Duration;

/// No wall-clock budget (iteration and restart limits only: deterministic results).
const NO_BUDGET: Duration = Duration::from_secs(86_400 * 365);

/// The keywords IK takes, with armsim's defaults except `time_budget` (None: no
/// wall-clock limit, so the same seed gives the same answer on any machine).
pub const IK_KEYWORDS: &str = "position_only, tol_position, tol_rotation, max_iterations, max_restarts, time_budget (s or None), respect_limits, seed, rotation_weight";

/// Reads IK keywords into options.
pub fn options(kw: Option<&Bound<'_, PyDict>>) -> PyResult<IkOptions> {
    let mut o = IkOptions {
        time_budget: NO_BUDGET,
        ..IkOptions::default()
    };
    let Some(kw) = kw else { return Ok(o) };
    for (k, v) in kw.iter() {
        let key: String = k.extract()?;
        let bad = |e: PyErr| err(format!("IK option {key}: {e}"));
        let opt = format!("IK option {key}");
        match key.as_str() {
            "position_only" => o.position_only = v.extract().map_err(bad)?,
            "tol_position" => o.tol_position = positive(&key, v.extract().map_err(bad)?)?,
            "tol_rotation" => o.tol_rotation = positive(&key, v.extract().map_err(bad)?)?,
            "max_iterations" => {
                o.max_iterations =
                    crate::args::size(v.extract::<crate::args::Int>().map_err(bad)?, &opt)?
            }
            "max_restarts" => {
                o.max_restarts =
                    crate::args::size(v.extract::<crate::args::Int>().map_err(bad)?, &opt)?
            }
            "respect_limits" => o.respect_limits = v.extract().map_err(bad)?,
            "seed" => {
                o.seed = crate::args::seed(v.extract::<crate::args::Int>().map_err(bad)?, &opt)?
            }
            "rotation_weight" => o.rotation_weight = positive(&key, v.extract().map_err(bad)?)?,
            "time_budget" => {
                let t: Option<f64> = v.extract().map_err(bad)?;
                o.time_budget = match t {
                    None => NO_BUDGET,
                    Some(s) => Duration::from_secs_f64(positive(&key, s)?),
                };
            }
            _ => {
                return Err(err(format!(
                    "unknown IK option '{key}' (expected {IK_KEYWORDS})"
                )))
            }
        }
    }
    Ok(o)
}

fn positive(key: &str, x: f64) -> PyResult<f64> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(err(format!(
            "IK option {key}: {x} is not a positive number"
        )))
    }
}

/// The answer of an IK solve.
#[pyclass(module = "armsim", name = "IkResult", get_all, frozen)]
pub struct IkResult {
    /// The joint values.
    pub q: Py<PyArray1<f64>>,
    /// "converged", "best_effort" or "unreachable".
    pub status: &'static str,
    /// Position error of `q`'s pose (m).
    pub position_error: f64,
    /// Rotation error (rad; 0 for position-only solves).
    pub rotation_error: f64,
    /// Iterations over all attempts.
    pub iterations: usize,
    /// Why it ended, in words.
    pub reason: String,
}

#[pymethods]
impl IkResult {
    /// Whether both errors are within the tolerances.
    #[getter]
    fn converged(&self) -> bool {
        self.status == "converged"
    }

    /// `(position_error, rotation_error)`.
    #[getter]
    fn residual(&self) -> (f64, f64) {
        (self.position_error, self.rotation_error)
    }

    fn __repr__(&self) -> String {
        format!(
            "IkResult(status='{}', position_error={:.3e}, rotation_error={:.3e}, reason='{}')",
            self.status, self.position_error, self.rotation_error, self.reason
        )
    }
}

impl IkResult {
    pub fn new(py: Python<'_>, s: IkSolution) -> IkResult {
        IkResult {
            q: PyArray1::from_vec(py, s.q).unbind(),
            status: s.status.as_str(),
            position_error: s.position_error,
            rotation_error: s.rotation_error,
            iterations: s.iterations,
            reason: s.reason,
        }
    }
}
