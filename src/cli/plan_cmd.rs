//! `armsim plan`: plans MoveIt problems (one scene + request pair, or every
//! `sceneNNNN.yaml` / `requestNNNN.yaml` pair of one or more benchmark folders) with
//! [`armsim::planning::Planner`], and prints a table per problem and the anchor-style
//! summary (or JSON).
//!
//! Every input is read before anything is planned, so a bad file stops the command with
//! its `FILE:LINE: ELEMENT: PROBLEM` message and nothing written. Problems run in order on
//! one thread, or on `--threads N` (rayon, one planner per problem); the results do not
//! depend on the thread count (the sampler is seeded per query). `--passes N` plans each
//! problem N times and reports the median times (the VAMP anchor's protocol; the paths of
//! the passes must be identical, which is checked).

use crate::cli::plan_report::{self, PlanOutcome, ReportHeader};
use armsim::collision::Obstacle;
use armsim::model::{LoadOptions, Model};
use armsim::planning::acm::Acm;
use armsim::planning::moveit::{self, problem_pairs};
use armsim::planning::plan_options::{PlannerKind, RANGE_LIMITS};
use armsim::planning::srdf;
use armsim::planning::{PairSource, PlanOptions, Planner, PlanningRobot};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Arguments of `armsim plan`.
#[derive(clap::Args, Debug)]
#[command(group(
    clap::ArgGroup::new("problems")
        .required(true)
        .args(["moveit_scene", "moveit_dir", "scenario"])
))]
pub struct PlanArgs {
    /// Robot model (URDF). Its collision spheres are used as given; boxes, cylinders,
    /// capsules and meshes are covered with spheres (link pairs whose covers touch where
    /// the meshes do not are decided on the meshes themselves).
    pub model: PathBuf,
    /// MoveIt SRDF: its <disable_collisions> link pairs are not checked for self-collision
    /// (nor are links one joint apart). Without it, pairs never in contact over random
    /// samples are dropped too.
    #[arg(long)]
    pub srdf: Option<PathBuf>,
    /// MoveIt PlanningScene YAML (obstacles; frame: world or the model's root link).
    #[arg(long, requires = "moveit_request")]
    pub moveit_scene: Option<PathBuf>,
    /// MoveIt MotionPlanRequest YAML (start state and joint goal).
    #[arg(long, requires = "moveit_scene")]
    pub moveit_request: Option<PathBuf>,
    /// Folder of sceneNNNN.yaml / requestNNNN.yaml pairs, planned in order (repeatable:
    /// the summary then has a row per folder and one for all).
    #[arg(long)]
    pub moveit_dir: Vec<PathBuf>,
    /// Arm scenario TOML (the model must be the scenario's): plans its task's planned
    /// moves (`type = "plan"` steps, or every joint move of `planner = "rrt-connect"`)
    /// around its obstacles, a result per move; the scenario's `[planner]` settings apply
    /// unless `--seed`, `--time-limit-ms`, `--no-simplify` or `--srdf` are given.
    #[arg(long, conflicts_with_all = ["moveit_scene", "moveit_dir"])]
    pub scenario: Option<PathBuf>,
    /// Seed of the sampler and of the simplifier (same seed, same path; default 0).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Wall-clock limit of each search, in milliseconds (simplification not counted).
    #[arg(long, allow_negative_numbers = true)]
    pub time_limit_ms: Option<f64>,
    /// Longest RRT-Connect step in joint space (default 1; VAMP uses 1 for the Panda and
    /// 1.5 for the UR5).
    #[arg(long, allow_negative_numbers = true)]
    pub range: Option<f64>,
    /// Return the first path found, without shortcutting and smoothing.
    #[arg(long)]
    pub no_simplify: bool,
    /// The search: `rrt-connect` (the first path, simplified) or `aorrtc` (asymptotically
    /// optimal: keeps searching for cheaper paths until its budget is spent). Default
    /// rrt-connect, or the scenario's `[planner] algorithm`.
    #[arg(long)]
    pub planner: Option<String>,
    /// `aorrtc`: search iterations per query, the first path's included (default 2000).
    #[arg(long)]
    pub budget_iterations: Option<usize>,
    /// `aorrtc`: wall-clock budget per query, in milliseconds (stops earlier than the
    /// iterations when it runs out; the path then depends on the machine's speed).
    #[arg(long, allow_negative_numbers = true)]
    pub budget_ms: Option<f64>,
    /// Threads planning problems in parallel (each problem has its own planner).
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Plan each problem this many times; times are the median over the passes.
    #[arg(long, default_value_t = 1)]
    pub passes: usize,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write the output to this file (atomically) instead of standard output.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Treat model warnings as errors, as the model commands' --strict does.
    #[arg(long)]
    pub strict: bool,
}

