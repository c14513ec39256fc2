//! Frame velocities and accelerations and the frame Jacobian's time variation, as
//! Pinocchio's `getFrameVelocity`, `getFrameAcceleration`,
//! `getFrameClassicalAcceleration` and `getFrameJacobianTimeVariation`, but each in one
//! call from `(q, v[, a])` (the kinematics pass runs inside, as in `frame_jacobian`).
//!
//! Spatial vectors are `(linear x y z, angular x y z)`; `reference` is
//! `"world_aligned"` (Pinocchio's LOCAL_WORLD_ALIGNED, the default here as for
//! `frame_jacobian`; Pinocchio's own default is LOCAL), `"local"` or `"world"`.

use crate::args::{self, vector};
use crate::convert::matrix_to_numpy;
use crate::dyn_calls::{finite_dmatrix, finite_values};
use crate::errors::err;
use crate::model::{PyData, PyModel};
use armsim::nalgebra::DMatrix;
use armsim::{kinematics, Expressed, Motion};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

/// `m` as a new 6-vector (linear, angular), or an error naming `what` when not finite.
fn motion_to_numpy<'py>(
    py: Python<'py>,
    what: &str,
    m: &Motion,
    inputs: &[(&str, &[f64])],
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let a = m.to_array();
    finite_values(what, &a, inputs).map_err(err)?;
    Ok(PyArray1::from_slice(py, &a))
}

/// The spatial velocity `(v, ω)` of `frame` at `(q, v)` in `reference` (see the module
/// docs): Pinocchio's `forwardKinematics(q, v)` + `getFrameVelocity(frame, reference)`.
/// Equals `frame_jacobian(model, data, q, frame, reference) @ v`.
#[pyfunction]
#[pyo3(signature = (model, data, q, v, frame, reference=None))]
pub fn frame_velocity<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    frame: &Bound<'py, PyAny>,
    reference: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v) = (vector(q, "q", m.nv)?, vector(v, "v", m.nv)?);
    let (f, e) = (args::frame(m, frame)?, args::reference(reference)?);
    kinematics::forward_kinematics_vel(m, &mut data.data, q.slice(), v.slice());
    let vel = kinematics::frame_velocity(m, &data.data, f, e);
    let inputs = [("q", q.slice()), ("v", v.slice())];
    motion_to_numpy(py, "the frame velocity", &vel, &inputs)
}

/// The spatial acceleration of `frame` at `(q, v, a)` in `reference`: Pinocchio's
/// `forwardKinematics(q, v, a)` + `getFrameAcceleration(frame, reference)`. Its linear
/// part is not the acceleration of the frame's origin (that is
/// `frame_classical_acceleration`).
#[pyfunction]
#[pyo3(signature = (model, data, q, v, a, frame, reference=None))]
#[allow(clippy::too_many_arguments)]
pub fn frame_acceleration<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
    frame: &Bound<'py, PyAny>,
    reference: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v, a) = (
        vector(q, "q", m.nv)?,
        vector(v, "v", m.nv)?,
        vector(a, "a", m.nv)?,
    );
    let (f, e) = (args::frame(m, frame)?, args::reference(reference)?);
    kinematics::forward_kinematics_acc(m, &mut data.data, q.slice(), v.slice(), a.slice());
    let acc = kinematics::frame_acceleration(m, &data.data, f, e);
    let inputs = [("q", q.slice()), ("v", v.slice()), ("a", a.slice())];
    motion_to_numpy(py, "the frame acceleration", &acc, &inputs)
}

/// The classical acceleration of `frame`: `(p̈, ω̇)`, the second derivative of its
/// origin and its angular acceleration, in world axes (`"world_aligned"`, the default) or
/// in the frame's axes (`"local"`): Pinocchio's `getFrameClassicalAcceleration` after
/// `forwardKinematics(q, v, a)`. At `a = 0` it is the acceleration drift
/// `J̇(q, v) v` of the world-aligned Jacobian. `"world"` is refused: the classical
/// acceleration is that of the frame's origin, which the world expression does not use.
#[pyfunction]
#[pyo3(signature = (model, data, q, v, a, frame, reference=None))]
#[allow(clippy::too_many_arguments)]
pub fn frame_classical_acceleration<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
    frame: &Bound<'py, PyAny>,
    reference: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v, a) = (
        vector(q, "q", m.nv)?,
        vector(v, "v", m.nv)?,
        vector(a, "a", m.nv)?,
    );
    let (f, e) = (args::frame(m, frame)?, args::reference(reference)?);
    if e == Expressed::World {
        return Err(err(
            "reference: the classical acceleration is the acceleration of the frame's \
             origin; use \"world_aligned\" (world axes) or \"local\", not \"world\"",
        ));
    }
    kinematics::forward_kinematics_acc(m, &mut data.data, q.slice(), v.slice(), a.slice());
    let acc = kinematics::frame_classical_acceleration(m, &data.data, f, e);
    let inputs = [("q", q.slice()), ("v", v.slice()), ("a", a.slice())];
    motion_to_numpy(py, "the classical acceleration", &acc, &inputs)
}

/// `J̇(q, v)`, the 6×nv time derivative of `frame_jacobian(model, data, q, frame,
/// reference)` along the velocity `v`: Pinocchio's `computeJointJacobiansTimeVariation(q,
/// v)` + `getFrameJacobianTimeVariation(frame, reference)`. `J̇ @ v` is the acceleration
/// drift, the acceleration at `a = 0`: the spatial one (`frame_acceleration`) for
/// `"local"` and `"world"`, the classical one (`frame_classical_acceleration`) for
/// `"world_aligned"`.
#[pyfunction]
#[pyo3(signature = (model, data, q, v, frame, reference=None))]
pub fn frame_jacobian_time_variation<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    frame: &Bound<'py, PyAny>,
    reference: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v) = (vector(q, "q", m.nv)?, vector(v, "v", m.nv)?);
    let (f, e) = (args::frame(m, frame)?, args::reference(reference)?);
    let d = &mut data.data;
    kinematics::compute_joint_jacobians_time_variation(m, d, q.slice(), v.slice());
    let mut dj = DMatrix::zeros(6, m.nv);
    kinematics::frame_jacobian_time_variation(m, d, f, e, &mut dj);
    let inputs = [("q", q.slice()), ("v", v.slice())];
    finite_dmatrix("dJ", &dj, &inputs).map_err(err)?;
    Ok(matrix_to_numpy(py, &dj))
}
