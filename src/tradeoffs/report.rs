//! The report files: `tradeoffs.md` (machine, mode, and per study a description, a
//! table, the plots and a reading generated from the numbers), one PNG per plot and
//! `tradeoffs.json` (every figure), all written atomically into one directory.

use super::formulations::NAMES as FORMULATIONS;
use super::ik::{ANALYTIC, NUMERIC, QP};
use super::integrators::{median_step_us, Outcome, METHODS};
use super::plot::{render_bars, render_panels, BarGroup, Flag, Legend, Panel, Series, PALETTE};
use super::{log_slope, Report};
use crate::workspace::Sampling;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// File name of the Markdown report.
pub const MARKDOWN: &str = "tradeoffs.md";
/// File name of the JSON figures.
pub const JSON: &str = "tradeoffs.json";

/// `12.3 µs`, `4.56 ms`, `789 ns` from nanoseconds.
pub fn fmt_ns(ns: f64) -> String {
    if !ns.is_finite() {
        "–".into()
    } else if ns >= 1e9 {
        format!("{:.2} s", ns * 1e-9)
    } else if ns >= 1e6 {
        format!("{:.2} ms", ns * 1e-6)
    } else if ns >= 1e3 {
        format!("{:.2} µs", ns * 1e-3)
    } else {
        format!("{ns:.0} ns")
    }
}

/// `1.2e-5` (or `0` / `–`).
pub fn sci(x: f64) -> String {
    if x.is_nan() {
        "–".into()
    } else if x.is_infinite() {
        "∞".into()
    } else if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.1e}")
    }
}

/// `97.5 %`.
fn pct(x: f64) -> String {
    let p = 100.0 * x;
    if (p - p.round()).abs() < 1e-9 {
        format!("{p:.0} %")
    } else {
        format!("{p:.1} %")
    }
}

/// Writes the PNGs, `tradeoffs.md` and `tradeoffs.json` into `dir` (created if needed),
/// each atomically. Returns the paths written.
pub fn write(report: &Report, dir: &Path) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    let mut written = Vec::new();
    let mut put = |name: &str, bytes: &[u8]| -> Result<(), String> {
        let p = dir.join(name);
        crate::io::write_atomic(&p, bytes)
            .map_err(|e| format!("{}: cannot write: {e}", p.display()))?;
        written.push(p);
        Ok(())
    };
    let plots = plots(report)?;
    for (name, bytes) in &plots {
        put(name, bytes)?;
    }
    let json = serde_json::to_string_pretty(report).map_err(|e| e.to_string())?;
    put(JSON, json.as_bytes())?;
    put(MARKDOWN, markdown(report).as_bytes())?;
    Ok(written)
}

