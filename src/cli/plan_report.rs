//! Output of `armsim plan`: the per-problem tables and the summary in the columns the VAMP
//! anchor prints (`../shared/benchmarks/motion-planning/vamp/anchor.sh`), and the JSON
//! contract `{"joints", "results": [{"problem", "status", "reason", "plan_time_us",
//! "simplify_time_us", "iterations", "cost_initial", "cost", "path"}], "summary"}`.
//!
//! Statistics follow the anchor: over the solved problems, the median of a problem's times
//! over the passes, then the median / mean / 95th percentile (linear interpolation, as
//! numpy) / maximum over problems; "valid" counts the problems whose start and goal are
//! valid (not `invalid_start` / `invalid_goal`).

use armsim::model::Model;
use armsim::planning::plan_options::{OptimiseBudget, PlannerKind};
use armsim::planning::{PlanResult, PlanStatus};
use serde_json::{json, Value};
use std::fmt::Write as _;

/// One planned problem.
#[derive(Debug)]
pub struct PlanOutcome {
    /// The folder's name (scene kind, e.g. `table_pick`).
    pub scene: String,
    /// The problem id (`NNNN`).
    pub problem: String,
    /// The first pass's result with the median times over the passes.
    pub result: PlanResult,
    /// Whether every pass returned the same status and path.
    pub passes_identical: bool,
}

/// What the run was.
pub struct ReportHeader<'a> {
    /// The robot.
    pub model: &'a Model,
    /// Seed.
    pub seed: u64,
    /// Simplification on.
    pub simplify: bool,
    /// Passes per problem.
    pub passes: usize,
    /// Threads.
    pub threads: usize,
    /// Time limit per search.
    pub time_limit_ms: Option<f64>,
    /// Longest RRT-Connect step.
    pub range: f64,
    /// The search.
    pub planner: PlannerKind,
    /// The optimising mode's budget (`None` for RRT-Connect).
    pub budget: Option<OptimiseBudget>,
}

/// Median (the mean of the two middle values for an even count; NaN when empty).
pub fn median(v: &mut [f64]) -> f64 {
    percentile(v, 50.0)
}

