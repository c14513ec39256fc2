//! The terms of the Lagrangian dynamics `τ = M(q) a + C(q, v) v + g(q)` that the other
//! bindings do not return: the kinetic and potential energies and the Coriolis matrix
//! (Pinocchio's `computeKineticEnergy`, `computePotentialEnergy`, `computeCoriolisMatrix`).

use crate::args::vector;
use crate::convert::matrix_to_numpy;
use crate::dyn_calls;
use crate::errors::err;
use crate::model::{PyData, PyModel};
use numpy::PyArray2;
use pyo3::prelude::*;

/// The kinetic energy `½ vᵀ M(q) v` (J) at `(q, v)` (Pinocchio's
/// `computeKineticEnergy(model, data, q, v)`); the model's armature is included (zero
/// for a URDF).
#[pyfunction]
pub fn compute_kinetic_energy(
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'_, PyAny>,
    v: &Bound<'_, PyAny>,
) -> PyResult<f64> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v) = (vector(q, "q", m.nv)?, vector(v, "v", m.nv)?);
    dyn_calls::kinetic_energy(m, &mut data.data, q.slice(), v.slice()).map_err(err)
}

/// The potential energy `−Σ m_i gᵀ c_i` (J) at `q` in the model's gravity, zero at the
/// world origin (Pinocchio's `computePotentialEnergy(model, data, q)`).
#[pyfunction]
pub fn compute_potential_energy(
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'_, PyAny>,
) -> PyResult<f64> {
    data.check_model(model)?;
    let m = &*model.model;
    let q = vector(q, "q", m.nv)?;
    dyn_calls::potential_energy(m, &mut data.data, q.slice()).map_err(err)
}

/// The nv×nv Coriolis matrix `C(q, v)` of the Christoffel symbols of `M(q)`:
/// `C_ij = Σ_k ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i) v_k`, so that `C v` is
/// `nonlinear_effects − gravity` and `Ṁ − 2C` is skew-symmetric (the matrix of
/// Pinocchio's `computeCoriolisMatrix`). A dense reference algorithm, O(nv⁴): refused
/// above 200 coordinates.
#[pyfunction]
pub fn compute_coriolis_matrix<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v) = (vector(q, "q", m.nv)?, vector(v, "v", m.nv)?);
    let c = dyn_calls::coriolis_matrix(m, &mut data.data, q.slice(), v.slice()).map_err(err)?;
    Ok(matrix_to_numpy(py, &c))
}