/// Every plot of the report as `(file name, PNG bytes)`.
pub fn plots(r: &Report) -> Result<Vec<(String, Vec<u8>)>, String> {
    let mut out = Vec::new();
    // 1. IK.
    let methods = [NUMERIC, QP, ANALYTIC];
    let ik_series = |f: &dyn Fn(&super::ik::IkRow) -> f64| -> Vec<Series> {
        methods
            .iter()
            .enumerate()
            .filter(|(_, m)| !r.ik.method(m).is_empty())
            .map(|(i, m)| Series {
                label: (*m).to_string(),
                points: r.ik.method(m).iter().map(|row| (row.tol, f(row))).collect(),
                color: PALETTE[i],
                dashed: false,
            })
            .collect()
    };
    let mut time_series = ik_series(&|row| row.time_us.median);
    for (i, m) in methods.iter().enumerate() {
        if r.ik.method(m).is_empty() {
            continue;
        }
        time_series.push(Series {
            label: format!("{m} p99"),
            points: r
                .ik
                .method(m)
                .iter()
                .map(|row| (row.tol, row.time_us.p99))
                .collect(),
            color: PALETTE[i],
            dashed: true,
        });
    }
    out.push((
        "ik_time.png".to_string(),
        render_panels(
            &format!(
                "IK on {} ({} targets): solve time vs tolerance",
                r.ik.robot, r.ik.targets
            ),
            &[Panel {
                title: "median (solid) and p99 (dashed) time per target".into(),
                x_desc: "tolerance (m and rad)".into(),
                y_desc: "time (µs)".into(),
                log_x: true,
                log_y: true,
                series: time_series,
                legend: Legend::UpperRight,
                headroom: 0.4,
                ..Default::default()
            }],
            1,
            (900, 560),
        )?,
    ));
    out.push((
        "ik_success.png".to_string(),
        render_panels(
            &format!(
                "IK on {} ({} targets): success rate vs tolerance",
                r.ik.robot, r.ik.targets
            ),
            &[Panel {
                title: format!(
                    "converged within tolerance and the {} ms budget",
                    r.ik.budget_ms
                ),
                x_desc: "tolerance (m and rad)".into(),
                y_desc: "success rate (%)".into(),
                log_x: true,
                log_y: false,
                series: ik_series(&|row| 100.0 * row.success_rate),
                y_range: Some((-3.0, 105.0)),
                legend: Legend::LowerLeft,
                layered: true,
                ..Default::default()
            }],
            1,
            (900, 480),
        )?,
    ));

    // 2. Integrators: energy error and tracking error vs dt, diverged runs flagged.
    let st = &r.integrators;
    let integ_panel = |case: &super::integrators::IntegratorCase, tracking: bool| -> Panel {
        let mut series = Vec::new();
        let mut flags = Vec::new();
        for (i, m) in METHODS.iter().enumerate() {
            let cells = st.series(&case.name, m.as_str());
            let pick = |c: &super::integrators::IntegratorCell| -> Outcome {
                if tracking {
                    c.tracking.clone()
                } else {
                    c.energy.clone()
                }
            };
            series.push(Series {
                label: m.as_str().into(),
                points: cells
                    .iter()
                    .filter_map(|c| pick(c).value().map(|v| (c.dt, v)))
                    .collect(),
                color: PALETTE[i],
                dashed: false,
            });
            flags.extend(cells.iter().filter(|c| pick(c).diverged()).map(|c| Flag {
                x: c.dt,
                color: PALETTE[i],
                lane: i,
            }));
        }
        Panel {
            title: format!("{} arm", case.name),
            x_desc: "step dt (s)".into(),
            y_desc: if tracking {
                "max tracking error (rad)".into()
            } else {
                "max relative energy error".into()
            },
            log_x: true,
            log_y: true,
            series,
            flags,
            flag_label: "diverged".into(),
            y_range: None,
            // Errors grow with the step: the lower right is free for energy errors, the
            // upper left for tracking errors (whose elastic floor fills the bottom).
            legend: if tracking {
                Legend::UpperLeft
            } else {
                Legend::LowerRight
            },
            headroom: 0.0,
            layered: true,
        }
    };
    let energy_panels: Vec<Panel> = st.cases.iter().map(|c| integ_panel(c, false)).collect();
    out.push((
        "integrators_energy.png".to_string(),
        render_panels(
            &format!(
                "{}: energy error of free motion under gravity vs step ({} s)",
                st.robot, st.duration
            ),
            &energy_panels,
            2,
            (700, 520),
        )?,
    ));
    let tracking_panels: Vec<Panel> = st.cases.iter().map(|c| integ_panel(c, true)).collect();
    out.push((
        "integrators_tracking.png".to_string(),
        render_panels(
            &format!(
                "{}: computed-torque tracking error vs step ({} s)",
                st.robot, st.duration
            ),
            &tracking_panels,
            2,
            (700, 520),
        )?,
    ));
    // Accuracy against cost: tracking error vs wall time.
    let cost_panels: Vec<Panel> = st
        .cases
        .iter()
        .map(|case| Panel {
            title: format!("{} arm", case.name),
            x_desc: "wall time of the run (s)".into(),
            y_desc: "max tracking error (rad)".into(),
            log_x: true,
            log_y: true,
            series: METHODS
                .iter()
                .enumerate()
                .map(|(i, m)| Series {
                    label: m.as_str().into(),
                    points: st
                        .series(&case.name, m.as_str())
                        .iter()
                        .filter_map(|c| Some((c.wall_s?, c.tracking.value()?)))
                        .collect(),
                    color: PALETTE[i],
                    dashed: false,
                })
                .collect(),
            legend: Legend::UpperRight,
            ..Default::default()
        })
        .collect();
    out.push((
        "integrators_cost.png".to_string(),
        render_panels(
            &format!(
                "{}: tracking error against wall time (each point one step size)",
                st.robot
            ),
            &cost_panels,
            2,
            (700, 520),
        )?,
    ));

    // 3. Formulations.
    let fs = &r.formulations;
    out.push((
        "dynamics_time.png".to_string(),
        render_panels(
            "Dynamics formulations: time per call vs DOF (generated chains)",
            &[Panel {
                title: "median time per call".into(),
                x_desc: "degrees of freedom".into(),
                y_desc: "time per call (ns)".into(),
                log_x: true,
                log_y: true,
                series: FORMULATIONS
                    .iter()
                    .enumerate()
                    .map(|(k, name)| Series {
                        label: (*name).into(),
                        points: fs.series(k),
                        color: PALETTE[k],
                        dashed: false,
                    })
                    .collect(),
                ..Default::default()
            }],
            1,
            (900, 600),
        )?,
    ));

    // 4. Workspace.
    let ws = &r.workspace;
    let ws_panels: Vec<Panel> = ws
        .cases
        .iter()
        .map(|case| {
            let mut series = Vec::new();
            for (i, s) in [Sampling::Random, Sampling::Sobol].iter().enumerate() {
                let rows = ws.series(&case.name, *s);
                let name = if *s == Sampling::Random {
                    "random"
                } else {
                    "Sobol'"
                };
                series.push(Series {
                    label: format!("{name}: mean |error|"),
                    points: rows
                        .iter()
                        .map(|r| (r.samples as f64, r.mean_abs_error))
                        .collect(),
                    color: PALETTE[i],
                    dashed: false,
                });
                series.push(Series {
                    label: format!("{name}: reported 95 % half-width"),
                    points: rows
                        .iter()
                        .filter(|r| r.median_band.is_finite())
                        .map(|r| (r.samples as f64, r.median_band))
                        .collect(),
                    color: PALETTE[i],
                    dashed: true,
                });
            }
            Panel {
                title: format!(
                    "{} (truth {:.4} {}, voxel {} m)",
                    case.name, case.truth, case.unit, case.voxel
                ),
                x_desc: "samples N".into(),
                y_desc: format!("error ({})", case.unit),
                log_x: true,
                log_y: true,
                series,
                legend: Legend::LowerLeft,
                ..Default::default()
            }
        })
        .collect();
    out.push((
        "workspace_error.png".to_string(),
        render_panels(
            "Workspace measure: error vs samples, random vs Sobol' (band: where finite)",
            &ws_panels,
            2,
            (700, 540),
        )?,
    ));

    out.push((
        "workspace_convergence.png".to_string(),
        workspace_convergence_png(&ws.convergence)?,
    ));

    // 5. Effects.
    let ef = &r.effects;
    let cats: Vec<String> = ef.rows.iter().map(|r| r.name.clone()).collect();
    out.push((
        "effects_cost.png".to_string(),
        render_bars(
            &format!(
                "{}: cost of each effect relative to the bare rigid model",
                ef.robot
            ),
            "time / bare (median)",
            &cats,
            &[
                BarGroup {
                    label: "inverse dynamics".into(),
                    values: ef.rows.iter().map(|r| r.inverse_ratio).collect(),
                    color: PALETTE[0],
                },
                BarGroup {
                    label: "simulation step (forward dynamics + update)".into(),
                    values: ef.rows.iter().map(|r| r.step_ratio).collect(),
                    color: PALETTE[1],
                },
            ],
            Some(1.0),
            &|v| format!("{v:.2}"),
            (1000, 520),
        )?,
    ));
    Ok(out)
}

