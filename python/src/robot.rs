//! `armsim.Robot`: the facade for Robotics-Toolbox habits (fk, jacobian, rnea, aba, crba,
//! gravity, ik by frame name or id; the default frame is the tool link, `Model::tool_link`). It pickles as
//! its `Model` and the gravity it computes with.

use crate::args::{self, vector};
use crate::convert::{check_pose, matrix_to_numpy, se3_from_4x4, se3_to_numpy};
use crate::errors::err;
use crate::ik::{self, IkResult};
use crate::model::PyModel;
use armsim::{FrameId, Robot};
use numpy::{PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::sync::Arc;

/// A model with its own workspace and IK solver.
#[pyclass(module = "armsim", name = "Robot")]
pub struct PyRobot {
    robot: Robot,
    model: Py<PyModel>,
}

impl PyRobot {
    fn frame(&self, frame: Option<&Bound<'_, PyAny>>) -> PyResult<usize> {
        let m = self.robot.model();
        match frame {
            None => Ok(m.tool_link()),
            Some(f) => args::frame(m, f),
        }
    }

    fn nv(&self) -> usize {
        self.robot.nv()
    }
}

fn to_err(e: armsim::RobotError) -> PyErr {
    err(e)
}

#[pymethods]
impl PyRobot {
    /// A robot on `model` (an `armsim.Model`).
    #[new]
    fn new(py: Python<'_>, model: Py<PyModel>) -> Self {
        let m = Arc::clone(&model.borrow(py).model);
        PyRobot {
            robot: Robot::from_model((*m).clone()),
            model,
        }
    }

    /// Plans a collision-free path (see `armsim.plan`): start and goal given or read from
    /// a MoveIt request file, obstacles from a MoveIt scene file, self pairs from an SRDF.
    #[pyo3(signature = (start=None, goal=None, scene=None, request=None, srdf=None, seed=args::Int::Fits(0), time_limit_ms=1000.0, simplify=true, range=1.0, planner="rrt-connect".to_string(), budget_iterations=None, budget_ms=None, goal_pose=None, path_constraints=None), text_signature = "($self, start=None, goal=None, scene=None, request=None, srdf=None, seed=0, time_limit_ms=1000.0, simplify=True, range=1.0, planner='rrt-connect', budget_iterations=None, budget_ms=None, goal_pose=None, path_constraints=None)")]
    #[allow(clippy::too_many_arguments)]
    fn plan<'py>(
        &self,
        py: Python<'py>,
        start: Option<Bound<'py, PyAny>>,
        goal: Option<Bound<'py, PyAny>>,
        scene: Option<std::path::PathBuf>,
        request: Option<std::path::PathBuf>,
        srdf: Option<std::path::PathBuf>,
        seed: args::Int,
        time_limit_ms: f64,
        simplify: bool,
        range: f64,
        planner: String,
        budget_iterations: Option<args::Int>,
        budget_ms: Option<f64>,
        goal_pose: Option<Bound<'py, PyAny>>,
        path_constraints: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let seed = args::seed(seed, "seed")?;
        crate::plan::plan(
            py,
            self.robot.model(),
            crate::plan::PlanArgs {
                start,
                goal,
                scene,
                request,
                srdf,
                seed,
                time_limit_ms,
                simplify,
                range,
                query: crate::plan::Query {
                    planner,
                    budget_iterations,
                    budget_ms,
                    goal_pose,
                    path_constraints,
                },
            },
        )
    }

    /// Loads a URDF or DH-table file.
    #[staticmethod]
    #[pyo3(signature = (path, strict=false, ignore_mimic=false))]
    fn from_file(
        py: Python<'_>,
        path: std::path::PathBuf,
        strict: bool,
        ignore_mimic: bool,
    ) -> PyResult<Self> {
        let model = PyModel::from_file_py(py, path, strict, ignore_mimic)?;
        Ok(Self::new(py, Py::new(py, model)?))
    }

    /// Pickle support: a robot on `model` computing with `gravity` (the model's gravity
    /// when the robot was made; a later change of `model.gravity` does not reach it).
    #[staticmethod]
    fn _from_state(py: Python<'_>, model: Py<PyModel>, gravity: [f64; 3]) -> Self {
        let mut r = Self::new(py, model);
        r.robot.set_gravity(armsim::Vec3::from(gravity));
        r
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let me = slf.borrow();
        let ctor = py.get_type::<PyRobot>().getattr("_from_state")?;
        let g = me.robot.gravity();
        let state = (me.model.clone_ref(py), [g.x, g.y, g.z]);
        PyTuple::new(py, [ctor.into_any(), state.into_pyobject(py)?.into_any()])
    }

    /// The model.
    #[getter]
    fn model(&self, py: Python<'_>) -> Py<PyModel> {
        self.model.clone_ref(py)
    }

    #[getter(nv)]
    fn nv_py(&self) -> usize {
        self.nv()
    }

    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.robot.joint_names()
    }

    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.robot.frame_names()
    }

    /// The world placement (4×4) of `frame` (default: the tool link) at `q`.
    #[pyo3(signature = (q, frame=None))]
    fn fk<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let f = self.frame(frame)?;
        let q = vector(q, "q", self.nv())?;
        let p = self.robot.pose(q.slice(), FrameId(f)).map_err(to_err)?;
        Ok(se3_to_numpy(py, &p))
    }

    /// The 6×nv Jacobian of `frame` at `q` ("world_aligned", "local" or "world").
    #[pyo3(signature = (q, frame=None, reference="world_aligned"))]
    fn jacobian<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: Option<&Bound<'py, PyAny>>,
        reference: &str,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let f = self.frame(frame)?;
        let e = args::expressed(reference)?;
        let n = self.nv();
        let q = vector(q, "q", n)?;
        let j = self
            .robot
            .jacobian(q.slice(), FrameId(f), e)
            .map_err(to_err)?;
        Ok(matrix_to_numpy(py, j))
    }

    /// Inverse dynamics with the model's gravity (`v`, `a` default to zeros).
    #[pyo3(signature = (q, v=None, a=None))]
    fn rnea<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: Option<&Bound<'py, PyAny>>,
        a: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.nv();
        let zeros = vec![0.0; n];
        let q = vector(q, "q", n)?;
        let v = v.map(|v| vector(v, "v", n)).transpose()?;
        let a = a.map(|a| vector(a, "a", n)).transpose()?;
        let vs = v.as_ref().map_or(&zeros[..], |v| v.slice());
        let as_ = a.as_ref().map_or(&zeros[..], |a| a.slice());
        let tau = self.robot.rnea(q.slice(), vs, as_).map_err(to_err)?;
        Ok(PyArray1::from_slice(py, tau))
    }

    /// Forward dynamics `q̈` with the model's gravity.
    fn aba<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.nv();
        let (q, v, t) = (
            vector(q, "q", n)?,
            vector(v, "v", n)?,
            vector(tau, "tau", n)?,
        );
        let ddq = self
            .robot
            .aba(q.slice(), v.slice(), t.slice())
            .map_err(to_err)?;
        Ok(PyArray1::from_slice(py, ddq))
    }

    /// The mass matrix `M(q)`.
    fn crba<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.nv();
        let q = vector(q, "q", n)?;
        let m = self.robot.crba(q.slice()).map_err(to_err)?;
        Ok(matrix_to_numpy(py, m))
    }

    /// Gravity torques `g(q)`.
    fn gravity<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let q = vector(q, "q", self.nv())?;
        let g = self.robot.gravity_torque(q.slice()).map_err(to_err)?;
        Ok(PyArray1::from_slice(py, g))
    }

    /// IK for `frame` (default: the tool link) reaching `target` (4×4), from `q0` first
    /// when given, then from random restarts. Keywords: see `armsim.IK_KEYWORDS`
    /// (`time_budget=None` by default: deterministic for a seed).
    #[pyo3(signature = (target, frame=None, q0=None, **kwargs))]
    fn ik(
        &mut self,
        py: Python<'_>,
        target: PyReadonlyArray2<'_, f64>,
        frame: Option<&Bound<'_, PyAny>>,
        q0: Option<&Bound<'_, PyAny>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<IkResult> {
        let f = self.frame(frame)?;
        let opts = ik::options(kwargs)?;
        let a = target.as_array();
        if a.shape() != [4, 4] {
            return Err(err(format!(
                "target: shape {:?}, expected (4, 4)",
                a.shape()
            )));
        }
        let mut t = [0.0; 16];
        for (k, x) in a.iter().enumerate() {
            t[k] = *x;
        }
        check_pose(&t).map_err(|m| err(format!("target: {m}")))?;
        let q0 = q0.map(|q| vector(q, "q0", self.nv())).transpose()?;
        let sol = self
            .robot
            .ik_from(
                FrameId(f),
                &se3_from_4x4(&t),
                q0.as_ref().map(|q| q.slice()),
                &opts,
            )
            .map_err(to_err)?;
        Ok(IkResult::new(py, sol))
    }
}
