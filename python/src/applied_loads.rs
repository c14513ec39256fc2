//! Inverse and forward dynamics with loads applied to the links: external wrenches and a
//! rigid payload (the crate's `dynamics::Effects`, with the model's gravity), and the
//! reading of those two arguments from Python.
//!
//! - `wrenches={frame: [fx, fy, fz, mx, my, mz]}`: the force (N) and the moment (N m)
//!   about the frame's **origin**, both in **world axes**, acting on the frame's link.
//!   (Pinocchio's `fext[j]` is one wrench per joint in that joint's local frame:
//!   `fext[j] = data.oMi[j].actInv(pin.Force(f, m + p × f))` with `p` the frame origin.)
//!   A wrench on a link fixed to the world loads no joint.
//! - `payload={"frame": ..., "mass": kg, "com": [x, y, z], "inertia": 3×3}`: a rigid body
//!   fixed to the frame's link, its centre of mass and its inertia tensor about that centre
//!   in the frame's axes (`com` and `inertia` default to zero). The same as adding
//!   `frame.placement.act(pin.Inertia(mass, com, inertia))` to the inertia of the frame's
//!   joint in Pinocchio.

use crate::args::{self, vector};
use crate::dyn_calls;
use crate::errors::err;
use crate::model::{PyData, PyModel};
use armsim::core::spatial::Inertia;
use armsim::dynamics::{Effects, ExternalWrench, Payload};
use armsim::{Mat3, Model, Vec3};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The keys a payload dict accepts.
const PAYLOAD_KEYS: [&str; 4] = ["frame", "mass", "com", "inertia"];

/// `obj` as a dict, or an error naming the argument `what` and the form expected.
fn dict<'a, 'py>(
    obj: &'a Bound<'py, PyAny>,
    what: &str,
    form: &str,
) -> PyResult<&'a Bound<'py, PyDict>> {
    obj.cast::<PyDict>().map_err(|_| {
        let given = obj
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_default();
        err(format!("{what}: expected a dict {form}, got {given}"))
    })
}

/// A frame argument inside `what`, its error message prefixed by `what`.
fn frame_in(m: &Model, obj: &Bound<'_, PyAny>, what: &str) -> PyResult<usize> {
    args::frame(m, obj).map_err(|e| err(format!("{what}: {}", e.value(obj.py()))))
}

