//! Study 1, IK: tolerance (decades from 1e-3 to 1e-12) × method on the UR5's `tool0`,
//! against median and 99th-percentile solve time, success rate and the residual reached,
//! over the same random reachable targets (FK of uniform configurations inside the
//! limits, [`crate::kinematics::ik::benchmark::random_targets`]).
//!
//! Methods:
//! - **numeric DLS**: [`IkSolver`] (Levenberg–Marquardt damped least squares with joint
//!   limits and random restarts) with its default restarts and a 50 ms budget per target;
//!   each solve is repeated (same seed) and its time is the median of the repeats;
//! - **QP**: [`qp_ik`] (a clarabel QP per step) from the middle of the limits, then from
//!   random configurations while the same budget lasts (the library's `qp_ik` has no
//!   restarts of its own; without them it is a local method);
//! - **analytic**: [`AnalyticSolver`] (closed form, every branch). It has no tolerance: its
//!   time is measured once and the same figures appear in every row; a row's success is
//!   whether its answer (the branch nearest the middle of the limits) is within that row's
//!   tolerance.
//!
//! Position and rotation use the same tolerance (m and rad), as `armsim ik --tol` does.

use crate::core::spatial::Se3;
use crate::kinematics::ik::analytic::{AnalyticOptions, AnalyticSolver};
use crate::kinematics::ik::benchmark::random_targets;
use crate::kinematics::ik::qp::{qp_ik, QpIkOptions};
use crate::kinematics::ik::{rotation_log, IkOptions, IkSolver, IkStatus};
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::Model;
use crate::studies::tradeoffs::study_options::Options;
use crate::studies::tradeoffs::study_timing::Stats;
use rand::rngs::SmallRng;
use rand::SeedableRng;
use serde::Serialize;
use std::time::{Duration, Instant};

/// Sizes of the IK study.
#[derive(Clone, Debug)]
pub struct IkConfig {
    /// Random reachable targets.
    pub targets: usize,
    /// Tolerances (m and rad), loosest first.
    pub tolerances: Vec<f64>,
    /// Time budget per target for the iterative methods (ms).
    pub budget_ms: f64,
    /// Timed repetitions of each analytic solve (its per-target time is their median).
    pub analytic_repeats: usize,
    /// Timed repetitions of each numeric DLS solve (same seed, same answer; the
    /// per-target time is their median, so a preemption does not pose as a slow target).
    pub numeric_repeats: usize,
}

impl IkConfig {
    /// The sizes of `mode`.
    pub fn for_mode(mode: crate::studies::tradeoffs::study_options::StudyMode) -> Self {
        let decades = |lo: i32| (3..=lo).map(|k| 10f64.powi(-k)).collect::<Vec<_>>();
        match mode {
            crate::studies::tradeoffs::study_options::StudyMode::Tiny => IkConfig {
                targets: 6,
                tolerances: vec![1e-3, 1e-6, 1e-9, 1e-12],
                budget_ms: 20.0,
                analytic_repeats: 5,
                numeric_repeats: 3,
            },
            crate::studies::tradeoffs::study_options::StudyMode::Quick => IkConfig {
                targets: 40,
                tolerances: decades(12),
                budget_ms: 50.0,
                analytic_repeats: 21,
                numeric_repeats: 5,
            },
            crate::studies::tradeoffs::study_options::StudyMode::Full => IkConfig {
                targets: 200,
                tolerances: decades(12),
                budget_ms: 50.0,
                analytic_repeats: 51,
                numeric_repeats: 5,
            },
        }
    }
}

/// Method names as they appear in the report.
pub const NUMERIC: &str = "numeric DLS";
/// See [`NUMERIC`].
pub const QP: &str = "QP";
/// See [`NUMERIC`].
pub const ANALYTIC: &str = "analytic";