/// The Markdown report.
pub fn markdown(r: &Report) -> String {
    let mut s = String::new();
    let m = &r.machine;
    let _ = writeln!(s, "# armsim trade-offs report\n");
    let _ = writeln!(
        s,
        "Generated by `armsim tradeoffs` in **{} mode**{}. Every figure below was measured in this run; \
         timings are medians (with 99th percentiles where a distribution exists) on a shared machine, \
         so expect a few per cent of noise between runs. The raw figures are in [`{JSON}`]({JSON}).\n",
        r.mode.as_str(),
        match r.mode {
            super::Mode::Full => "",
            super::Mode::Quick => " (reduced sizes: `--quick`; run without it for the full study)",
            super::Mode::Tiny => " (smoke-test sizes: the numbers are coarse)",
        }
    );
    let load1 = m
        .load_start
        .as_deref()
        .and_then(|l| l.split_whitespace().next()?.parse::<f64>().ok());
    if let Some(l) = load1.filter(|l| *l > m.cores as f64) {
        let _ = writeln!(
            s,
            "The machine was shared and busy during this run (1-minute load average {l:.1} on {} logical cores): \
             wall times of long runs (the integrator runs, QP solves) include time spent waiting for a CPU, \
             while the per-call medians, taken over short rounds, mostly are not.\n",
            m.cores
        );
    }
    let _ = writeln!(s, "| | |\n|---|---|");
    let _ = writeln!(s, "| date | {} |", m.date);
    let _ = writeln!(s, "| armsim | {} |", m.version);
    let _ = writeln!(s, "| CPU | {} |", m.cpu);
    let _ = writeln!(
        s,
        "| cores | {} logical ({} available to the process) |",
        m.cores, m.available_threads
    );
    let _ = writeln!(s, "| OS | {} |", m.os);
    let _ = writeln!(
        s,
        "| load average (1, 5, 15 min) | start {}, end {} |",
        m.load_start.as_deref().unwrap_or("–"),
        m.load_end.as_deref().unwrap_or("–")
    );
    let per: Vec<String> = r
        .study_seconds
        .iter()
        .map(|(n, t)| format!("{n} {t:.1} s"))
        .collect();
    let _ = writeln!(
        s,
        "| wall time | {:.1} s ({}) |\n",
        r.total_seconds,
        per.join(", ")
    );
    let _ = writeln!(s, "Contents: [1. IK](#1-inverse-kinematics-tolerance--method) · [2. Integrators](#2-integrators-step-size--method) · [3. Dynamics formulations](#3-dynamics-formulations-time-vs-dof) · [4. Workspace sampling](#4-workspace-sampling-samples--scheme) · [5. Effects](#5-effects-cost-of-each-effect)\n");
    ik_section(&mut s, r);
    integrator_section(&mut s, r);
    formulation_section(&mut s, r);
    workspace_section(&mut s, r);
    effects_section(&mut s, r);
    s
}

