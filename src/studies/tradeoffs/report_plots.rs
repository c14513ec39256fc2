//! The trade-off report's plots (PNG bytes): IK time and success, integrator errors and
//! cost, dynamics formulations, workspace error and convergence, effects' cost.

use crate::io::plots::panels::{
    render_bars, render_panels, BarGroup, Flag, Legend, Panel, Series, PALETTE,
};
use crate::io::plots::plot_error::PlotError;
use crate::studies::tradeoffs::formulations::NAMES as FORMULATIONS;
use crate::studies::tradeoffs::ik_study::{ANALYTIC, NUMERIC, QP};
use crate::studies::tradeoffs::integrators::{IntegratorOutcome, METHODS};
use crate::studies::tradeoffs::TradeoffsReport;
use crate::workspace::Sampling;

/// Every plot of the report as `(file name, PNG bytes)`.
pub fn plots(r: &TradeoffsReport) -> Result<Vec<(String, Vec<u8>)>, PlotError> {
    let mut out = Vec::new();
    ik_plots(r, &mut out)?;
    integrator_plots(r, &mut out)?;
    formulation_plots(r, &mut out)?;
    workspace_plots(r, &mut out)?;
    effects_plots(r, &mut out)?;
    out.push((
        "rotor_error.png".to_string(),
        crate::studies::tradeoffs::rotor_report::png(&r.rotor)?,
    ));
    use crate::studies::tradeoffs::derivatives_report as deriv;
    out.push((
        "derivatives_error.png".into(),
        deriv::error_png(&r.derivatives)?,
    ));
    out.push((
        "derivatives_cost.png".into(),
        deriv::cost_png(&r.derivatives)?,
    ));
    use crate::studies::tradeoffs::planning_report;
    out.push((
        planning_report::PNG.into(),
        planning_report::png(&r.planning)?,
    ));
    Ok(out)
}

/// Plots as `(file name, PNG bytes)`.
type Plots = Vec<(String, Vec<u8>)>;

/// The IK plots: solve time (median and p99) and success rate against tolerance.
fn ik_plots(r: &TradeoffsReport, out: &mut Plots) -> Result<(), PlotError> {
    let methods = [NUMERIC, QP, ANALYTIC];
    let ik_series =
        |f: &dyn Fn(&crate::studies::tradeoffs::ik_study::IkRow) -> f64| -> Vec<Series> {
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
    Ok(())
}

/// One integrator panel of `case`: energy (or tracking) error against the step per method,
/// diverged runs as crosses.
fn integrator_panel(
    st: &crate::studies::tradeoffs::integrators::IntegratorStudy,
    case: &crate::studies::tradeoffs::integrators::IntegratorCase,
    tracking: bool,
) -> Panel {
    let mut series = Vec::new();
    let mut flags = Vec::new();
    for (i, m) in METHODS.iter().enumerate() {
        let cells = st.series(&case.name, m.as_str());
        let pick =
            |c: &crate::studies::tradeoffs::integrators::IntegratorCell| -> IntegratorOutcome {
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
        equal_aspect: false,
    }
}

/// The integrator plots: energy and tracking error against the step (diverged runs flagged), and
/// tracking error against wall time.
fn integrator_plots(r: &TradeoffsReport, out: &mut Plots) -> Result<(), PlotError> {
    let st = &r.integrators;
    let energy_panels: Vec<Panel> = st
        .cases
        .iter()
        .map(|c| integrator_panel(st, c, false))
        .collect();
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
    let tracking_panels: Vec<Panel> = st
        .cases
        .iter()
        .map(|c| integrator_panel(st, c, true))
        .collect();
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
    Ok(())
}

/// The dynamics-formulation plot: time per call against DOF.
fn formulation_plots(r: &TradeoffsReport, out: &mut Plots) -> Result<(), PlotError> {
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
    Ok(())
}

/// The workspace plots: error against samples (random and Sobol') and the estimator's convergence.
fn workspace_plots(r: &TradeoffsReport, out: &mut Plots) -> Result<(), PlotError> {
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
    Ok(())
}

/// The effects plot: cost of each effect relative to the bare rigid model.
fn effects_plots(r: &TradeoffsReport, out: &mut Plots) -> Result<(), PlotError> {
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
    Ok(())
}

/// The convergence plot: estimate, interval (lower bound only while not converged) and
/// the closed form against samples.
pub fn workspace_convergence_png(
    c: &crate::studies::tradeoffs::workspace_study::ConvergenceRun,
) -> Result<Vec<u8>, PlotError> {
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
