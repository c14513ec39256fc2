//! `armsim.Model` (immutable model, picklable as its source text plus the load options
//! and gravity; the loader's warnings as `LoaderWarning`s and `model.warnings`) and
//! `armsim.Data` (the reusable workspace of one model, picklable with its model and the
//! results Python can read from it).

use crate::args;
use crate::convert::se3_to_numpy;
use crate::errors::{err, loader_warning, require_file};
use armsim::model::LoadOptions;
use armsim::{kinematics, Data, Mat3, Model, Se3, Vec3};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::sync::Arc;

/// A robot model loaded from a URDF or a DH table (`.toml`).
#[pyclass(module = "armsim", name = "Model")]
pub struct PyModel {
    pub model: Arc<Model>,
    /// The file's text and its name (for pickling).
    text: String,
    file: String,
    strict: bool,
    ignore_mimic: bool,
    /// The loader's warnings (`file:line: element: message`).
    warnings: Vec<String>,
}

impl PyModel {
    /// Loads a model file (the body of `Model.from_file`), issuing its warnings.
    pub fn from_file_py(
        py: Python<'_>,
        path: std::path::PathBuf,
        strict: bool,
        ignore_mimic: bool,
    ) -> PyResult<PyModel> {
        require_file(&path)?;
        let file = path.display().to_string();
        let text =
            std::fs::read_to_string(&path).map_err(|e| err(format!("{file}: cannot read: {e}")))?;
        Self::load(text, file, strict, ignore_mimic)?.warn(py)
    }

    /// Builds the model; its warnings are kept, not issued.
    fn load(text: String, file: String, strict: bool, ignore_mimic: bool) -> PyResult<PyModel> {
        let opts = LoadOptions {
            strict,
            ignore_mimic,
        };
        let (model, warnings) = Model::load_str(&text, &file, &opts).map_err(err)?;
        Ok(PyModel {
            model: Arc::new(model),
            text,
            file,
            strict,
            ignore_mimic,
            warnings: warnings.iter().map(|w| w.to_string()).collect(),
        })
    }

    /// Issues each loader warning as a Python `armsim.LoaderWarning`.
    fn warn(self, py: Python<'_>) -> PyResult<PyModel> {
        for w in &self.warnings {
            loader_warning(py, w)?;
        }
        Ok(self)
    }
}

#[pymethods]
impl PyModel {
    /// Loads a `.urdf` (`.xml`) or DH-table `.toml` file. `strict` turns the loader's
    /// warnings into errors; `ignore_mimic` makes mimic joints independent coordinates
    /// (as Pinocchio's URDF parser does).
    #[staticmethod]
    #[pyo3(signature = (path, strict=false, ignore_mimic=false))]
    fn from_file(
        py: Python<'_>,
        path: std::path::PathBuf,
        strict: bool,
        ignore_mimic: bool,
    ) -> PyResult<Self> {
        Self::from_file_py(py, path, strict, ignore_mimic)
    }

    /// Builds a model from text; `name`'s extension (`.urdf`, `.xml`, `.toml`) picks the
    /// reader and names the text in messages.
    #[staticmethod]
    #[pyo3(signature = (text, name="model.urdf", strict=false, ignore_mimic=false))]
    fn from_string(
        py: Python<'_>,
        text: String,
        name: &str,
        strict: bool,
        ignore_mimic: bool,
    ) -> PyResult<Self> {
        Self::load(text, name.to_string(), strict, ignore_mimic)?.warn(py)
    }

    /// Pickle support: rebuilt from its source text, options and gravity (the loader's
    /// warnings are kept in `warnings`, not issued again).
    #[staticmethod]
    fn _from_state(
        text: String,
        file: String,
        strict: bool,
        ignore_mimic: bool,
        gravity: [f64; 3],
    ) -> PyResult<Self> {
        let mut m = Self::load(text, file, strict, ignore_mimic)?;
        Arc::make_mut(&mut m.model).gravity = Vec3::from(gravity);
        Ok(m)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let me = slf.borrow();
        let ctor = py.get_type::<PyModel>().getattr("_from_state")?;
        let g = me.model.gravity;
        let state = (
            me.text.clone(),
            me.file.clone(),
            me.strict,
            me.ignore_mimic,
            [g.x, g.y, g.z],
        );
        PyTuple::new(py, [ctor.into_any(), state.into_pyobject(py)?.into_any()])
    }

    /// A fresh workspace for this model.
    fn create_data(slf: &Bound<'_, Self>) -> PyData {
        PyData::new(slf.borrow().model.clone(), slf.clone().unbind())
    }