fn ik_section(s: &mut String, r: &Report) {
    let st = &r.ik;
    let _ = writeln!(s, "## 1. Inverse kinematics: tolerance × method\n");
    let _ = writeln!(
        s,
        "{} link `{}`, {} random reachable targets (FK of uniform random configurations inside the limits), \
         the same targets for every cell; position and rotation tolerance equal (m, rad). \
         **numeric DLS**: Levenberg–Marquardt damped least squares with limits and random restarts (budget {} ms per target; \
         each solve repeated with the same seed, its time the median of the repeats, so that a preemption on the shared machine \
         does not pose as a slow target). \
         **QP**: one clarabel QP per step from the middle of the limits, restarted from random configurations within the same budget \
         (checked between attempts, so an attempt can overrun it; timed once per target). \
         **analytic**: closed form ({}), every branch; it has no tolerance, so it is timed once (median over repeats per target) \
         and a row's success says whether its answer (the branch nearest the middle of the limits) meets that row's tolerance. \
         Residual = max(position error, rotation error) over the successful targets.\n",
        st.robot,
        st.link,
        st.targets,
        st.budget_ms,
        st.analytic_kind.as_deref().unwrap_or("not available for this arm")
    );
    let _ = writeln!(
        s,
        "| method | tolerance | median time | p99 time | success | mean iterations | mean restarts | median residual | max residual |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for row in &st.rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {:.1} | {:.2} | {} | {} |",
            row.method,
            sci(row.tol),
            fmt_ns(row.time_us.median * 1e3),
            fmt_ns(row.time_us.p99 * 1e3),
            pct(row.success_rate),
            row.mean_iterations,
            row.mean_restarts,
            if row.residual.count > 0 {
                sci(row.residual.median)
            } else {
                "–".into()
            },
            if row.residual.count > 0 {
                sci(row.residual.max)
            } else {
                "–".into()
            },
        );
    }
    let _ = writeln!(
        s,
        "\n![IK time vs tolerance](ik_time.png)\n\n![IK success vs tolerance](ik_success.png)\n"
    );
    let _ = writeln!(s, "**Reading.** {}\n", ik_reading(r));
}

/// The generated reading of the IK study.
pub fn ik_reading(r: &Report) -> String {
    let st = &r.ik;
    let mut out = Vec::new();
    let ends = |m: &str| {
        let rows = st.method(m);
        Some((rows.first().copied()?, rows.last().copied()?))
    };
    if let Some((a, b)) = ends(NUMERIC) {
        out.push(format!(
            "The numeric DLS solver's median time grows {:+.0} % from {} to {} ({} → {}, p99 {} → {}) and its success rate goes from {} to {}.",
            100.0 * (b.time_us.median / a.time_us.median - 1.0),
            sci(a.tol),
            sci(b.tol),
            fmt_ns(a.time_us.median * 1e3),
            fmt_ns(b.time_us.median * 1e3),
            fmt_ns(a.time_us.p99 * 1e3),
            fmt_ns(b.time_us.p99 * 1e3),
            pct(a.success_rate),
            pct(b.success_rate)
        ));
    }
    if let (Some((a, b)), Some((na, nb))) = (ends(QP), ends(NUMERIC)) {
        out.push(format!(
            "The QP method is {:.0}× slower than DLS at {} and {:.0}× at {} (median), with success {} → {}.",
            a.time_us.median / na.time_us.median,
            sci(a.tol),
            b.time_us.median / nb.time_us.median,
            sci(b.tol),
            pct(a.success_rate),
            pct(b.success_rate)
        ));
    }
    if let (Some((a, b)), Some((_, nb))) = (ends(ANALYTIC), ends(NUMERIC)) {
        let worst = st
            .method(ANALYTIC)
            .iter()
            .map(|r| r.residual.max)
            .fold(0.0, f64::max);
        out.push(format!(
            "The analytic solver answers in {} (median, p99 {}), {:.1}× faster than DLS at {}; its answers are accurate to {} and meet {} of the targets at {} and {} at {}.",
            fmt_ns(a.time_us.median * 1e3),
            fmt_ns(a.time_us.p99 * 1e3),
            nb.time_us.median / a.time_us.median,
            sci(b.tol),
            sci(worst),
            pct(a.success_rate),
            sci(a.tol),
            pct(b.success_rate),
            sci(b.tol)
        ));
    }
    out.join(" ")
}

fn outcome_cell(o: &Outcome) -> String {
    match o {
        Outcome::Value { value } => sci(*value),
        Outcome::Diverged { t } => format!("**diverged** (t = {t:.3} s)"),
        Outcome::Failed { message } => format!("failed: {message}"),
    }
}

fn integrator_section(s: &mut String, r: &Report) {
    let st = &r.integrators;
    let _ = writeln!(s, "## 2. Integrators: step size × method\n");
    let _ = writeln!(
        s,
        "Each cell is two runs of {} s from the same configuration. **Energy error**: free motion under gravity, \
         no controller and nothing dissipating, `max |E(t) − E(0)|` relative to the energy scale (the simulator's audit). \
         **Tracking error**: computed torque (K_p = 100, K_d = 20) following `q_d = q₀ + 0.3 (1 − cos πt)` rad, \
         `max |q − q_d|` over joints and time; on the rigid arm the controller's model is exact and the reference starts at rest, \
         so this is pure integration error, while on the elastic arm the link also lags the motors through the springs. \
         **Wall time**: the tracking run (per-step energy audit included; runs under 0.2 s are repeated and the median of three \
         kept, longer ones are exposed to whatever else the machine runs). Methods: semi-implicit (symplectic) Euler, \
         classic RK4, linearly implicit Euler (one Newton step of backward Euler, finite-difference Jacobian). \
         **diverged** = the simulator stopped with `SimError::Diverged`.\n",
        st.duration
    );
    for case in &st.cases {
        let _ = writeln!(
            s,
            "**{} arm**: {}{}.\n",
            case.name,
            case.description,
            case.fastest_mode
                .map_or(String::new(), |w| format!("; fastest mode ≈ {w:.0} rad/s"))
        );
        let _ = writeln!(
            s,
            "| method | dt (s) | energy error | tracking error (rad) | wall time | per step |"
        );
        let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|");
        for m in METHODS {
            for c in st.series(&case.name, m.as_str()) {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} |",
                    c.method,
                    sci(c.dt),
                    outcome_cell(&c.energy),
                    outcome_cell(&c.tracking),
                    c.wall_s.map_or("–".into(), |w| fmt_ns(w * 1e9)),
                    c.us_per_step.map_or("–".into(), |u| fmt_ns(u * 1e3)),
                );
            }
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "![energy error vs dt](integrators_energy.png)\n\n![tracking error vs dt](integrators_tracking.png)\n\n![tracking error vs wall time](integrators_cost.png)\n"
    );
    let _ = writeln!(s, "**Reading.** {}\n", integrator_reading(r));
}

