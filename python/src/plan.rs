//! `armsim.plan`, `Robot.plan` and `armsim.Planner`: collision-free paths (`armsim plan`:
//! RRT-Connect, or the optimising AORRTC with its budget) around the obstacles of a MoveIt
//! `PlanningScene` file or of obstacle dicts, start and goal (joint values, or a tool pose
//! with path constraints, [`crate::pose_dicts`]) given or read from a MoveIt
//! `MotionPlanRequest` file, self pairs from an SRDF or from the computed
//! allowed-collision matrix. `Planner` builds the robot
//! half once and takes a scene per query. Every call runs without the GIL on a worker
//! thread while the calling thread polls for Ctrl-C ([`crate::interrupt`]): an interrupt
//! stops the work within milliseconds and raises `KeyboardInterrupt`.

use crate::args::{self, vector};
use crate::errors::{err, require_file};
use crate::interrupt::interruptible;
use crate::pose_dicts;
use armsim::model::Model;
use armsim::planning::path_constraints::PathConstraint;
use armsim::planning::plan_options::PlannerKind;
use armsim::planning::pose_goal::Goal;
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
    pub query: Query<'py>,
}

/// The search and the goal forms of a query (`armsim.plan`, `Robot.plan`, `Planner.plan`).
pub struct Query<'py> {
    pub planner: String,
    pub budget_iterations: Option<args::Int>,
    pub budget_ms: Option<f64>,
    pub goal_pose: Option<Bound<'py, PyAny>>,
    pub path_constraints: Option<Bound<'py, PyAny>>,
}

/// What a query plans to, read and checked.
struct Asked {
    goal: Goal,
    constraints: Vec<PathConstraint>,
}

/// The planner and budget of `q`, refused with a pose goal or path constraints as
/// `armsim plan` refuses them (AORRTC plans to joint goals without constraints).
fn search_of(q: &Query<'_>, asked: &Asked, opts: &mut PlanOptions) -> PyResult<()> {
    let (kind, budget) = pose_dicts::search(&q.planner, q.budget_iterations.clone(), q.budget_ms)?;
    let pose = matches!(asked.goal, Goal::Pose(_));
    if kind == PlannerKind::Aorrtc && (pose || !asked.constraints.is_empty()) {
        return Err(err(
            "planner='aorrtc' plans to joint goals without path constraints; this query has a \
             goal_pose or path_constraints (plan it with planner='rrt-connect')",
        ));
    }
    opts.planner = kind;
    opts.budget = budget;
    Ok(())
}

/// A goal set's `(found, valid, searches)` ([`Planner::plan_to`]).
type SetCounts = (usize, usize, usize);

/// Runs one query: a joint goal without constraints through [`Planner::plan`] (either
/// search), otherwise [`Planner::plan_to`]; the second value is the goal set's
/// `(found, valid, searches)` of the latter.
fn run(
    planner: &mut Planner,
    start: &[f64],
    asked: &Asked,
) -> Result<(PlanResult, Option<SetCounts>), String> {
    match &asked.goal {
        Goal::Joints(g) if asked.constraints.is_empty() => Ok((planner.plan(start, g), None)),
        goal => {
            let r = planner.plan_to(start, goal, &asked.constraints)?;
            Ok((r.result, Some((r.goals_found, r.goals_valid, r.searches))))
        }
    }
}