    /// The loader's warnings (`file:line: element: message`), also issued as
    /// `armsim.LoaderWarning`s when the model was loaded; empty for a clean file.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The middle of the joint limits (0 for unbounded joints).
    fn neutral<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.model.neutral())
    }

    /// Length of `q` (one value per independent joint; continuous joints take an angle).
    #[getter]
    fn nq(&self) -> usize {
        self.model.nv
    }

    /// Length of `v`, `a`, `tau` (equals `nq`).
    #[getter]
    fn nv(&self) -> usize {
        self.model.nv
    }

    #[getter]
    fn name(&self) -> String {
        self.model.name.clone()
    }

    /// The file the model came from.
    #[getter]
    fn source(&self) -> String {
        self.file.clone()
    }

    /// The coordinates' joint names, in order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.model.dof_names()
    }

    /// The frame (link) names; a frame's id is its index here.
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.model.links.iter().map(|l| l.name.clone()).collect()
    }

    /// Whether coordinate `k` is a continuous (unlimited revolute) joint.
    fn is_continuous(&self, k: args::Int) -> PyResult<bool> {
        let k = args::size(k, "k")?;
        if k >= self.model.nv {
            return Err(err(format!("coordinate {k} does not exist")));
        }
        Ok(self.model.is_continuous(k))
    }

    #[getter]
    fn lower_limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.model.lower)
    }

    #[getter]
    fn upper_limits<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.model.upper)
    }

    /// The gravity vector the dynamics use (default `(0, 0, -9.81)`).
    #[getter]
    fn get_gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.model.gravity.as_slice())
    }

    #[setter]
    fn set_gravity(&mut self, g: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = args::vector(g, "gravity", 3)?;
        let s = v.slice();
        Arc::make_mut(&mut self.model).gravity = Vec3::new(s[0], s[1], s[2]);
        Ok(())
    }

    /// The id of the frame called `name` (an error lists the frames when there is none).
    fn frame_id(&self, name: &str) -> PyResult<usize> {
        args::frame_by_name(&self.model, name)
    }

    fn __repr__(&self) -> String {
        format!(
            "armsim.Model('{}', nq={}, frames={}, source='{}')",
            self.model.name,
            self.model.nv,
            self.model.links.len(),
            self.file
        )
    }
}

/// The workspace of one model: what the last call computed (placements, τ, q̈, M).
#[pyclass(module = "armsim", name = "Data")]
pub struct PyData {
    pub model: Arc<Model>,
    pub data: Data,
    /// The `Model` that created it (pickled with it).
    owner: Py<PyModel>,
}

impl PyData {
    pub fn new(model: Arc<Model>, owner: Py<PyModel>) -> PyData {
        let data = Data::new(&model);
        PyData { model, data, owner }
    }

    /// Refuses a workspace whose sizes do not fit `model` (built for another robot); a
    /// workspace of the same structure (the same model before `gravity` was set, or the
    /// same file loaded again) is adopted.
    pub fn check_model(&mut self, model: &PyModel) -> PyResult<()> {
        if Arc::ptr_eq(&self.model, &model.model) {
            return Ok(());
        }
        let (a, b) = (&*self.model, &*model.model);
        if a.nv == b.nv && a.nbodies() == b.nbodies() && a.links.len() == b.links.len() {
            self.model = Arc::clone(&model.model);
            return Ok(());
        }
        Err(err(format!(
            "data was created for '{}' ({} coordinates, {} frames), not for '{}' ({}, {}): use model.create_data()",
            a.name,
            a.nv,
            a.links.len(),
            b.name,
            b.nv,
            b.links.len()
        )))
    }
}

#[pymethods]
impl PyData {
    /// The world placement (4×4) of frame `frame` (id or name) as the last
    /// `forward_kinematics` left it.
    fn frame_pose<'py>(
        &self,
        py: Python<'py>,
        frame: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let f = args::frame(&self.model, frame)?;
        Ok(se3_to_numpy(
            py,
            &kinematics::frame_placement(&self.model, &self.data, f),
        ))
    }

    /// The last `rnea` result.
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.data.tau)
    }

    /// The last `aba` result.
    #[getter]
    fn ddq<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.data.qdd)
    }

    /// Pickle support: a workspace of `model` holding the body placements (12 values per
    /// body: the rotation row by row, then the translation), `tau` and `ddq` it had.
    #[staticmethod]
    fn _from_state(
        model: Bound<'_, PyModel>,
        placements: Vec<f64>,
        tau: Vec<f64>,
        ddq: Vec<f64>,
    ) -> PyResult<Self> {
        let mut d = PyData::new(model.borrow().model.clone(), model.unbind());
        let sizes = [
            ("placements", placements.len(), 12 * d.data.o_m_i.len()),
            ("tau", tau.len(), d.data.tau.len()),
            ("ddq", ddq.len(), d.data.qdd.len()),
        ];
        for (what, got, want) in sizes {
            if got != want {
                return Err(err(format!(
                    "Data state: {what} has {got} values, the model '{}' needs {want}",
                    d.model.name
                )));
            }
        }
        for (p, v) in d.data.o_m_i.iter_mut().zip(placements.chunks_exact(12)) {
            *p = Se3 {
                rot: Mat3::from_row_slice(&v[..9]),
                trans: Vec3::new(v[9], v[10], v[11]),
            };
        }
        d.data.tau.copy_from_slice(&tau);
        d.data.qdd.copy_from_slice(&ddq);
        Ok(d)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let me = slf.borrow();
        let ctor = py.get_type::<PyData>().getattr("_from_state")?;
        let mut placements: Vec<f64> = Vec::with_capacity(12 * me.data.o_m_i.len());
        for p in &me.data.o_m_i {
            placements.extend(p.rot.transpose().iter());
            placements.extend(p.trans.iter());
        }
        let state = (
            me.owner.clone_ref(py),
            placements,
            me.data.tau.clone(),
            me.data.qdd.clone(),
        );
        PyTuple::new(py, [ctor.into_any(), state.into_pyobject(py)?.into_any()])
    }

    /// The number of coordinates of the model it serves.
    #[getter]
    fn nv(&self) -> usize {
        self.model.nv
    }
}