/// The `wrenches` argument (see the module docs); none when not given.
fn wrenches(m: &Model, obj: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<ExternalWrench>> {
    let Some(obj) = obj else {
        return Ok(Vec::new());
    };
    let d = dict(obj, "wrenches", "{frame: [fx, fy, fz, mx, my, mz]}")?;
    let mut out = Vec::with_capacity(d.len());
    for (key, value) in d.iter() {
        let link = frame_in(m, &key, "wrenches")?;
        let what = format!("wrenches['{}']", m.links[link].name);
        let w = vector(&value, &what, 6)?;
        let s = w.slice();
        out.push(ExternalWrench {
            link,
            force: Vec3::new(s[0], s[1], s[2]),
            moment: Vec3::new(s[3], s[4], s[5]),
        });
    }
    Ok(out)
}

/// The `payload` argument (see the module docs); none when not given.
fn payload(m: &Model, obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Payload>> {
    let Some(obj) = obj else {
        return Ok(None);
    };
    let d = dict(
        obj,
        "payload",
        "{\"frame\", \"mass\", \"com\", \"inertia\"}",
    )?;
    for key in d.keys() {
        let k: String = key.extract().unwrap_or_else(|_| key.to_string());
        if !PAYLOAD_KEYS.contains(&k.as_str()) {
            return Err(err(format!(
                "payload: unknown key '{k}'; the keys are {}",
                PAYLOAD_KEYS.join(", ")
            )));
        }
    }
    let required = |k: &str| {
        d.get_item(k)?
            .ok_or_else(|| err(format!("payload: '{k}' is required")))
    };
    let link = frame_in(m, &required("frame")?, "payload['frame']")?;
    let mass: f64 = required("mass")?
        .extract()
        .map_err(|_| err("payload['mass']: expected a number (kg)"))?;
    let com = match d.get_item("com")? {
        Some(c) => {
            let c = vector(&c, "payload['com']", 3)?;
            Vec3::from_column_slice(c.slice())
        }
        None => Vec3::zeros(),
    };
    let inertia = match d.get_item("inertia")? {
        Some(i) => inertia_tensor(&i)?,
        None => Mat3::zeros(),
    };
    Payload::new(m, link, Inertia::new(mass, com, inertia))
        .map(Some)
        .map_err(err)
}

/// `payload['inertia']`: a finite, symmetric 3×3 matrix.
fn inertia_tensor(obj: &Bound<'_, PyAny>) -> PyResult<Mat3> {
    const WHAT: &str = "payload['inertia']";
    let r = args::rows(obj, WHAT, 3)?;
    if r.rows != 3 {
        return Err(err(format!(
            "{WHAT}: shape ({}, 3), expected (3, 3)",
            r.rows
        )));
    }
    let t = Mat3::from_row_slice(r.slice());
    let asym = (t - t.transpose()).abs().max();
    if asym > 1e-9 * t.abs().max().max(1.0) {
        return Err(err(format!(
            "{WHAT} is not symmetric (|I − Iᵀ| = {asym:.1e})"
        )));
    }
    Ok(t)
}

/// The effects of a call: the model's gravity, the wrenches and the payload.
fn effects(
    m: &Model,
    w: Option<&Bound<'_, PyAny>>,
    p: Option<&Bound<'_, PyAny>>,
) -> PyResult<Effects> {
    Ok(Effects {
        gravity: Some(m.gravity),
        external: wrenches(m, w)?,
        payload: payload(m, p)?,
        ..Effects::default()
    })
}

/// Inverse dynamics `τ` at `(q, v, a)` with the model's gravity, external `wrenches` and
/// a `payload` (see the module docs for their forms and frames): Pinocchio's
/// `rnea(model, data, q, v, a, fext)` with the payload added to the body's inertia.
/// Without wrenches or payload it equals `rnea`.
#[pyfunction]
#[pyo3(signature = (model, data, q, v, a, *, wrenches=None, payload=None))]
#[allow(clippy::too_many_arguments)]
pub fn inverse_dynamics<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    a: &Bound<'py, PyAny>,
    wrenches: Option<&Bound<'py, PyAny>>,
    payload: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v, a) = (
        vector(q, "q", m.nv)?,
        vector(v, "v", m.nv)?,
        vector(a, "a", m.nv)?,
    );
    let e = effects(m, wrenches, payload)?;
    let tau = dyn_calls::inverse_dynamics(m, &mut data.data, &e, q.slice(), v.slice(), a.slice())
        .map_err(err)?;
    Ok(PyArray1::from_slice(py, tau))
}

/// Forward dynamics `q̈` for torques `tau` at `(q, v)` with the model's gravity, external
/// `wrenches` and a `payload` (see `inverse_dynamics`): Pinocchio's `aba(model, data, q,
/// v, tau, fext)` with the payload added to the body's inertia. Without wrenches or
/// payload it equals `aba`.
#[pyfunction]
#[pyo3(signature = (model, data, q, v, tau, *, wrenches=None, payload=None))]
#[allow(clippy::too_many_arguments)]
pub fn forward_dynamics<'py>(
    py: Python<'py>,
    model: &PyModel,
    data: &mut PyData,
    q: &Bound<'py, PyAny>,
    v: &Bound<'py, PyAny>,
    tau: &Bound<'py, PyAny>,
    wrenches: Option<&Bound<'py, PyAny>>,
    payload: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    data.check_model(model)?;
    let m = &*model.model;
    let (q, v, t) = (
        vector(q, "q", m.nv)?,
        vector(v, "v", m.nv)?,
        vector(tau, "tau", m.nv)?,
    );
    let e = effects(m, wrenches, payload)?;
    let ddq = dyn_calls::forward_dynamics(m, &mut data.data, &e, q.slice(), v.slice(), t.slice())
        .map_err(err)?;
    Ok(PyArray1::from_slice(py, ddq))
}
