//! The robot's centre of mass and its Jacobian (Pinocchio's `centerOfMass` and
//! `jacobianCenterOfMass`), over the bodies that move (links fixed to the world are left
//! out, as Pinocchio leaves out the universe's inertia).

use crate::args::vector;
use crate::convert::matrix_to_numpy;
use crate::dyn_calls;
use crate::errors::err;
use crate::model::{PyData, PyModel};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

/// The world position (3,) of the centre of mass at `q` (Pinocchio's
/// `centerOfMass(model, data, q)`). A model without mass raises `ArmsimError`.
#[pyfunction]
pub fn center_of_mass<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let q = vector(q, "q", m.nv)?;
    let c = dyn_calls::center_of_mass(m, &mut data.data, q.slice()).map_err(err)?;
    Ok(PyArray1::from_slice(py, c.as_slice()))
}

/// The 3×nv Jacobian of the centre of mass at `q`, world axes: `ċ = J_com v`
/// (Pinocchio's `jacobianCenterOfMass(model, data, q)`).
#[pyfunction]
pub fn jacobian_center_of_mass<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let q = vector(q, "q", m.nv)?;
    let j = dyn_calls::jacobian_center_of_mass(m, &mut data.data, q.slice()).map_err(err)?;
    Ok(matrix_to_numpy(py, &j))
}