/// Plans on `model`; returns the result as a dict ([`result_dict`]).
pub fn plan<'py>(py: Python<'py>, model: &Model, a: PlanArgs<'py>) -> PyResult<Bound<'py, PyDict>> {
    let (start, asked) = ends(model, &a)?;
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
    let mut opts = options(a.seed, a.time_limit_ms, a.simplify, a.range, 0.01)?;
    search_of(&a.query, &asked, &mut opts)?;
    let r = interruptible(py, |stop| -> Result<_, String> {
        let opts = PlanOptions {
            stop: Some(stop),
            ..opts
        };
        let mut planner =
            Planner::new(model, &obstacles, pairs.as_deref(), opts).map_err(|e| e.to_string())?;
        run(&mut planner, &start, &asked)
    })?;
    let (r, set) = r.map_err(err)?;
    result_dict(py, model, r, set)
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

/// A plan result as a dict: `status`, `reason`, `path` as an `(N, nv)` array, `goal` (the
/// joint values the path ends at, `None` without a path), `iterations`, `plan_time_us`,
/// `simplify_time_us`, `cost_initial`, `cost`, `planner` (the search that answered),
/// `improvements` (dicts `time_us`, `iterations`, `cost`: the simplified first path, then
/// each cheaper one), `goal_set` (a pose goal or constrained query: dict `found`, `valid`,
/// `searches`; else `None`) and `joints`.
fn result_dict<'py>(
    py: Python<'py>,
    model: &Model,
    r: PlanResult,
    set: Option<SetCounts>,
) -> PyResult<Bound<'py, PyDict>> {
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
    let goal = r.path.last().map(|q| numpy::PyArray1::from_slice(py, q));
    d.set_item("goal", goal)?;
    d.set_item("iterations", r.iterations)?;
    d.set_item("plan_time_us", r.plan_time_us)?;
    d.set_item("simplify_time_us", r.simplify_time_us)?;
    d.set_item("cost_initial", r.cost_initial)?;
    d.set_item("cost", r.cost)?;
    d.set_item("planner", r.planner.name())?;
    let improvements = pyo3::types::PyList::empty(py);
    for i in &r.improvements {
        let e = PyDict::new(py);
        e.set_item("time_us", i.time_us)?;
        e.set_item("iterations", i.iterations)?;
        e.set_item("cost", i.cost)?;
        improvements.append(e)?;
    }
    d.set_item("improvements", improvements)?;
    let set = match set {
        Some((found, valid, searches)) => {
            let s = PyDict::new(py);
            s.set_item("found", found)?;
            s.set_item("valid", valid)?;
            s.set_item("searches", searches)?;
            Some(s)
        }
        None => None,
    };
    d.set_item("goal_set", set)?;
    d.set_item("joints", model.dof_names())?;
    Ok(d)
}

/// Start, goal and path constraints: given (`goal` or `goal_pose`), or read from the
/// request file (given ones win).
fn ends(model: &Model, a: &PlanArgs<'_>) -> PyResult<(Vec<f64>, Asked)> {
    let req = match &a.request {
        Some(p) => {
            require_file(p)?;
            Some(moveit::load_request(p, model).map_err(err)?.0)
        }
        None => None,
    };
    let start = match (&a.start, &req) {
        (Some(q), _) => vector(q, "start", model.nv)?.slice().to_vec(),
        (None, Some(r)) => r.start.clone(),
        (None, None) => return Err(err("start: give it, or a request file")),
    };
    let asked = goal_of(model, a.goal.as_ref(), &a.query, req)?;
    Ok((start, asked))
}

/// The goal (`goal` joint values or `goal_pose`, else the request's) and the path
/// constraints (given, else the request's).
fn goal_of(
    model: &Model,
    goal: Option<&Bound<'_, PyAny>>,
    q: &Query<'_>,
    req: Option<moveit::Request>,
) -> PyResult<Asked> {
    let goal = match (goal, &q.goal_pose, &req) {
        (Some(_), Some(_), _) => {
            return Err(err(
                "goal and goal_pose: give one (joint values or a tool pose), not both",
            ))
        }
        (Some(g), None, _) => Goal::Joints(vector(g, "goal", model.nv)?.slice().to_vec()),
        (None, Some(p), _) => Goal::Pose(pose_dicts::goal_pose(model, p)?),
        (None, None, Some(r)) => match &r.goal_pose {
            Some(p) => Goal::Pose(p.clone()),
            None => Goal::Joints(r.goal.clone()),
        },
        (None, None, None) => return Err(err("goal: give it, a goal_pose, or a request file")),
    };
    let constraints = match (&q.path_constraints, req) {
        (Some(c), _) => pose_dicts::path_constraints(model, c)?,
        (None, Some(r)) => r.path_constraints,
        (None, None) => Vec::new(),
    };
    Ok(Asked { goal, constraints })
}

