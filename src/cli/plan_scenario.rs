//! `armsim plan MODEL --scenario FILE.toml`: plans an arm scenario's planned moves (the
//! `type = "plan"` steps, or every joint move when the task says `planner =
//! "rrt-connect"`) around the scenario's obstacles, exactly as `armsim run` does, and
//! reports one result per move in the form of the MoveIt problems (`scene` is the
//! scenario's name, `problem` the step's key).
//!
//! The task is planned as a whole (each move starts where the previous step ended, tool
//! poses through IK, the grasped part on the tool from pick to place), so a move that
//! cannot be planned stops the command with the step's location, as `armsim run` does.

use crate::cli::plan_cmd::PlanArgs;
use crate::cli::plan_report::{self, PlanOutcome, ReportHeader};
use armsim::planning::plan_options::PlannerKind;
use armsim::planning::srdf;
use armsim::planning::PlanOptions;
use std::path::Path;

/// Plans the scenario's moves `a.passes` times; returns the report text.
pub fn run(a: &PlanArgs, file: &Path, opts: &PlanOptions) -> Result<String, String> {
    let text = armsim::core::files::read_input_string(file)
        .map_err(|e| format!("{}: cannot read: {e}", file.display()))?;
    let mut scene = armsim::scenarios::arm::load(file, &text).map_err(|e| e.to_string())?;
    let same = |p: &Path| p.canonicalize().ok();
    if same(&a.model) != same(&scene.model_path) {
        return Err(format!(
            "{}: --scenario plans with the scenario's own model, {}; give that file as MODEL",
            a.model.display(),
            scene.model_path.display()
        ));
    }
    for w in &scene.model_warnings {
        eprintln!("warning: {w}");
    }
    let Some(settings) = scene.planner.as_mut() else {
        return Err(format!(
            "{}: the task plans nothing: give it a step `type = \"plan\"` or `planner = \
             \"rrt-connect\"`",
            file.display()
        ));
    };
    if let Some(seed) = a.seed {
        settings.seed = seed;
    }
    if let Some(t) = opts.time_limit {
        settings.time_limit = t;
    }
    if a.no_simplify {
        settings.simplify = false;
    }
    if a.range.is_some() {
        settings.range = f64::from(opts.rrt.range);
    }
    if a.planner.is_some() {
        let queries = scene
            .steps
            .iter()
            .any(|s| matches!(s.step, armsim::scenarios::arm::scene::Step::PlanTo(_)));
        if opts.planner == PlannerKind::Aorrtc && queries {
            return Err(format!(
                "{}: --planner aorrtc plans to joint goals without path constraints; this \
                 scenario has task.goal_pose or task.path_constraints (plan it with rrt-connect)",
                file.display()
            ));
        }
        settings.algorithm = opts.planner;
    }
    if a.budget_iterations.is_some() || a.budget_ms.is_some() {
        if settings.algorithm != PlannerKind::Aorrtc {
            return Err(format!(
                "--budget-iterations / --budget-ms apply to the aorrtc planner; {} plans with \
                 rrt-connect (give --planner aorrtc)",
                file.display()
            ));
        }
        if a.budget_iterations.is_some() {
            settings.budget.iterations = opts.budget.iterations;
        }
        if a.budget_ms.is_some() {
            settings.budget.time = opts.budget.time;
        }
    }
    if let Some(p) = &a.srdf {
        let (pairs, warnings) =
            srdf::load_disabled_pairs(p, &scene.model).map_err(|e| e.to_string())?;
        for w in warnings {
            eprintln!("warning: {w}");
        }
        settings.srdf = Some((p.display().to_string(), pairs));
    }
    let seed = settings.seed;
    let time_limit_ms = settings.time_limit.as_secs_f64() * 1e3;
    let simplify = settings.simplify;
    let range = settings.range;
    let (planner, budget) = (settings.algorithm, settings.budget);
    let mut outcomes: Vec<PlanOutcome> = Vec::new();
    let mut times: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    for pass in 0..a.passes {
        let plan = armsim::scenarios::arm::task_motion::plan(&scene).map_err(|e| e.to_string())?;
        if pass == 0 {
            for note in plan
                .planner
                .iter()
                .flat_map(|p| p["notes"].as_array().cloned())
            {
                for n in note.iter().filter_map(|n| n.as_str()) {
                    eprintln!("note: {n}");
                }
            }
        }
        for (k, seg) in plan.planned_segments.into_iter().enumerate() {
            if pass == 0 {
                times.push((Vec::new(), Vec::new()));
                outcomes.push(PlanOutcome {
                    scene: scene.name.clone(),
                    problem: seg.step.clone(),
                    result: seg.result.clone(),
                    passes_identical: true,
                });
            }
            let (o, t) = (&mut outcomes[k], &mut times[k]);
            o.passes_identical &= o.result.path == seg.result.path;
            t.0.push(seg.result.plan_time_us);
            t.1.push(seg.result.simplify_time_us);
        }
    }
    for (o, (p, s)) in outcomes.iter_mut().zip(&mut times) {
        o.result.plan_time_us = plan_report::median(p);
        o.result.simplify_time_us = plan_report::median(s);
    }
    let header = ReportHeader {
        model: &scene.model,
        seed,
        simplify,
        passes: a.passes,
        threads: 1,
        time_limit_ms: Some(time_limit_ms),
        range,
        planner,
        budget: (planner == PlannerKind::Aorrtc).then_some(budget),
    };
    Ok(if a.json {
        plan_report::json(&header, &outcomes)
    } else {
        plan_report::text(&header, &outcomes)
    })
}