/// Observed order of `method` on `case`: the log-log slope of the energy error over the
/// (up to) four smallest finished steps whose error is above the rounding floor.
pub fn observed_order(r: &Report, case: &str, method: &str) -> Option<f64> {
    let mut pts: Vec<(f64, f64)> = r
        .integrators
        .series(case, method)
        .iter()
        .filter_map(|c| c.energy.value().map(|v| (c.dt, v)))
        .filter(|(_, v)| *v > 1e-12 && *v < 1e-1)
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    pts.truncate(4);
    log_slope(&pts)
}

/// The generated reading of the integrator study.
pub fn integrator_reading(r: &Report) -> String {
    let st = &r.integrators;
    let mut out = Vec::new();
    for case in &st.cases {
        let orders: Vec<String> = METHODS
            .iter()
            .filter_map(|m| {
                observed_order(r, &case.name, m.as_str())
                    .map(|p| format!("{} {:.1}", m.as_str(), p))
            })
            .collect();
        let mut diverge = Vec::new();
        for m in METHODS {
            match (
                st.smallest_diverged_dt(&case.name, m.as_str()),
                st.largest_stable_dt(&case.name, m.as_str()),
            ) {
                (Some(d), Some(ok)) => diverge.push(match case.fastest_mode {
                    Some(w) => format!(
                        "{} diverges at dt = {} (h·ω = {:.2}) and is stable at {} (h·ω = {:.2})",
                        m.as_str(),
                        sci(d),
                        d * w,
                        sci(ok),
                        ok * w
                    ),
                    None => format!(
                        "{} diverges at dt = {} and is stable at {}",
                        m.as_str(),
                        sci(d),
                        sci(ok)
                    ),
                }),
                (Some(d), None) => diverge.push(format!(
                    "{} diverges at every step down to {}",
                    m.as_str(),
                    sci(d)
                )),
                (None, _) => diverge.push(format!("{} is stable at every step tried", m.as_str())),
            }
        }
        let costs: Vec<String> = METHODS
            .iter()
            .filter_map(|m| {
                median_step_us(st, &case.name, m.as_str())
                    .map(|u| format!("{} {}", m.as_str(), fmt_ns(u * 1e3)))
            })
            .collect();
        // Cheapest run meeting a tracking target.
        let goal = 1e-4;
        let cheapest = st
            .cells
            .iter()
            .filter(|c| c.case == case.name)
            .filter_map(|c| Some((c, c.wall_s?, c.tracking.value()?)))
            .filter(|(_, _, e)| *e <= goal)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let cheapest = match cheapest {
            Some((c, w, e)) => format!(
                "the cheapest run tracking within {} rad is {} at dt = {} ({} wall, error {})",
                sci(goal),
                c.method,
                sci(c.dt),
                fmt_ns(w * 1e9),
                sci(e)
            ),
            None => format!("no run tracks within {} rad", sci(goal)),
        };
        // A tracking floor no step removes (the springs' lag on the elastic arm).
        let finished: Vec<(f64, f64)> = st
            .series(&case.name, "rk4")
            .iter()
            .filter_map(|c| Some((c.dt, c.tracking.value()?)))
            .collect();
        let floor = match finished.as_slice() {
            [.., (_, a), (dt, b)] if *b > 1e-6 && b / a > 0.9 => format!(
                "; the tracking error levels off at {} rad (RK4 at dt = {}): it is physical, not numerical, and smaller steps do not remove it",
                sci(*b),
                sci(*dt)
            ),
            _ => String::new(),
        };
        out.push(format!(
            "On the {} arm the energy error's observed order (slope over the smallest steps) is {}; {}; wall time per step (median) {}; {}{}.",
            case.name,
            if orders.is_empty() { "not measurable".into() } else { orders.join(", ") },
            diverge.join(", "),
            costs.join(", "),
            cheapest,
            floor
        ));
    }
    out.join(" ")
}