/// Plans a collision-free path for `model` (see the module docs).
#[pyfunction(name = "plan")]
#[pyo3(signature = (model, start=None, goal=None, scene=None, request=None, srdf=None, seed=args::Int::Fits(0), time_limit_ms=1000.0, simplify=true, range=1.0, planner="rrt-connect".to_string(), budget_iterations=None, budget_ms=None, goal_pose=None, path_constraints=None), text_signature = "(model, start=None, goal=None, scene=None, request=None, srdf=None, seed=0, time_limit_ms=1000.0, simplify=True, range=1.0, planner='rrt-connect', budget_iterations=None, budget_ms=None, goal_pose=None, path_constraints=None)")]
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
    planner: String,
    budget_iterations: Option<args::Int>,
    budget_ms: Option<f64>,
    goal_pose: Option<Bound<'py, PyAny>>,
    path_constraints: Option<Bound<'py, PyAny>>,
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
            query: Query {
                planner,
                budget_iterations,
                budget_ms,
                goal_pose,
                path_constraints,
            },
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
    /// The settings it was built with (an AORRTC query plans with a planner of its own).
    opts: PlanOptions,
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
            planner: Planner::for_robot(Arc::new(robot), opts.clone()),
            model: m,
            opts,
        })
    }

    /// Plans from `start` to `goal` (joint values) or `goal_pose`, keeping
    /// `path_constraints`, among `obstacles` (a list of dicts: `shape` "box" with `size`,
    /// "sphere" with `radius`, "cylinder" or "capsule" with `radius` and `length`; `xyz`,
    /// `rpy` optional; `name` optional) or the obstacles of a MoveIt `scene` file, with
    /// `planner` "rrt-connect" or "aorrtc" (and its budget). Returns the dict of
    /// `armsim.plan`.
    #[pyo3(signature = (start, goal=None, obstacles=None, scene=None, planner="rrt-connect".to_string(), budget_iterations=None, budget_ms=None, goal_pose=None, path_constraints=None), text_signature = "($self, start, goal=None, obstacles=None, scene=None, planner='rrt-connect', budget_iterations=None, budget_ms=None, goal_pose=None, path_constraints=None)")]
    #[allow(clippy::too_many_arguments)]
    fn plan<'py>(
        &mut self,
        py: Python<'py>,
        start: Bound<'py, PyAny>,
        goal: Option<Bound<'py, PyAny>>,
        obstacles: Option<Bound<'py, PyAny>>,
        scene: Option<PathBuf>,
        planner: String,
        budget_iterations: Option<args::Int>,
        budget_ms: Option<f64>,
        goal_pose: Option<Bound<'py, PyAny>>,
        path_constraints: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let model = self.model.clone();
        let start = vector(&start, "start", model.nv)?.slice().to_vec();
        let query = Query {
            planner,
            budget_iterations,
            budget_ms,
            goal_pose,
            path_constraints,
        };
        let asked = goal_of(&model, goal.as_ref(), &query, None)?;
        let mut opts = self.opts.clone();
        search_of(&query, &asked, &mut opts)?;
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
        // The optimising search plans with a planner of its own (same robot half).
        let mut own = match opts.planner {
            PlannerKind::Aorrtc => {
                let mut p = Planner::for_robot(self.planner.robot.clone(), opts);
                p.set_obstacles(&obs).map_err(err)?;
                Some(p)
            }
            PlannerKind::RrtConnect => None,
        };
        let planner = own.as_mut().unwrap_or(&mut self.planner);
        let r = interruptible(py, |stop| {
            planner.set_stop(Some(stop));
            let r = run(planner, &start, &asked);
            planner.set_stop(None);
            r
        })?;
        let (r, set) = r.map_err(err)?;
        result_dict(py, &model, r, set)
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
