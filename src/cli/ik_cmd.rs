//! `armsim ik`: numeric IK (Levenberg–Marquardt with limits and restarts) or every
//! closed-form branch (`--analytic`), for one target pose or a CSV file of targets.

use crate::cli::{limit, link_id, load, parse_values, print_json, ModelArgs};
use armsim::core::spatial::{Se3, Vec3};
use armsim::kinematics;
use armsim::model::data::Data;
use armsim::model::Model;
use serde_json::{json, Value};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct IkArgs {
    #[command(flatten)]
    pub m: ModelArgs,
    /// The link whose frame should reach the target.
    #[arg(long)]
    pub link: String,
    /// Target x,y,z,qw,qx,qy,qz (world frame; quaternion w first).
    #[arg(long, allow_hyphen_values = true)]
    pub target: Option<String>,
    /// CSV file of targets, rows x,y,z,qw,qx,qy,qz (an optional header row).
    #[arg(long)]
    pub targets: Option<PathBuf>,
    /// Position only (the quaternion, if given, is ignored).
    #[arg(long)]
    pub position_only: bool,
    /// Tolerance for position (m) and rotation (rad).
    #[arg(long, default_value_t = 1e-6)]
    pub tol: f64,
    /// Start configuration (default: the middle of the limits).
    #[arg(long, allow_hyphen_values = true)]
    pub seed_q: Option<String>,
    /// Random restarts allowed per target.
    #[arg(long, default_value_t = 200)]
    pub restarts: usize,
    /// Time budget per target (ms). A target that cannot be reached uses all of it, so
    /// the targets × this may be at most 60 000 ms (one minute of solver time) without
    /// --force.
    #[arg(long, default_value_t = 50.0)]
    pub budget_ms: f64,
    /// Run a batch whose worst case (targets × --budget-ms) is over the one-minute budget.
    #[arg(long)]
    pub force: bool,
    /// Let iterates leave the joint limits.
    #[arg(long)]
    pub no_limits: bool,
    /// Closed-form IK (UR family, spherical-wrist 6R, textbook R-R-P, planar 2R): every
    /// branch inside the limits; `q` is the branch nearest the start configuration.
    #[arg(long)]
    pub analytic: bool,
}

/// `armsim ik`.
pub fn run(a: &IkArgs) -> Result<(), String> {
    ik_cmd(&load(&a.m)?, a, a.m.json)
}

use armsim::kinematics::ik::MAX_TARGET_DISTANCE;

/// The most solver time (ms) a numeric IK run may be given without `--force`: targets ×
/// `--budget-ms`, what a batch of unreachable targets spends (each uses its whole
/// budget). One minute: 1 200 targets at the default 50 ms.
pub const MAX_IK_WORK_MS: f64 = 60_000.0;

/// The largest `--budget-ms` accepted at all (about 11.6 days), as the planner's
/// `--time-limit-ms`.
const MAX_BUDGET_MS: f64 = 1e9;

/// Refuses `rows` targets at `budget_ms` each when their worst case is over
/// [`MAX_IK_WORK_MS`] (checked row by row while a file is read, so a huge file is refused
/// at the first row over the budget); `what` names the file and line, or `--target`.
fn check_ik_work(rows: usize, o: &IkArgs, what: &str) -> Result<(), String> {
    let total = rows as f64 * o.budget_ms;
    if o.analytic || o.force || total <= MAX_IK_WORK_MS {
        return Ok(());
    }
    let fit = (MAX_IK_WORK_MS / o.budget_ms).floor();
    let fmt = armsim::core::diag::fmt_num;
    Err(format!(
        "{what}: target {rows} is over the work budget: at --budget-ms {} each (an unreachable \
         target uses its whole budget), at most {} targets fit the {} s of solver time \
         (targets × --budget-ms) allowed without --force: lower --budget-ms, split the \
         targets, or pass --force to run it",
        fmt(o.budget_ms),
        fmt(fit),
        fmt(MAX_IK_WORK_MS * 1e-3)
    ))
}