fn formulation_section(s: &mut String, r: &Report) {
    let st = &r.formulations;
    let _ = writeln!(s, "## 3. Dynamics formulations: time vs DOF\n");
    let _ = writeln!(
        s,
        "Generated chains (`armsim chain N`: alternating z/y/x revolute joints, 1 kg links). Time per call at random states \
         (256 states cycled; median over rounds, p99 across rounds in the JSON). Inverse dynamics: RNEA, the textbook's trace-form \
         Lagrange (O(n⁴), allocates; run up to {} DOF) and the energy/Christoffel form (up to {} DOF). Forward dynamics: CRBA + \
         Cholesky and ABA, fed `τ = RNEA(q, q̇, q̈)` so that every method computes the same answer. Agreement over {} states: \
         `|q̈_ABA − q̈_CRBA|` (absolute and relative to max |q̈|), the round trip `|q̈_ABA − q̈|/max|q̈|`, and `|τ_RNEA − τ_Lagrange|/max|τ|`.\n",
        st.max_dof_trace, st.max_dof_energy, st.agreement_states
    );
    let _ = writeln!(s, "| DOF | {} | ABA vs CRBA abs | ABA vs CRBA rel | round trip | RNEA vs trace | RNEA vs energy |", FORMULATIONS.join(" | "));
    let _ = writeln!(
        s,
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for row in &st.rows {
        let times: Vec<String> = row
            .ns
            .iter()
            .map(|t| t.map_or("–".into(), |t| fmt_ns(t.median)))
            .collect();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} |",
            row.dof,
            times.join(" | "),
            sci(row.aba_vs_crba_abs),
            sci(row.aba_vs_crba_rel),
            sci(row.roundtrip_rel),
            row.rnea_vs_trace_rel.map_or("–".into(), sci),
            row.rnea_vs_energy_rel.map_or("–".into(), sci),
        );
    }
    let _ = writeln!(s, "\n![time vs DOF](dynamics_time.png)\n");
    let _ = writeln!(s, "**Reading.** {}\n", formulation_reading(r));
}

/// The generated reading of the formulation study.
pub fn formulation_reading(r: &Report) -> String {
    let st = &r.formulations;
    let mut out = Vec::new();
    let slopes: Vec<String> = (0..FORMULATIONS.len())
        .filter_map(|k| {
            let pts: Vec<(f64, f64)> = st
                .series(k)
                .into_iter()
                .filter(|(n, _)| *n >= 8.0)
                .collect();
            (pts.len() >= 2).then(|| {
                let (a, b) = (pts[0], pts[pts.len() - 1]);
                format!(
                    "{} n^{:.1} ({} → {} from {} to {} DOF)",
                    FORMULATIONS[k],
                    log_slope(&pts).unwrap_or(f64::NAN),
                    fmt_ns(a.1),
                    fmt_ns(b.1),
                    a.0,
                    b.0
                )
            })
        })
        .collect();
    if !slopes.is_empty() {
        out.push(format!(
            "Fitted growth from 8 DOF up: {}.",
            slopes.join(", ")
        ));
    }
    // ABA vs CRBA + Cholesky crossover.
    let both: Vec<(usize, f64, f64)> = st
        .rows
        .iter()
        .filter_map(|r| Some((r.dof, r.ns[1]?.median, r.ns[2]?.median)))
        .collect();
    if let Some(&(n_max, crba, aba)) = both.last() {
        let first_aba = both.iter().find(|(_, c, a)| a < c).map(|x| x.0);
        let msg = match first_aba {
            Some(n) if n == both[0].0 => format!("ABA is faster than CRBA + Cholesky at every size ({:.1}× at {n_max} DOF)", crba / aba),
            Some(n) => format!(
                "CRBA + Cholesky is the faster forward dynamics on short chains and ABA from {n} DOF on ({:.1}× faster at {n_max} DOF)",
                crba / aba
            ),
            None => format!("CRBA + Cholesky stays faster than ABA up to {n_max} DOF ({:.1}×)", aba / crba),
        };
        out.push(format!("{msg}."));
    }
    if let Some(row) = st.rows.iter().rev().find(|r| r.ns[3].is_some()) {
        out.push(format!(
            "At {} DOF the trace-form Lagrange takes {:.0}× RNEA's time{}.",
            row.dof,
            row.ns[3].map_or(f64::NAN, |t| t.median) / row.ns[0].map_or(f64::NAN, |t| t.median),
            st.rows
                .iter()
                .rev()
                .find(|r| r.ns[4].is_some())
                .map_or(String::new(), |e| format!(
                    " (the energy form {:.0}× at {} DOF)",
                    e.ns[4].map_or(f64::NAN, |t| t.median) / e.ns[0].map_or(f64::NAN, |t| t.median),
                    e.dof
                ))
        ));
    }
    let worst = |f: &dyn Fn(&super::formulations::FormulationRow) -> Option<f64>| {
        st.rows.iter().filter_map(f).fold(0.0, f64::max)
    };
    out.push(format!(
        "They agree: max |q̈_ABA − q̈_CRBA| = {} rad/s² ({} relative), round trip {}, RNEA vs trace-form Lagrange {}, vs energy form {} (relative).",
        sci(worst(&|r| Some(r.aba_vs_crba_abs))),
        sci(worst(&|r| Some(r.aba_vs_crba_rel))),
        sci(worst(&|r| Some(r.roundtrip_rel))),
        sci(worst(&|r| r.rnea_vs_trace_rel)),
        sci(worst(&|r| r.rnea_vs_energy_rel)),
    ));
    out.join(" ")
}

