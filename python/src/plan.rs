//! `armsim.plan`, `Robot.plan` and `armsim.Planner`: collision-free RRT-Connect paths
//! (`armsim plan`) around the obstacles of a MoveIt `PlanningScene` file or of obstacle
//! dicts, start and goal given or read from a MoveIt `MotionPlanRequest` file, self pairs
//! from an SRDF or from the computed allowed-collision matrix. `Planner` builds the robot
//! half once and takes a scene per query. Every call runs without the GIL on a worker
//! thread while the calling thread polls for Ctrl-C ([`crate::interrupt`]): an interrupt
//! stops the work within milliseconds and raises `KeyboardInterrupt`.

use crate::args::{self, vector};
use crate::errors::{err, require_file};
use crate::interrupt::interruptible;
use armsim::model::Model;
use armsim::planning::srdf;
use armsim::planning::{
    moveit, PairSource, PlanOptions, PlanResult, PlanStatus, Planner, PlanningRobot,
};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

/// What a plan call takes besides the model.
pub struct PlanArgs<'py> {
    pub start: Option<Bound<'py, PyAny>>,
    pub goal: Option<Bound<'py, PyAny>>,
    pub scene: Option<PathBuf>,
    pub request: Option<PathBuf>,
    pub srdf: Option<PathBuf>,
    pub seed: u64,
    pub time_limit_ms: f64,
    pub simplify: bool,
    pub range: f64,
}

/// Plans on `model`; returns the result as a dict (`status`, `reason`, `path` as an
/// `(N, nv)` array, `iterations`, `plan_time_us`, `simplify_time_us`, `cost_initial`,
/// `cost`, `joints`).
pub fn plan<'py>(py: Python<'py>, model: &Model, a: PlanArgs<'py>) -> PyResult<Bound<'py, PyDict>> {
    let (start, goal) = ends(model, &a)?;
    let root = model.links[0].name.clone();
    let obstacles = match &a.scene {
        Some(p) => {
            require_file(p)?;
            moveit::load_scene_in(p, &[root.as_str()]).map_err(err)?
        }
        None => Vec::new(),
    };
    let pairs = match &a.srdf {
        Some(p) => {
            require_file(p)?;
            Some(srdf::load_disabled_pairs(p, model).map_err(err)?.0)
        }
        None => None,
    };
    let opts = options(a.seed, a.time_limit_ms, a.simplify, a.range, 0.01)?;
    let r = interruptible(py, |stop| -> Result<_, String> {
        let opts = PlanOptions {
            stop: Some(stop),
            ..opts
        };
        let mut planner =
            Planner::new(model, &obstacles, pairs.as_deref(), opts).map_err(|e| e.to_string())?;
        Ok(planner.plan(&start, &goal))
    })?;
    result_dict(py, model, r.map_err(err)?)
}

/// The planner settings, checked.
fn options(
    seed: u64,
    time_limit_ms: f64,
    simplify: bool,
    range: f64,
    max_overshoot: f64,
) -> PyResult<PlanOptions> {
    if !(time_limit_ms.is_finite()
        && time_limit_ms > 0.0
        && time_limit_ms <= armsim::planning::plan_options::MAX_TIME_LIMIT_MS)
    {
        return Err(err(format!(
            "time_limit_ms: expected a positive number (at most 1e9), got {time_limit_ms}"
        )));
    }
    let (lo, hi) = armsim::planning::plan_options::RANGE_LIMITS;
    if !(range >= lo && range <= hi) {
        return Err(err(format!(
            "range: expected a joint-space distance in {lo} … {hi}, got {range}"
        )));
    }
    if !(max_overshoot.is_finite() && (1e-4..=0.1).contains(&max_overshoot)) {
        return Err(err(format!(
            "max_overshoot: expected 0.0001 to 0.1 m, got {max_overshoot}"
        )));
    }
    let mut opts = PlanOptions {
        seed,
        time_limit: Some(Duration::from_secs_f64(time_limit_ms / 1e3)),
        simplify,
        ..Default::default()
    };
    opts.rrt.range = range as f32;
    opts.spheres.max_overshoot = max_overshoot;
    Ok(opts)
}

