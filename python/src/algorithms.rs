//! The Pinocchio-style functions on `(model, data, ...)`: forward kinematics, frame
//! Jacobians in three expressions, RNEA, ABA, CRBA, gravity and nonlinear effects, the
//! RNEA and ABA derivatives and `M⁻¹`. Inputs
//! are checked (lengths, NaN, frame, data of this model) before any Rust algorithm runs.

use crate::args::{self, vector};
use crate::convert::{matrix_to_numpy, symmetric_to_numpy};
use crate::dyn_calls;
use crate::errors::err;
use crate::model::{PyData, PyModel};
use armsim::kinematics;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;

/// Forward kinematics at `q`: every frame's placement is updated in `data`.
#[pyfunction]
pub fn forward_kinematics(
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'_, PyAny>,
) -> PyResult<()> {
    data.check_model(model)?;
    let m = &*model.model;
    let q = vector(q, "q", m.nv)?;
    kinematics::forward_kinematics(m, &mut data.data, q.slice());
    Ok(())
}

/// The 6×nv Jacobian of `frame` at `q` (rows: linear x y z, angular x y z), in
/// `reference` = "world_aligned" (LOCAL_WORLD_ALIGNED), "local" or "world". Like
/// Pinocchio's `computeFrameJacobian`, it runs forward kinematics on the frame's support
/// only: the placements of the bodies after the frame's body are left as they were.
#[pyfunction]
#[pyo3(signature = (model, data, q, frame, reference=None))]
pub fn frame_jacobian<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    frame: &Bound<'py, PyAny>,
    reference: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let q = vector(q, "q", m.nv)?;
    let f = args::frame(m, frame)?;
    let e = args::reference(reference)?;
    // SAFETY: a fresh C-ordered array, written in full (zeros, then the columns) before
    // Python sees it.
    let arr = unsafe { PyArray2::<f64>::new(py, [6, m.nv], false) };
    let out = unsafe { arr.as_slice_mut() }.expect("fresh C-ordered array");
    kinematics::compute_frame_jacobian(m, &mut data.data, q.slice(), f, e, out);
    Ok(arr)
}

/// Inverse dynamics `τ = M(q) a + C(q, v) v + g(q)` with the model's gravity.
#[pyfunction]
pub fn rnea<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v, a) = (
        vector(q, "q", m.nv)?,
        vector(v, "v", m.nv)?,
        vector(a, "a", m.nv)?,
    );
    let tau = dyn_calls::rnea(m, &mut data.data, q.slice(), v.slice(), a.slice()).map_err(err)?;
    Ok(PyArray1::from_slice(py, tau))
}

/// Forward dynamics `q̈` for torques `tau` with the model's gravity.
#[pyfunction]
pub fn aba<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v, t) = (
        vector(q, "q", m.nv)?,
        vector(v, "v", m.nv)?,
        vector(tau, "tau", m.nv)?,
    );
    let ddq = dyn_calls::aba(m, &mut data.data, q.slice(), v.slice(), t.slice()).map_err(err)?;
    Ok(PyArray1::from_slice(py, ddq))
}

/// The joint-space mass matrix `M(q)` (full and symmetric).
#[pyfunction]
pub fn crba<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let q = vector(q, "q", m.nv)?;
    let mass = dyn_calls::crba(m, &mut data.data, q.slice()).map_err(err)?;
    Ok(symmetric_to_numpy(py, mass))
}

/// Generalised gravity torques `g(q)`.
#[pyfunction]
pub fn compute_generalized_gravity<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let q = vector(q, "q", m.nv)?;
    Ok(PyArray1::from_slice(
        py,
        dyn_calls::gravity(m, &mut data.data, q.slice()).map_err(err)?,
    ))
}

/// Nonlinear effects `h(q, v) = C(q, v) v + g(q)`.
#[pyfunction]
pub fn nonlinear_effects<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v) = (vector(q, "q", m.nv)?, vector(v, "v", m.nv)?);
    let h = dyn_calls::nonlinear_effects(m, &mut data.data, q.slice(), v.slice()).map_err(err)?;
    Ok(PyArray1::from_slice(py, h))
}

/// `(dtau_dq, dtau_dv, M)`: the partial derivatives of `τ = rnea(q, v, a)` (Carpentier &
/// Mansard's analytical RNEA derivatives, as Pinocchio's `computeRNEADerivatives`).
#[pyfunction]
pub fn rnea_derivatives<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
) -> PyResult<Matrices3<'py>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v, a) = (
        vector(q, "q", m.nv)?,
        vector(v, "v", m.nv)?,
        vector(a, "a", m.nv)?,
    );
    let p = dyn_calls::rnea_derivatives(m, &mut data.data, q.slice(), v.slice(), a.slice())
        .map_err(err)?;
    Ok((
        matrix_to_numpy(py, p.dtau_dq),
        matrix_to_numpy(py, p.dtau_dv),
        symmetric_to_numpy(py, p.mass),
    ))
}

/// `(ddq_dq, ddq_dv, Minv)`: the partial derivatives of `ddq = aba(q, v, tau)`, the last
/// being `∂q̈/∂τ = M⁻¹` (as Pinocchio's `computeABADerivatives`).
#[pyfunction]
pub fn aba_derivatives<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
) -> PyResult<Matrices3<'py>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v, t) = (
        vector(q, "q", m.nv)?,
        vector(v, "v", m.nv)?,
        vector(tau, "tau", m.nv)?,
    );
    let p = dyn_calls::aba_derivatives(m, &mut data.data, q.slice(), v.slice(), t.slice())
        .map_err(err)?;
    Ok((
        matrix_to_numpy(py, p.ddq_dq),
        matrix_to_numpy(py, p.ddq_dv),
        symmetric_to_numpy(py, p.minv),
    ))
}

/// The inverse of the joint-space mass matrix, `M(q)⁻¹` (full and symmetric), as
/// Pinocchio's `computeMinverse`: above 12 coordinates in O(n²) without forming `M`, up
/// to 12 (where that is faster) from `M` through its Cholesky factor.
#[pyfunction]
pub fn compute_minverse<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let q = vector(q, "q", m.nv)?;
    let minv = dyn_calls::compute_minverse(m, &mut data.data, q.slice()).map_err(err)?;
    Ok(symmetric_to_numpy(py, minv))
}

/// Three nv × nv arrays.
type Matrices3<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
);