/// A pose from `x,y,z,qw,qx,qy,qz` (or `x,y,z` when only the position matters).
fn parse_pose(s: &str, position_only: bool, what: &str) -> Result<Se3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("{what}: '{s}' has a value that is not a number"))?;
    if !v.iter().all(|x| x.is_finite()) {
        return Err(format!("{what}: '{s}' has a non-finite value"));
    }
    if let Some(x) = v.iter().take(3).find(|x| x.abs() > MAX_TARGET_DISTANCE) {
        return Err(format!(
            "{what}: the position coordinate {} m is beyond the {} m accepted for a target",
            armsim::core::diag::fmt_num(*x),
            armsim::core::diag::fmt_num(MAX_TARGET_DISTANCE)
        ));
    }
    let p = match v.len() {
        3 if position_only => return Ok(Se3::from_translation(Vec3::new(v[0], v[1], v[2]))),
        7 => Vec3::new(v[0], v[1], v[2]),
        n => {
            return Err(format!(
                "{what}: expected 7 values x,y,z,qw,qx,qy,qz{}, got {n}",
                if position_only { " (or x,y,z)" } else { "" }
            ))
        }
    };
    // Scale by the largest component before the norm: [1e200, 1e200, 0, 0] overflows
    // the sum of squares but is a fine rotation.
    let big = v[3..7].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if big == 0.0 {
        return Err(format!("{what}: the quaternion is zero"));
    }
    let quat = nalgebra::Quaternion::new(v[3] / big, v[4] / big, v[5] / big, v[6] / big);
    if quat.norm() * big < 1e-9 {
        return Err(format!(
            "{what}: the quaternion's norm {} is too small to give a rotation",
            armsim::core::diag::fmt_num(quat.norm() * big)
        ));
    }
    let r = nalgebra::UnitQuaternion::from_quaternion(quat).to_rotation_matrix();
    Ok(Se3::new(*r.matrix(), p))
}

fn ik_cmd(model: &Model, o: &IkArgs, as_json: bool) -> Result<(), String> {
    use armsim::kinematics::ik::{solve_batch, IkOptions};
    let link = link_id(model, &o.link)?;
    if !(o.tol > 0.0 && o.tol.is_finite()) {
        return Err(format!("--tol: {} is not a positive number", o.tol));
    }
    if !(o.budget_ms > 0.0 && o.budget_ms <= MAX_BUDGET_MS) {
        return Err(format!(
            "--budget-ms: {} is not a positive number of at most 1e9 ms",
            armsim::core::diag::fmt_num(o.budget_ms)
        ));
    }
    let seed = o
        .seed_q
        .as_deref()
        .map(|s| parse_values(model, "seed-q", s))
        .transpose()?;
    let targets: Vec<Se3> = match (&o.target, &o.targets) {
        (Some(t), None) => {
            check_ik_work(1, o, "--budget-ms")?;
            vec![parse_pose(t, o.position_only, "--target")?]
        }
        (None, Some(file)) => {
            let text = armsim::core::files::read_input_string(file)
                .map_err(|e| format!("{}: cannot read: {e}", file.display()))?;
            let mut out = Vec::new();
            let mut first_row = true;
            for (i, line) in text.lines().enumerate() {
                let l = line.trim();
                if l.is_empty() || l.starts_with('#') {
                    continue;
                }
                let header = first_row && l.chars().next().is_some_and(|c| c.is_ascii_alphabetic());
                first_row = false;
                if header {
                    continue; // one header row, the first
                }
                let what = format!("{}:{}", file.display(), i + 1);
                check_ik_work(out.len() + 1, o, &what)?;
                out.push(parse_pose(l, o.position_only, &what)?);
            }
            if out.is_empty() {
                return Err(format!("{}: no targets", file.display()));
            }
            out
        }
        (Some(_), Some(_)) => return Err("give either --target or --targets, not both".into()),
        (None, None) => {
            return Err("give a --target x,y,z,qw,qx,qy,qz or a --targets FILE.csv".into())
        }
    };
    let opts = IkOptions {
        position_only: o.position_only,
        tol_position: o.tol,
        tol_rotation: o.tol,
        max_restarts: o.restarts,
        time_budget: std::time::Duration::from_secs_f64(o.budget_ms * 1e-3),
        respect_limits: !o.no_limits,
        ..Default::default()
    };
    if o.analytic {
        return ik_analytic_cmd(model, link, &targets, seed.as_deref(), o, as_json);
    }
    // Levenberg–Marquardt holds an nv × nv normal matrix per thread.
    armsim::model::data::dense_fits(model).map_err(|m| format!("{}: {m}", model.source))?;
    let results = solve_batch(model, link, &targets, seed.as_deref(), &opts);
    if as_json {
        let rows: Vec<Value> = results
            .iter()
            .map(|r| {
                json!({
                    "q": r.q,
                    "status": r.status.as_str(),
                    "position_error": limit(r.position_error),
                    "rotation_error": limit(r.rotation_error),
                    "iterations": r.iterations,
                    "restarts": r.restarts,
                    "time_us": r.time_us,
                })
            })
            .collect();
        print_json(&json!({"joints": model.dof_names(), "link": o.link, "results": rows}));
        return Ok(());
    }
    println!("joints: {}", model.dof_names().join(" "));
    for (i, r) in results.iter().enumerate() {
        println!(
            "target {i}: {} after {} iterations, {} restarts, {:.1} µs; position error {:.3e} m, rotation error {:.3e} rad",
            r.status.as_str(),
            r.iterations,
            r.restarts,
            r.time_us,
            r.position_error,
            r.rotation_error
        );
        let q: Vec<String> = r.q.iter().map(|x| format!("{x:.9}")).collect();
        println!("  q = {}", q.join(", "));
    }
    Ok(())
}