/// One problem, read.
struct Input {
    scene_label: String,
    id: String,
    scene_file: PathBuf,
    obstacles: Vec<Obstacle>,
    start: Vec<f64>,
    goal: Vec<f64>,
    /// A tool-pose goal (then `goal` is empty) and the path constraints.
    pose: Option<armsim::planning::pose_goal::PoseGoal>,
    constraints: Vec<armsim::planning::path_constraints::PathConstraint>,
}

/// Runs the command; returns what goes to standard output (empty with `--out`).
pub fn run(a: &PlanArgs) -> Result<String, String> {
    let opts = plan_options(a)?;
    check_counts(a)?;
    if let Some(file) = &a.scenario {
        let text = crate::cli::plan_scenario::run(a, file, &opts)?;
        return emit(a, text);
    }
    let model = load_model(&a.model, a.strict)?;
    let disabled = match &a.srdf {
        Some(p) => {
            let (pairs, warnings) =
                srdf::load_disabled_pairs(p, &model).map_err(|e| e.to_string())?;
            for w in warnings {
                eprintln!("warning: {w}");
            }
            Some(pairs)
        }
        None => None,
    };
    let inputs = read_inputs(a, &model)?;
    // The robot half (sphere model, self pairs), built once and said once.
    let robot = std::sync::Arc::new(
        PlanningRobot::new(&model, disabled.as_deref(), &opts)
            .map_err(|e| format!("{}: {e}", a.model.display()))?,
    );
    if let Some(w) = robot.spheres.warnings.first().filter(|_| a.strict) {
        // A collision mesh left out of the sphere model leaves its link unprotected.
        return Err(format!("{}: --strict: {w}", a.model.display()));
    }
    for w in &robot.spheres.warnings {
        eprintln!("warning: {}: {w}", a.model.display());
    }
    if let PairSource::Computed(acm) = &robot.pair_source {
        eprintln!("note: {}", acm_note(acm, robot.setup_time_s));
    }
    let solve = |inp: &Input| solve(&robot, &opts, a.passes, inp);
    let outcomes: Vec<PlanOutcome> = if a.threads == 1 {
        inputs.iter().map(solve).collect::<Result<_, _>>()?
    } else {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(a.threads)
            .build()
            .map_err(|e| format!("--threads {}: cannot start the threads: {e}", a.threads))?;
        pool.install(|| inputs.par_iter().map(solve).collect::<Result<_, _>>())?
    };
    if armsim::core::interrupt::requested() {
        return Err("interrupted (Ctrl-C): nothing written".into());
    }
    for o in outcomes.iter().filter(|o| !o.passes_identical) {
        eprintln!(
            "warning: {} {}: the {} passes did not return the same path",
            o.scene, o.problem, a.passes
        );
    }
    let header = ReportHeader {
        model: &model,
        seed: opts.seed,
        simplify: !a.no_simplify,
        passes: a.passes,
        threads: a.threads,
        time_limit_ms: a.time_limit_ms,
        range: f64::from(opts.rrt.range),
        planner: opts.planner,
        budget: (opts.planner == PlannerKind::Aorrtc).then_some(opts.budget),
    };
    let text = if a.json {
        plan_report::json(&header, &outcomes)
    } else {
        plan_report::text(&header, &outcomes)
    };
    emit(a, text)
}

/// Loads a model, its warnings on standard error (errors under `strict`).
pub(super) fn load_model(path: &Path, strict: bool) -> Result<Model, String> {
    let load = LoadOptions {
        strict,
        ..Default::default()
    };
    let (model, warnings) = Model::load_with(path, &load).map_err(|e| e.to_string())?;
    for w in warnings {
        eprintln!("warning: {w}");
    }
    Ok(model)
}

/// What the computed allowed-collision matrix disabled, for the note on standard error.
pub(super) fn acm_note(acm: &Acm, setup_s: f64) -> String {
    let counts: Vec<String> = acm
        .counts()
        .iter()
        .map(|(r, n)| format!("{n} {}", r.as_str().to_lowercase()))
        .collect();
    format!(
        "no --srdf: self-collision pairs from the allowed-collision matrix computed as MoveIt's \
         Setup Assistant does ({} random configurations): disabled {}; {} pairs checked; set-up \
         {:.2} s (`armsim srdf MODEL` writes it as an SRDF)",
        acm.samples,
        counts.join(", "),
        acm.checked.len(),
        setup_s
    )
}

/// Writes `text` to `--out` (atomically; returns nothing to print) or returns it.
fn emit(a: &PlanArgs, text: String) -> Result<String, String> {
    write_or_return(a.out.as_deref(), text)
}