fn workspace_section(s: &mut String, r: &Report) {
    let st = &r.workspace;
    let _ = writeln!(s, "## 4. Workspace sampling: samples × scheme\n");
    let _ = writeln!(
        s,
        "`sample_workspace` with {} replicates per estimate (N = replicates × 2^k samples), randomly shifted grids, \
         {} rayon threads; the estimate is the headline (bias-corrected closed occupancy plus the boundary slivers still to come), \
         compared with the closed form. Its own error estimate: the 95 % interval (the band: its half-width; ∞ while only \
         a lower bound is given); σ is the replicates' spread. Each cell is the mean over independent seeds \
         (the band: their median); \"truth in finite band\" = how often the reported interval contained the truth, among the \
         runs whose band was finite. Seeds per cell: {}.\n",
        st.replicates,
        st.threads,
        st.rows.first().map_or(0, |r| r.seeds)
    );
    for case in &st.cases {
        let _ = writeln!(
            s,
            "**{}**: {}; truth {:.6} {}; voxel {} m.\n",
            case.name, case.description, case.truth, case.unit, case.voxel
        );
        let _ = writeln!(s, "| N | scheme | mean abs error | rel. error | raw occupancy rel. error | mean σ | median band | band finite | truth in finite band | time (median) |");
        let _ = writeln!(s, "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|");
        let rand = st.series(&case.name, Sampling::Random);
        let sob = st.series(&case.name, Sampling::Sobol);
        for (a, b) in rand.iter().zip(&sob) {
            for row in [a, b] {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                    row.samples,
                    if row.sampling == Sampling::Random {
                        "random"
                    } else {
                        "Sobol'"
                    },
                    sci(row.mean_abs_error),
                    pct(row.mean_rel_error),
                    pct(row.mean_rel_error_raw),
                    sci(row.mean_stderr),
                    sci(row.median_band),
                    pct(row.converged_fraction),
                    row.covered_fraction.map_or("–".into(), pct),
                    fmt_ns(row.time_s.median * 1e9),
                );
            }
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s, "![workspace error vs samples](workspace_error.png)\n");
    let c = &st.convergence;
    let _ = writeln!(
        s,
        "**Convergence of one run** ({}, voxel {} m, Sobol', truth {:.4} m³): the estimate and its 95 % interval \
         after every doubling of the samples (only a lower bound while coverage has not converged).\n",
        c.case, c.voxel, c.truth
    );
    let _ = writeln!(
        s,
        "![workspace estimate and interval vs samples](workspace_convergence.png)\n"
    );
    let _ = writeln!(s, "**Reading.** {}\n", workspace_reading(r));
}

/// The smallest N at which `rows` (by increasing N) reach a relative error of `goal`
/// and stay there.
fn samples_to_reach(rows: &[&super::workspace::WorkspaceRow], goal: f64) -> Option<u64> {
    let last_bad = rows.iter().rposition(|r| r.mean_rel_error > goal);
    match last_bad {
        None => rows.first().map(|r| r.samples),
        Some(i) => rows.get(i + 1).map(|r| r.samples),
    }
}

/// The generated reading of the workspace study.
pub fn workspace_reading(r: &Report) -> String {
    let st = &r.workspace;
    let mut out = Vec::new();
    let goal = 0.05;
    for case in &st.cases {
        let rand = st.series(&case.name, Sampling::Random);
        let sob = st.series(&case.name, Sampling::Sobol);
        let (Some(ra), Some(sa)) = (rand.last(), sob.last()) else {
            continue;
        };
        let reach = match (samples_to_reach(&sob, goal), samples_to_reach(&rand, goal)) {
            (Some(s), Some(r)) => format!(
                "the error drops below {} for good at N = {s} with Sobol' and N = {r} with random sampling",
                pct(goal)
            ),
            (Some(s), None) => format!(
                "the error drops below {} for good at N = {s} with Sobol' and not by N = {} with random sampling",
                pct(goal),
                ra.samples
            ),
            (None, Some(r)) => format!(
                "the error drops below {} for good at N = {r} with random sampling and not by N = {} with Sobol'",
                pct(goal),
                ra.samples
            ),
            (None, None) => format!("neither scheme gets below {} by N = {}", pct(goal), ra.samples),
        };
        let uncovered = rand
            .iter()
            .chain(&sob)
            .filter(|r| r.converged_fraction == 0.0)
            .map(|r| r.samples)
            .max();
        let conv: Vec<&&super::workspace::WorkspaceRow> = rand
            .iter()
            .chain(&sob)
            .filter(|r| r.converged_fraction > 0.0)
            .collect();
        let covered = if conv.is_empty() {
            "no run's coverage converged, so no finite band was reported".to_string()
        } else {
            let tot: f64 = conv
                .iter()
                .map(|r| r.converged_fraction * r.seeds as f64)
                .sum();
            let hit: f64 = conv
                .iter()
                .map(|r| r.covered_fraction.unwrap_or(0.0) * r.converged_fraction * r.seeds as f64)
                .sum();
            format!(
                "where the sampler reported a finite band the truth was inside it in {} of the runs",
                pct(hit / tot.max(1.0))
            )
        };
        out.push(format!(
            "{}: the estimate counts occupied cells, so it means nothing until the grid is covered (below that it is even negative, and the sampler reports an infinite band up to N = {}); \
             {}; at N = {} it is {} (Sobol') against {} (random), \
             the raw occupancy's {} / {}; {}; one estimate at that N takes {} (random) / {} (Sobol').",
            case.name,
            uncovered.map_or("–".into(), |n| n.to_string()),
            reach,
            ra.samples,
            pct(sa.mean_rel_error),
            pct(ra.mean_rel_error),
            pct(sa.mean_rel_error_raw),
            pct(ra.mean_rel_error_raw),
            covered,
            fmt_ns(ra.time_s.median * 1e9),
            fmt_ns(sa.time_s.median * 1e9),
        ));
    }
    if st.cases.len() > 1 {
        out.push("A coarser grid is covered with fewer samples but keeps a larger discretisation error; a finer one needs more samples before its estimate means anything.".into());
    }
    out.join(" ")
}

