//! `linearise_step`: the A and B of one integration step (semi-implicit Euler or RK4) for
//! MPC, from the analytical derivatives, with the model's gravity and armature (as the
//! other Pinocchio-style functions) and, on request, the model file's joint friction.

use crate::args::vector;
use crate::convert::matrix_to_numpy;
use crate::errors::err;
use crate::model::{PyData, PyModel};
use armsim::dynamics::{Effects, Friction, StepLinearisation, StepScheme};
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// `(A, B, x_next)`.
type Step<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// The discrete dynamics of one step of `dt` seconds from the state `x = (q, v)` with the
/// torque `tau` held over the step, and their Jacobians: `x_next`, `A = ∂x_next/∂x`
/// (2nv × 2nv, state order q then v) and `B = ∂x_next/∂tau` (2nv × nv), from the analytical
/// ABA derivatives. `integrator` is "rk4" (classic Runge–Kutta) or "semi_implicit_euler"
/// (`v⁺ = v + dt·a`, `q⁺ = q + dt·v⁺`, Crocoddyl's Euler). The model's gravity and
/// armature are included; `friction=True` adds the model file's joint damping (viscous)
/// and friction (Coulomb, smoothed by tanh over 1e-3 rad/s) with their slopes.
#[pyfunction]
#[pyo3(signature = (model, data, q, v, tau, dt, integrator="rk4", friction=false))]
#[allow(clippy::too_many_arguments)]
pub fn linearise_step<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
    dt: f64,
    integrator: &str,
    friction: bool,
) -> PyResult<Step<'py>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v, t) = (
        vector(q, "q", m.nv)?,
        vector(v, "v", m.nv)?,
        vector(tau, "tau", m.nv)?,
    );
    let scheme = match integrator {
        "rk4" => StepScheme::Rk4,
        "semi_implicit_euler" => StepScheme::SemiImplicitEuler,
        other => {
            return Err(PyValueError::new_err(format!(
                "integrator: '{other}' is not one of 'rk4', 'semi_implicit_euler'"
            )))
        }
    };
    armsim::model::derivative_data::derivatives_fit(m).map_err(err)?;
    let mut step = StepLinearisation::new(m, scheme, dt)
        .map_err(|e| PyValueError::new_err(format!("dt: {e}")))?;
    let mut effects = Effects::gravity(m.gravity);
    if friction {
        effects.friction = Some(Friction::from_model(m));
    }
    step.linearise(m, &mut data.data, &effects, q.slice(), v.slice(), t.slice())
        .map_err(err)?;
    Ok((
        matrix_to_numpy(py, step.a()),
        matrix_to_numpy(py, step.b()),
        PyArray1::from_slice(py, step.next_state()),
    ))
}