/// A plan result as a dict (`status`, `reason`, `path` as an `(N, nv)` array,
/// `iterations`, `plan_time_us`, `simplify_time_us`, `cost_initial`, `cost`, `joints`).
fn result_dict<'py>(py: Python<'py>, model: &Model, r: PlanResult) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let status = match r.status {
        PlanStatus::Solved => "solved",
        PlanStatus::Failed => "failed",
        PlanStatus::InvalidStart => "invalid_start",
        PlanStatus::InvalidGoal => "invalid_goal",
    };
    d.set_item("status", status)?;
    d.set_item("reason", r.reason)?;
    let path = if r.path.is_empty() {
        PyArray2::<f64>::zeros(py, [0, model.nv], false)
    } else {
        PyArray2::from_vec2(py, &r.path).map_err(err)?
    };
    d.set_item("path", path)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("plan_time_us", r.plan_time_us)?;
    d.set_item("simplify_time_us", r.simplify_time_us)?;
    d.set_item("cost_initial", r.cost_initial)?;
    d.set_item("cost", r.cost)?;
    d.set_item("joints", model.dof_names())?;
    Ok(d)
}

/// Start and goal: given, or read from the request file (given ones win).
fn ends(model: &Model, a: &PlanArgs<'_>) -> PyResult<(Vec<f64>, Vec<f64>)> {
    let req = match &a.request {
        Some(p) => {
            require_file(p)?;
            Some(moveit::load_request(p, model).map_err(err)?.0)
        }
        None => None,
    };
    let pick =
        |given: &Option<Bound<'_, PyAny>>, what: &str, from: Option<&Vec<f64>>| match (given, from)
        {
            (Some(q), _) => Ok(vector(q, what, model.nv)?.slice().to_vec()),
            (None, Some(q)) => Ok(q.clone()),
            (None, None) => Err(err(format!("{what}: give it, or a request file"))),
        };
    let start = pick(&a.start, "start", req.as_ref().map(|r| &r.start))?;
    let goal = pick(&a.goal, "goal", req.as_ref().map(|r| &r.goal))?;
    Ok((start, goal))
}

/// Plans a collision-free path for `model` (see the module docs).
#[pyfunction(name = "plan")]
#[pyo3(signature = (model, start=None, goal=None, scene=None, request=None, srdf=None, seed=args::Int::Fits(0), time_limit_ms=1000.0, simplify=true, range=1.0), text_signature = "(model, start=None, goal=None, scene=None, request=None, srdf=None, seed=0, time_limit_ms=1000.0, simplify=True, range=1.0)")]
#[allow(clippy::too_many_arguments)]
pub fn plan_py<'py>(
    py: Python<'py>,
    model: PyRef<'py, crate::model::PyModel>,
    start: Option<Bound<'py, PyAny>>,
    goal: Option<Bound<'py, PyAny>>,
    scene: Option<PathBuf>,
    request: Option<PathBuf>,
    srdf: Option<PathBuf>,
    seed: args::Int,
    time_limit_ms: f64,
    simplify: bool,
    range: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let seed = args::seed(seed, "seed")?;
    let m = std::sync::Arc::clone(&model.model);
    plan(
        py,
        &m,
        PlanArgs {
            start,
            goal,
            scene,
            request,
            srdf,
            seed,
            time_limit_ms,
            simplify,
            range,
        },
    )
}

/// A planner for one robot: the sphere model and the self pairs (from `srdf`, or the
/// allowed-collision matrix computed as MoveIt's Setup Assistant does) are built once;
/// each `plan` call takes its own scene (`obstacles` dicts, or a MoveIt scene file).
#[pyclass(module = "armsim", name = "Planner")]
pub struct PyPlanner {
    planner: Planner,
    model: Arc<Model>,
}