fn effects_section(s: &mut String, r: &Report) {
    let st = &r.effects;
    let _ = writeln!(s, "## 5. Effects: cost of each effect\n");
    let _ = writeln!(
        s,
        "{}: each effect switched on alone against the bare rigid model (no gravity), then all together. \
         **Inverse dynamics**: one `inverse_dynamics` call at a random (q, q̇, q̈) (with elastic joints this is the rigid \
         link-side computation, so it costs what the bare model does). **Step**: one semi-implicit Euler step, i.e. one \
         forward-dynamics evaluation (`forward_dynamics_with`, or `elastic_forward_dynamics` whose state also carries the \
         motor angles) and the state update, from stored random states. Interleaved passes; median and p99 over all rounds; \
         ratios of medians.\n",
        st.robot
    );
    let _ = writeln!(
        s,
        "| effect | what | inverse dynamics | p99 | × bare | step | p99 | × bare |"
    );
    let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|---:|");
    for row in &st.rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.2} | {} | {} | {:.2} |",
            row.name,
            row.description,
            fmt_ns(row.inverse_ns.median),
            fmt_ns(row.inverse_ns.p99),
            row.inverse_ratio,
            fmt_ns(row.step_ns.median),
            fmt_ns(row.step_ns.p99),
            row.step_ratio
        );
    }
    let _ = writeln!(s, "\n![cost of each effect](effects_cost.png)\n");
    let _ = writeln!(s, "**Reading.** {}\n", effects_reading(r));
}

/// The generated reading of the effects study.
pub fn effects_reading(r: &Report) -> String {
    let st = &r.effects;
    let singles: Vec<&super::effects::EffectRow> = st
        .rows
        .iter()
        .filter(|r| r.name != "bare" && r.name != "all")
        .collect();
    let mut out = Vec::new();
    if let Some(top) = singles
        .iter()
        .max_by(|a, b| a.step_ratio.total_cmp(&b.step_ratio))
    {
        out.push(format!(
            "The most expensive single effect per simulation step is {} (×{:.2} the bare step, {} → {}).",
            top.name,
            top.step_ratio,
            fmt_ns(st.rows[0].step_ns.median),
            fmt_ns(top.step_ns.median)
        ));
    }
    if let Some(top) = singles
        .iter()
        .max_by(|a, b| a.inverse_ratio.total_cmp(&b.inverse_ratio))
    {
        out.push(format!(
            "In inverse dynamics the most expensive is {} (×{:.2}).",
            top.name, top.inverse_ratio
        ));
    }
    let cheap: Vec<String> = singles
        .iter()
        .filter(|r| r.step_ratio < 1.1 && r.inverse_ratio < 1.1)
        .map(|r| r.name.clone())
        .collect();
    if !cheap.is_empty() {
        out.push(format!(
            "Within 10 % of the bare model in both: {}.",
            cheap.join(", ")
        ));
    }
    if let Some(all) = st.rows.iter().find(|r| r.name == "all") {
        out.push(format!(
            "Everything on costs ×{:.2} per step and ×{:.2} in inverse dynamics.",
            all.step_ratio, all.inverse_ratio
        ));
    }
    out.join(" ")
}

/// The convergence plot: estimate, interval (lower bound only while not converged) and
/// the closed form against samples.
pub fn workspace_convergence_png(c: &super::workspace::ConvergenceRun) -> Result<Vec<u8>, String> {
    let pts = &c.points;
    let xs = |f: &dyn Fn(&crate::workspace::ConvergencePoint) -> Option<f64>| -> Vec<(f64, f64)> {
        pts.iter()
            .filter_map(|p| f(p).map(|y| (p.samples as f64, y)))
            .collect()
    };
    let (x0, x1) = (
        pts.first().map_or(1.0, |p| p.samples as f64),
        pts.last().map_or(1.0, |p| p.samples as f64),
    );
    let panel = Panel {
        title: format!("{} (voxel {} m)", c.case, c.voxel),
        x_desc: "samples N".into(),
        y_desc: "volume (m³)".into(),
        log_x: true,
        series: vec![
            Series {
                label: "truth (closed form)".into(),
                points: vec![(x0, c.truth), (x1, c.truth)],
                color: PALETTE[2],
                dashed: false,
            },
            Series {
                label: "estimate".into(),
                points: xs(&|p| Some(p.measure)),
                color: PALETTE[0],
                dashed: false,
            },
            Series {
                label: "95 % interval: lower end".into(),
                points: xs(&|p| p.interval[0]),
                color: PALETTE[1],
                dashed: true,
            },
            Series {
                label: "95 % interval: upper end".into(),
                points: xs(&|p| p.interval[1]),
                color: PALETTE[3],
                dashed: true,
            },
        ],
        y_range: Some((0.0, 1.5 * c.truth)),
        legend: Legend::LowerRight,
        ..Default::default()
    };
    render_panels(
        "Workspace volume: estimate and 95 % interval vs samples",
        &[panel],
        1,
        (900, 560),
    )
}