/// One (method, tolerance) cell.
#[derive(Clone, Debug, Serialize)]
pub struct IkRow {
    /// [`NUMERIC`], [`QP`] or [`ANALYTIC`].
    pub method: &'static str,
    /// Tolerance (m and rad).
    pub tol: f64,
    /// Targets attempted.
    pub targets: usize,
    /// Fraction within the tolerance.
    pub success_rate: f64,
    /// Solve time over targets (µs).
    pub time_us: Stats,
    /// Mean iterations (QP: steps) per target, over all attempts.
    pub mean_iterations: f64,
    /// Mean restarts per target.
    pub mean_restarts: f64,
    /// Residual `max(position error, rotation error)` over the successful targets.
    pub residual: Stats,
}

/// Result of the IK study.
#[derive(Clone, Debug, Serialize)]
pub struct IkStudy {
    /// Robot.
    pub robot: String,
    /// Link solved for.
    pub link: String,
    /// Targets per cell.
    pub targets: usize,
    /// Budget per target of the iterative methods (ms).
    pub budget_ms: f64,
    /// The analytic family recognised, if any.
    pub analytic_kind: Option<String>,
    /// Rows, method-major, loosest tolerance first.
    pub rows: Vec<IkRow>,
}

impl IkStudy {
    /// The rows of one method.
    pub fn method(&self, m: &str) -> Vec<&IkRow> {
        self.rows.iter().filter(|r| r.method == m).collect()
    }
}

/// Position and rotation error of `q` for `target`.
fn pose_errors(model: &Model, data: &mut Data, link: usize, q: &[f64], target: &Se3) -> f64 {
    forward_kinematics(model, data, q);
    let p = frame_placement(model, data, link);
    let ep = (p.trans - target.trans).norm();
    let er = rotation_log(&(target.rot * p.rot.transpose())).norm();
    ep.max(er)
}

fn finish(
    method: &'static str,
    tol: f64,
    times: &[f64],
    residuals: &[f64],
    iterations: usize,
    restarts: usize,
) -> IkRow {
    let n = times.len().max(1) as f64;
    IkRow {
        method,
        tol,
        targets: times.len(),
        success_rate: residuals.len() as f64 / n,
        time_us: Stats::of(times),
        mean_iterations: iterations as f64 / n,
        mean_restarts: restarts as f64 / n,
        residual: Stats::of(residuals),
    }
}

/// The numeric damped-least-squares rows, one per tolerance (median of the repeats per
/// target).
fn numeric_rows(
    model: &Model,
    link: usize,
    targets: &[Se3],
    budget: Duration,
    opts: &Options,
    cfg: &IkConfig,
    rows: &mut Vec<IkRow>,
) {
    let mut solver = IkSolver::new(model);
    for &tol in &cfg.tolerances {
        opts.say(format!("ik: {NUMERIC}, tol {tol:.0e}"));
        let (mut times, mut res) = (Vec::new(), Vec::new());
        let (mut iters, mut restarts) = (0, 0);
        for (i, t) in targets.iter().enumerate() {
            let o = IkOptions {
                tol_position: tol,
                tol_rotation: tol,
                time_budget: budget,
                seed: opts.seed.wrapping_add(i as u64),
                ..Default::default()
            };
            let mut reps = Vec::with_capacity(cfg.numeric_repeats.max(1));
            let mut r = solver.solve(model, link, t, None, &o);
            reps.push(r.time_us);
            for _ in 1..cfg.numeric_repeats.max(1) {
                r = solver.solve(model, link, t, None, &o);
                reps.push(r.time_us);
            }
            times.push(Stats::of(&reps).median);
            iters += r.iterations;
            restarts += r.restarts;
            if r.status == IkStatus::Converged {
                res.push(r.position_error.max(r.rotation_error));
            }
        }
        rows.push(finish(NUMERIC, tol, &times, &res, iters, restarts));
    }
}