/// `armsim ik --analytic`: every closed-form branch inside the limits per target.
fn ik_analytic_cmd(
    model: &Model,
    link: usize,
    targets: &[Se3],
    seed: Option<&[f64]>,
    o: &IkArgs,
    as_json: bool,
) -> Result<(), String> {
    use armsim::kinematics::ik::analytic::{AnalyticOptions, AnalyticSolver};
    let solver = AnalyticSolver::new(model, link).map_err(|e| format!("{}: {e}", model.source))?;
    let start_q = seed.map(<[f64]>::to_vec).unwrap_or_else(|| model.neutral());
    let aopts = AnalyticOptions {
        respect_limits: !o.no_limits,
        ..Default::default()
    };
    let mut rows = Vec::new();
    for t in targets {
        let t0 = std::time::Instant::now();
        let sols = solver.solve(t, &aopts);
        let time_us = t0.elapsed().as_secs_f64() * 1e6;
        let row = match sols {
            Ok(sols) if !sols.is_empty() => {
                let dist = |q: &[f64]| {
                    q.iter()
                        .zip(&start_q)
                        .map(|(a, b)| (a - b).powi(2))
                        .sum::<f64>()
                };
                let best = sols
                    .iter()
                    .min_by(|a, b| dist(&a.q).total_cmp(&dist(&b.q)))
                    .expect("non-empty");
                let mut data = Data::new(model);
                kinematics::forward_kinematics(model, &mut data, &best.q);
                let p = kinematics::frame_placement(model, &data, link);
                let pe = (p.trans - t.trans).norm();
                let re = armsim::kinematics::ik::rotation_log(&(t.rot * p.rot.transpose())).norm();
                json!({
                    "q": best.q,
                    "status": "converged",
                    "position_error": pe,
                    "rotation_error": if o.position_only { 0.0 } else { re },
                    "iterations": 0,
                    "time_us": time_us,
                    "solutions": sols.iter().map(|s| json!({"q": s.q, "branch": s.branch, "singular": s.singular})).collect::<Vec<_>>(),
                })
            }
            Ok(_) => {
                json!({"q": start_q, "status": "unreachable", "position_error": null, "rotation_error": null, "iterations": 0, "time_us": time_us, "solutions": [], "reason": "no solution"})
            }
            Err(e) => {
                json!({"q": start_q, "status": "unreachable", "position_error": null, "rotation_error": null, "iterations": 0, "time_us": time_us, "solutions": [], "reason": e.to_string()})
            }
        };
        rows.push(row);
    }
    if as_json {
        print_json(&json!({"joints": model.dof_names(), "link": o.link, "results": rows}));
        return Ok(());
    }
    println!("joints: {}", model.dof_names().join(" "));
    for (i, r) in rows.iter().enumerate() {
        let sols = r["solutions"].as_array().map(Vec::len).unwrap_or(0);
        println!(
            "target {i}: {} ({sols} branch(es) inside the limits, {:.2} µs)",
            r["status"].as_str().unwrap_or(""),
            r["time_us"].as_f64().unwrap_or(0.0)
        );
        for s in r["solutions"].as_array().into_iter().flatten() {
            let q: Vec<String> = s["q"]
                .as_array()
                .into_iter()
                .flatten()
                .map(|x| format!("{:.9}", x.as_f64().unwrap_or(f64::NAN)))
                .collect();
            println!(
                "  {:<36} {}{}",
                s["branch"].as_str().unwrap_or(""),
                q.join(", "),
                if s["singular"].as_bool() == Some(true) {
                    "  (singular)"
                } else {
                    ""
                }
            );
        }
        if let Some(reason) = r.get("reason") {
            println!("  {}", reason.as_str().unwrap_or(""));
        }
    }
    Ok(())
}