/// Writes `text` to `out` (atomically; returns nothing to print) or returns it.
pub(super) fn write_or_return(out: Option<&Path>, text: String) -> Result<String, String> {
    match out {
        Some(p) => {
            armsim::core::files::write_atomic(p, text.as_bytes())
                .map_err(|e| format!("{}: cannot write: {e}", p.display()))?;
            Ok(String::new())
        }
        None => Ok(text),
    }
}

/// The planner settings the arguments ask for.
fn plan_options(a: &PlanArgs) -> Result<PlanOptions, String> {
    use armsim::planning::plan_options::MAX_TIME_LIMIT_MS;
    let time_limit = match a.time_limit_ms {
        None => None,
        Some(t) if t.is_finite() && t > 0.0 && t <= MAX_TIME_LIMIT_MS => {
            Some(Duration::from_secs_f64(t / 1e3))
        }
        Some(t) => {
            return Err(format!(
                "--time-limit-ms: expected a positive number of milliseconds, got {t}"
            ))
        }
    };
    // Ctrl-C stops the set-up's sampling and the searches (the command then fails).
    armsim::core::interrupt::install().map_err(|e| e.to_string())?;
    let mut opts = PlanOptions {
        seed: a.seed.unwrap_or(0),
        time_limit,
        simplify: !a.no_simplify,
        stop: Some(armsim::core::interrupt::flag()),
        ..Default::default()
    };
    match a.range {
        None => {}
        Some(r) if r >= RANGE_LIMITS.0 && r <= RANGE_LIMITS.1 => opts.rrt.range = r as f32,
        Some(r) => {
            return Err(format!(
                "--range: expected a joint-space distance in {} … {}, got {r}",
                RANGE_LIMITS.0, RANGE_LIMITS.1
            ))
        }
    }
    planner_choice(a, &mut opts)?;
    Ok(opts)
}

/// `--planner` and its budget (refused with RRT-Connect, which does not use them).
fn planner_choice(a: &PlanArgs, opts: &mut PlanOptions) -> Result<(), String> {
    use armsim::planning::plan_options::{MAX_OPTIMISE_ITERATIONS, MAX_TIME_LIMIT_MS};
    let name = a.planner.as_deref().unwrap_or("rrt-connect");
    opts.planner = PlannerKind::from_name(name)
        .ok_or_else(|| format!("--planner: expected rrt-connect or aorrtc, got '{name}'"))?;
    // A scenario's own `[planner] algorithm` may be aorrtc: its budget flags are checked
    // against that (plan_scenario).
    if opts.planner == PlannerKind::RrtConnect && (a.planner.is_some() || a.scenario.is_none()) {
        for (flag, given) in [
            ("--budget-iterations", a.budget_iterations.is_some()),
            ("--budget-ms", a.budget_ms.is_some()),
        ] {
            if given {
                return Err(format!(
                    "{flag} applies to --planner aorrtc (RRT-Connect stops at its first path)"
                ));
            }
        }
        return Ok(());
    }
    match a.budget_iterations {
        None => {}
        Some(n) if (1..=MAX_OPTIMISE_ITERATIONS).contains(&n) => opts.budget.iterations = n,
        Some(n) => {
            return Err(format!(
                "--budget-iterations: expected 1 … {MAX_OPTIMISE_ITERATIONS}, got {n}"
            ))
        }
    }
    match a.budget_ms {
        None => {}
        Some(t) if t.is_finite() && t > 0.0 && t <= MAX_TIME_LIMIT_MS => {
            opts.budget.time = Some(Duration::from_secs_f64(t / 1e3));
        }
        Some(t) => {
            return Err(format!(
                "--budget-ms: expected a positive number of milliseconds, got {t}"
            ))
        }
    }
    Ok(())
}

/// The problem files the arguments name, as (scene label, id, scene, request).
fn problem_files(a: &PlanArgs) -> Result<Vec<(String, String, PathBuf, PathBuf)>, String> {
    if let (Some(s), Some(r)) = (&a.moveit_scene, &a.moveit_request) {
        let stem = r.file_stem().map(|s| s.to_string_lossy().into_owned());
        let stem = stem.unwrap_or_default();
        let id = stem.strip_prefix("request").unwrap_or(&stem).to_string();
        let label = dir_label(s.parent().unwrap_or(Path::new(".")));
        return Ok(vec![(label, id, s.clone(), r.clone())]);
    }
    let mut out = Vec::new();
    for dir in &a.moveit_dir {
        let label = dir_label(dir);
        for p in problem_pairs(dir).map_err(|e| e.to_string())? {
            out.push((label.clone(), p.id, p.scene, p.request));
        }
    }
    Ok(out)
}