#[pymethods]
impl PyPlanner {
    #[new]
    #[pyo3(signature = (model, srdf=None, seed=args::Int::Fits(0), time_limit_ms=1000.0, simplify=true, range=1.0, max_overshoot=0.01), text_signature = "(model, srdf=None, seed=0, time_limit_ms=1000.0, simplify=True, range=1.0, max_overshoot=0.01)")]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        model: PyRef<'_, crate::model::PyModel>,
        srdf: Option<PathBuf>,
        seed: args::Int,
        time_limit_ms: f64,
        simplify: bool,
        range: f64,
        max_overshoot: f64,
    ) -> PyResult<Self> {
        let seed = args::seed(seed, "seed")?;
        let m = Arc::clone(&model.model);
        let pairs = match &srdf {
            Some(p) => {
                require_file(p)?;
                Some(srdf::load_disabled_pairs(p, &m).map_err(err)?.0)
            }
            None => None,
        };
        let opts = options(seed, time_limit_ms, simplify, range, max_overshoot)?;
        let robot = interruptible(py, |stop| {
            let o = PlanOptions {
                stop: Some(stop),
                ..opts.clone()
            };
            PlanningRobot::new(&m, pairs.as_deref(), &o)
        })?
        .map_err(err)?;
        Ok(PyPlanner {
            planner: Planner::for_robot(Arc::new(robot), opts),
            model: m,
        })
    }

    /// Plans from `start` to `goal` among `obstacles` (a list of dicts: `shape` "box"
    /// with `size`, "sphere" with `radius`, "cylinder" or "capsule" with `radius` and
    /// `length`; `xyz`, `rpy` optional; `name` optional) or the obstacles of a MoveIt
    /// `scene` file. Returns the dict of `armsim.plan`.
    #[pyo3(signature = (start, goal, obstacles=None, scene=None))]
    fn plan<'py>(
        &mut self,
        py: Python<'py>,
        start: Bound<'py, PyAny>,
        goal: Bound<'py, PyAny>,
        obstacles: Option<Bound<'py, PyAny>>,
        scene: Option<PathBuf>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let model = self.model.clone();
        let start = vector(&start, "start", model.nv)?.slice().to_vec();
        let goal = vector(&goal, "goal", model.nv)?.slice().to_vec();
        let mut obs = match &scene {
            Some(p) => {
                require_file(p)?;
                moveit::load_scene_in(p, &[model.links[0].name.as_str()]).map_err(err)?
            }
            None => Vec::new(),
        };
        if let Some(list) = &obstacles {
            obs.extend(crate::obstacles::from_py(list)?);
        }
        self.planner.set_obstacles(&obs).map_err(err)?;
        let planner = &mut self.planner;
        let r = interruptible(py, |stop| {
            planner.set_stop(Some(stop));
            let r = planner.plan(&start, &goal);
            planner.set_stop(None);
            r
        })?;
        result_dict(py, &model, r)
    }

    /// Set-up time (s): sphere cover and allowed-collision matrix.
    #[getter]
    fn setup_time_s(&self) -> f64 {
        self.planner.robot.setup_time_s
    }

    /// The disabled self-collision pairs `(link1, link2, reason)`; the reason is
    /// "srdf" for pairs from the SRDF.
    #[getter]
    fn disabled_pairs(&self) -> Vec<(String, String, String)> {
        match &self.planner.robot.pair_source {
            PairSource::Computed(acm) => acm
                .disabled
                .iter()
                .map(|p| {
                    (
                        p.link1.clone(),
                        p.link2.clone(),
                        p.reason.as_str().to_string(),
                    )
                })
                .collect(),
            PairSource::Srdf => Vec::new(),
        }
    }

    /// The checked self-collision pairs `(link1, link2)`.
    #[getter]
    fn checked_pairs(&self) -> Vec<(String, String)> {
        let r = &self.planner.robot;
        let name = |g: usize| r.model.links[r.spheres.links[g].link].name.clone();
        r.self_pairs
            .iter()
            .map(|&(a, b)| (name(a), name(b)))
            .collect()
    }

    /// The joint (coordinate) names, in the order of `start`, `goal` and the path.
    #[getter]
    fn joints(&self) -> Vec<String> {
        self.model.dof_names()
    }

    fn __repr__(&self) -> String {
        format!(
            "Planner(model='{}', nv={}, spheres={}, self_pairs={})",
            self.model.name,
            self.model.nv,
            self.planner.robot.spheres.len(),
            self.planner.robot.self_pairs.len()
        )
    }
}