/// The `p`-th percentile with numpy's default linear interpolation (NaN when empty).
pub fn percentile(v: &mut [f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let x = p / 100.0 * (v.len() - 1) as f64;
    let (lo, hi) = (x.floor() as usize, x.ceil() as usize);
    v[lo] + (x - lo as f64) * (v[hi] - v[lo])
}

/// The anchor's summary figures of a set of problems.
#[derive(Debug)]
struct Stats {
    solved: usize,
    valid: usize,
    total: usize,
    plan: [f64; 4],
    simplify: [f64; 2],
    total_time: [f64; 2],
    cost_initial: f64,
    cost: f64,
    iterations: [f64; 2],
}

fn stats(outcomes: &[&PlanOutcome]) -> Stats {
    let solved: Vec<&PlanResult> = outcomes
        .iter()
        .map(|o| &o.result)
        .filter(|r| r.status == PlanStatus::Solved)
        .collect();
    let col = |f: &dyn Fn(&PlanResult) -> f64| solved.iter().map(|r| f(r)).collect::<Vec<_>>();
    let mean = |v: &[f64]| {
        if v.is_empty() {
            f64::NAN
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    let max = |v: &[f64]| v.iter().copied().fold(f64::NAN, f64::max);
    let mut plan = col(&|r| r.plan_time_us);
    let mut simp = col(&|r| r.simplify_time_us);
    let mut tot = col(&|r| r.plan_time_us + r.simplify_time_us);
    let mut iters = col(&|r| r.iterations as f64);
    Stats {
        solved: solved.len(),
        valid: outcomes
            .iter()
            .filter(|o| {
                !matches!(
                    o.result.status,
                    PlanStatus::InvalidStart | PlanStatus::InvalidGoal
                )
            })
            .count(),
        total: outcomes.len(),
        plan: [
            median(&mut plan),
            mean(&plan),
            percentile(&mut plan, 95.0),
            max(&plan),
        ],
        simplify: [median(&mut simp), mean(&simp)],
        total_time: [median(&mut tot), mean(&tot)],
        cost_initial: median(&mut col(&|r| r.cost_initial)),
        cost: median(&mut col(&|r| r.cost)),
        iterations: [median(&mut iters), max(&iters)],
    }
}

/// The scenes in order of first appearance, each with its outcomes.
fn by_scene(outcomes: &[PlanOutcome]) -> Vec<(String, Vec<&PlanOutcome>)> {
    let mut out: Vec<(String, Vec<&PlanOutcome>)> = Vec::new();
    for o in outcomes {
        match out.iter_mut().find(|(s, _)| *s == o.scene) {
            Some((_, v)) => v.push(o),
            None => out.push((o.scene.clone(), vec![o])),
        }
    }
    out
}

/// A JSON number, or null when not finite.
fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

fn stats_json(scene: &str, s: &Stats) -> Value {
    json!({
        "scene": scene,
        "solved": s.solved,
        "valid": s.valid,
        "total": s.total,
        "plan_time_us": {"median": num(s.plan[0]), "mean": num(s.plan[1]),
                         "p95": num(s.plan[2]), "max": num(s.plan[3])},
        "simplify_time_us": {"median": num(s.simplify[0]), "mean": num(s.simplify[1])},
        "total_time_us": {"median": num(s.total_time[0]), "mean": num(s.total_time[1])},
        "cost_initial_median": num(s.cost_initial),
        "cost_median": num(s.cost),
        "iterations": {"median": num(s.iterations[0]), "max": num(s.iterations[1])},
    })
}

/// The JSON output (pretty-printed, with a trailing newline).
pub fn json(h: &ReportHeader, outcomes: &[PlanOutcome]) -> String {
    let results: Vec<Value> = outcomes
        .iter()
        .map(|o| {
            let r = &o.result;
            json!({
                "scene": o.scene,
                "problem": o.problem,
                "status": r.status,
                "reason": r.reason,
                "plan_time_us": r.plan_time_us,
                "simplify_time_us": r.simplify_time_us,
                "iterations": r.iterations,
                "cost_initial": r.cost_initial,
                "cost": r.cost,
                "improvements": r.improvements,
                "goal": r.path.last(),
                "path": r.path,
            })
        })
        .collect();
    let mut scenes: Vec<Value> = by_scene(outcomes)
        .iter()
        .map(|(s, v)| stats_json(s, &stats(v)))
        .collect();
    let all: Vec<&PlanOutcome> = outcomes.iter().collect();
    scenes.push(stats_json("ALL", &stats(&all)));
    let v = json!({
        "joints": h.model.dof_names(),
        "seed": h.seed,
        "simplify": h.simplify,
        "passes": h.passes,
        "time_limit_ms": h.time_limit_ms,
        "range": h.range,
        "planner": h.planner.name(),
        "budget_iterations": h.budget.map(|b| b.iterations),
        "budget_ms": h.budget.and_then(|b| b.time).map(|t| t.as_secs_f64() * 1e3),
        "results": results,
        "summary": scenes,
    });
    let mut s = serde_json::to_string_pretty(&v).unwrap_or_default();
    s.push('\n');
    s
}

/// `x` with `prec` decimals, or `-` when there is no value (no solved problem).
fn fixed(x: f64, prec: usize) -> String {
    if x.is_finite() {
        format!("{x:.prec$}")
    } else {
        "-".to_string()
    }
}

fn status_name(s: PlanStatus) -> &'static str {
    match s {
        PlanStatus::Solved => "solved",
        PlanStatus::Failed => "failed",
        PlanStatus::InvalidStart => "invalid_start",
        PlanStatus::InvalidGoal => "invalid_goal",
    }
}

/// The text output: a table per scene, then the summary.
pub fn text(h: &ReportHeader, outcomes: &[PlanOutcome]) -> String {
    let mut t = String::new();
    let limit = h
        .time_limit_ms
        .map_or("none".to_string(), |ms| format!("{ms} ms"));
    let planner = match h.budget {
        None => h.planner.name().to_string(),
        Some(b) => format!(
            "{} (budget {} iterations{})",
            h.planner.name(),
            b.iterations,
            b.time
                .map_or(String::new(), |t| format!(", {} ms", t.as_secs_f64() * 1e3))
        ),
    };
    let _ = writeln!(
        t,
        "armsim plan: {} ({} joints: {}), planner {planner}, seed {}, range {}, simplify {}, time limit {limit}, {} pass(es), {} thread(s)",
        h.model.name,
        h.model.nv,
        h.model.dof_names().join(" "),
        h.seed,
        h.range,
        if h.simplify { "on" } else { "off" },
        h.passes,
        h.threads
    );
    let groups = by_scene(outcomes);
    for (scene, v) in &groups {
        let _ = writeln!(t, "\n{scene}: {} problems", v.len());
        t.push_str("| problem | status | plan µs | simplify µs | iterations | cost initial | cost | waypoints |\n");
        t.push_str("|---|---|---|---|---|---|---|---|\n");
        for o in v {
            let r = &o.result;
            let _ = writeln!(
                t,
                "| {} | {} | {:.1} | {:.1} | {} | {:.3} | {:.3} | {} |",
                o.problem,
                status_name(r.status),
                r.plan_time_us,
                r.simplify_time_us,
                r.iterations,
                r.cost_initial,
                r.cost,
                r.path.len()
            );
        }
        for o in v.iter().filter(|o| o.result.reason.is_some()) {
            let why = o.result.reason.as_deref().unwrap_or_default();
            let _ = writeln!(t, "  {} {}: {why}", o.problem, status_name(o.result.status));
        }
    }
    let _ = writeln!(
        t,
        "\nPer-problem times = median over {} identical passes; times in microseconds",
        h.passes
    );
    let hdr = "| scene | solved/valid/total | plan med | plan mean | plan p95 | plan max | simp med | simp mean | total med | total mean | init cost med | simp cost med | iters med | iters max |";
    let _ = writeln!(t, "{hdr}");
    let _ = writeln!(t, "|{}", "---|".repeat(hdr.matches('|').count() - 1));
    let all: Vec<&PlanOutcome> = outcomes.iter().collect();
    let mut rows: Vec<(&str, Stats)> = groups.iter().map(|(s, v)| (s.as_str(), stats(v))).collect();
    if groups.len() > 1 {
        rows.push(("ALL", stats(&all)));
    }
    for (scene, s) in rows {
        let f1 = |x: f64| fixed(x, 1);
        let _ = writeln!(
            t,
            "| {scene} | {}/{}/{} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            s.solved,
            s.valid,
            s.total,
            f1(s.plan[0]),
            f1(s.plan[1]),
            f1(s.plan[2]),
            f1(s.plan[3]),
            f1(s.simplify[0]),
            f1(s.simplify[1]),
            f1(s.total_time[0]),
            f1(s.total_time[1]),
            fixed(s.cost_initial, 3),
            fixed(s.cost, 3),
            fixed(s.iterations[0], 0),
            fixed(s.iterations[1], 0)
        );
    }
    t
}

#[cfg(test)]
mod tests {
    use crate::cli::plan_report::*;

    #[test]
    fn percentile_matches_numpy_linear_interpolation() {
        // numpy.percentile([1, 2, 3, 4, 10], 95) = 4 + 0.8 * (10 - 4) = 8.8
        let mut v = vec![10.0, 2.0, 4.0, 1.0, 3.0];
        assert!((percentile(&mut v, 95.0) - 8.8).abs() < 1e-12);
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(&mut [5.0]), 5.0);
        assert!(median(&mut []).is_nan());
    }
}