/// A folder's name for the tables (`table_pick` for `…/panda/table_pick/`).
fn dir_label(dir: &Path) -> String {
    let canon = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    canon
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| dir.display().to_string())
}

/// Reads every scene and request; request warnings repeated across files are said once.
fn read_inputs(a: &PlanArgs, model: &Model) -> Result<Vec<Input>, String> {
    let root = model
        .links
        .iter()
        .find(|l| l.parent_joint.is_none())
        .map(|l| l.name.clone())
        .unwrap_or_default();
    let frames = [root.as_str()];
    let mut seen: BTreeMap<(String, String), usize> = BTreeMap::new();
    let mut inputs = Vec::new();
    for (scene_label, id, scene, request) in problem_files(a)? {
        let obstacles = moveit::load_scene_in(&scene, &frames).map_err(|e| e.to_string())?;
        let (req, warnings) = moveit::load_request(&request, model).map_err(|e| e.to_string())?;
        for w in warnings {
            let n = seen.entry((w.key.clone(), w.message.clone())).or_insert(0);
            if *n == 0 {
                eprintln!("warning: {w}");
            }
            *n += 1;
        }
        if a.planner.as_deref() == Some("aorrtc")
            && (req.goal_pose.is_some() || !req.path_constraints.is_empty())
        {
            return Err(format!(
                "{}: --planner aorrtc plans to joint goals without path constraints; this \
                 request has a tool-pose goal or path constraints (plan it with rrt-connect)",
                request.display()
            ));
        }
        inputs.push(Input {
            scene_label,
            id,
            scene_file: scene,
            obstacles,
            start: req.start,
            goal: req.goal,
            pose: req.goal_pose,
            constraints: req.path_constraints,
        });
    }
    let repeated: usize = seen.values().map(|n| n - 1).sum();
    if repeated > 0 {
        eprintln!("warning: the same request warnings again in {repeated} more places (not shown)");
    }
    Ok(inputs)
}

/// Checks `--threads` and `--passes`.
pub(super) fn check_counts(a: &PlanArgs) -> Result<(), String> {
    if a.threads == 0 || a.threads > 1024 {
        return Err(format!("--threads: expected 1 to 1024, got {}", a.threads));
    }
    if a.passes == 0 || a.passes > 10_000 {
        return Err(format!("--passes: expected 1 to 10000, got {}", a.passes));
    }
    Ok(())
}

/// Plans one problem `passes` times.
fn solve(
    robot: &std::sync::Arc<PlanningRobot>,
    opts: &PlanOptions,
    passes: usize,
    inp: &Input,
) -> Result<PlanOutcome, String> {
    let mut planner = Planner::for_robot(robot.clone(), opts.clone());
    planner
        .set_obstacles(&inp.obstacles)
        .map_err(|e| format!("{}: {e}", inp.scene_file.display()))?;
    let mut result = plan_input(&mut planner, inp)?;
    let mut plan = vec![result.plan_time_us];
    let mut simplify = vec![result.simplify_time_us];
    let mut passes_identical = true;
    for _ in 1..passes {
        let r = plan_input(&mut planner, inp)?;
        passes_identical &= r.path == result.path && r.status == result.status;
        plan.push(r.plan_time_us);
        simplify.push(r.simplify_time_us);
    }
    result.plan_time_us = plan_report::median(&mut plan);
    result.simplify_time_us = plan_report::median(&mut simplify);
    Ok(PlanOutcome {
        scene: inp.scene_label.clone(),
        problem: inp.id.clone(),
        result,
        passes_identical,
    })
}

/// One query of a problem: a joint goal as before; a tool-pose goal or path constraints
/// through [`Planner::plan_to`] (a note on standard error gives the goal set's size).
fn plan_input(planner: &mut Planner, inp: &Input) -> Result<armsim::planning::PlanResult, String> {
    use armsim::planning::pose_goal::Goal;
    if inp.pose.is_none() && inp.constraints.is_empty() {
        return Ok(planner.plan(&inp.start, &inp.goal));
    }
    let goal = match &inp.pose {
        Some(p) => Goal::Pose(p.clone()),
        None => Goal::Joints(inp.goal.clone()),
    };
    let g = planner
        .plan_to(&inp.start, &goal, &inp.constraints)
        .map_err(|e| format!("{} {}: {e}", inp.scene_label, inp.id))?;
    if inp.pose.is_some() {
        eprintln!(
            "note: {} {}: goal pose: {} inverse-kinematics solution(s), {} valid, {} search(es)",
            inp.scene_label, inp.id, g.goals_found, g.goals_valid, g.searches
        );
    }
    Ok(g.result)
}