/// The QP rows, one per tolerance: QP steps from the middle of the limits, restarted from
/// random configurations within the budget.
fn qp_rows(
    model: &Model,
    link: usize,
    targets: &[Se3],
    (budget, mid): (Duration, &[f64]),
    opts: &Options,
    cfg: &IkConfig,
    rows: &mut Vec<IkRow>,
) {
    for &tol in &cfg.tolerances {
        opts.say(format!("ik: {QP}, tol {tol:.0e}"));
        let qo = QpIkOptions {
            tol_position: tol,
            tol_rotation: tol,
            ..Default::default()
        };
        let (mut times, mut res) = (Vec::new(), Vec::new());
        let (mut iters, mut restarts) = (0, 0);
        for (i, t) in targets.iter().enumerate() {
            let mut rng = SmallRng::seed_from_u64(opts.seed.wrapping_add(i as u64));
            let start = Instant::now();
            let mut q0 = mid.to_vec();
            let mut attempt = 0;
            let best = loop {
                let r = qp_ik(model, link, t, &q0, &qo);
                iters += r.iterations;
                if r.status == IkStatus::Converged || start.elapsed() >= budget {
                    break r;
                }
                attempt += 1;
                q0 = model.random_q(&mut rng);
            };
            times.push(start.elapsed().as_secs_f64() * 1e6);
            restarts += attempt;
            if best.status == IkStatus::Converged {
                res.push(best.position_error.max(best.rotation_error));
            }
        }
        rows.push(finish(QP, tol, &times, &res, iters, restarts));
    }
}

/// The analytic rows: each target solved (timed) once, the solution nearest the middle of
/// the limits judged against every tolerance.
fn analytic_rows(
    model: &Model,
    link: usize,
    targets: &[Se3],
    solver: &AnalyticSolver,
    (mid, opts): (&[f64], &Options),
    cfg: &IkConfig,
    rows: &mut Vec<IkRow>,
) {
    let mut data = Data::new(model);
    opts.say(format!("ik: {ANALYTIC}"));
    let aopts = AnalyticOptions::default();
    let mut times = Vec::new();
    let mut errors = Vec::new(); // None: no solution
    let mut reps = vec![0.0; cfg.analytic_repeats.max(1)];
    for t in targets {
        let mut sols = None;
        for r in reps.iter_mut() {
            let t0 = Instant::now();
            let s = solver.solve(t, &aopts);
            *r = t0.elapsed().as_secs_f64() * 1e6;
            sols = Some(s);
        }
        times.push(Stats::of(&reps).median);
        let err = match sols {
            Some(Ok(s)) if !s.is_empty() => {
                let dist =
                    |q: &[f64]| -> f64 { q.iter().zip(mid).map(|(a, b)| (a - b).powi(2)).sum() };
                let best = s
                    .iter()
                    .min_by(|a, b| dist(&a.q).total_cmp(&dist(&b.q)))
                    .expect("non-empty");
                Some(pose_errors(model, &mut data, link, &best.q, t))
            }
            _ => None,
        };
        errors.push(err);
    }
    for &tol in &cfg.tolerances {
        let res: Vec<f64> = errors
            .iter()
            .flatten()
            .copied()
            .filter(|e| *e <= tol)
            .collect();
        rows.push(finish(ANALYTIC, tol, &times, &res, 0, 0));
    }
}

/// Runs the study on the UR5.
pub fn run(opts: &Options, cfg: &IkConfig) -> Result<IkStudy, String> {
    let model = crate::studies::tradeoffs::bundled_robots::bundled_robot("ur5.urdf")?;
    let link_name = "tool0";
    let link = model
        .link_id(link_name)
        .ok_or("ur5.urdf has no link 'tool0'")?;
    let targets = random_targets(&model, link, cfg.targets, opts.seed);
    let budget = Duration::from_secs_f64(cfg.budget_ms * 1e-3);
    let mut rows = Vec::new();
    numeric_rows(&model, link, &targets, budget, opts, cfg, &mut rows);
    let mid = model.neutral();
    qp_rows(&model, link, &targets, (budget, &mid), opts, cfg, &mut rows);
    let analytic = AnalyticSolver::new(&model, link).ok();
    if let Some(solver) = &analytic {
        analytic_rows(&model, link, &targets, solver, (&mid, opts), cfg, &mut rows);
    }
    Ok(IkStudy {
        robot: model.name.clone(),
        link: link_name.into(),
        targets: targets.len(),
        budget_ms: cfg.budget_ms,
        analytic_kind: analytic.map(|s| s.kind().as_str().to_string()),
        rows,
    })
}
