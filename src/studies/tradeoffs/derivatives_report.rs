//! Study 7's part of the trade-offs report: the table per robot (scheme, evaluations,
//! error at a few steps, the best step and error, time, ratio to the analytical call), the
//! plots (`derivatives_error.png`: error against the step per robot, with the analytical
//! error marked; `derivatives_cost.png`: best error against time per call) and the
//! reading generated from the numbers (best steps against ε^½ and ε^⅓, fitted slopes of
//! the two arms of the V, what the differences cost and what they cannot reach).

use crate::io::plots::panels::{render_panels, Legend, Panel, Series, PALETTE};
use crate::io::plots::plot_error::PlotError;
use crate::io::report::fmt_ns;
use crate::studies::tradeoffs::derivatives_study::{
    DerivativeCase, DerivativeStudy, KernelResult, COMPLEX_STEP_NOTE,
};
use crate::studies::tradeoffs::difference_quotients::{
    ridders_evaluations, Kernel, Scheme, RIDDERS_CON, RIDDERS_LEVELS, RIDDERS_STARTS,
    RIDDERS_SWITCH,
};
use crate::studies::tradeoffs::report_numbers::sci;
use crate::studies::tradeoffs::study_timing::log_slope;
use std::fmt::Write as _;

/// The steps shown as table columns (the nearest measured step is used).
const TABLE_STEPS: [f64; 6] = [1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12];

/// Colour of `scheme` on kernel `k` (RNEA: blue, orange; ABA: green, red).
fn color(k: Kernel, scheme: Scheme) -> plotters::style::RGBColor {
    PALETTE[2 * usize::from(k == Kernel::Aba) + usize::from(scheme == Scheme::Central)]
}

/// Colour of kernel `k`'s analytical marks.
fn analytical_color(k: Kernel) -> plotters::style::RGBColor {
    PALETTE[if k == Kernel::Rnea { 7 } else { 4 }]
}

/// `derivatives_error.png`: per robot, the error of each scheme against the step (solid)
/// and the analytical Jacobians' error against the reference (dashed, flat).
pub fn error_png(st: &DerivativeStudy) -> Result<Vec<u8>, PlotError> {
    let (h_lo, h_hi) = (
        st.steps.iter().copied().fold(f64::INFINITY, f64::min),
        st.steps.iter().copied().fold(0.0, f64::max),
    );
    let panels: Vec<Panel> = st
        .cases
        .iter()
        .map(|c| {
            let mut series = Vec::new();
            for k in &c.kernels {
                for s in Scheme::ALL {
                    series.push(Series {
                        label: format!(
                            "{} {} ({}, {:.1}×)",
                            k.kernel.as_str(),
                            s.as_str(),
                            fmt_ns(k.ns(s).median),
                            k.ns(s).median / k.analytical_ns.median
                        ),
                        points: st
                            .steps
                            .iter()
                            .copied()
                            .zip(k.errors(s).iter().copied())
                            .collect(),
                        color: color(k.kernel, s),
                        dashed: false,
                    });
                }
            }
            for k in &c.kernels {
                series.push(Series {
                    label: format!(
                        "{} analytical vs reference ({})",
                        k.kernel.as_str(),
                        fmt_ns(k.analytical_ns.median)
                    ),
                    points: vec![(h_lo, k.analytical_error), (h_hi, k.analytical_error)],
                    color: analytical_color(k.kernel),
                    dashed: true,
                });
            }
            Panel {
                title: format!("{} ({} DOF)", c.name, c.nv),
                x_desc: "step h (rad, m, rad/s, m/s)".into(),
                y_desc: "max relative error of the Jacobian".into(),
                log_x: true,
                log_y: true,
                series,
                legend: Legend::UpperRight,
                headroom: 0.35,
                ..Default::default()
            }
        })
        .collect();
    render_panels(
        "Dynamics derivatives: finite-difference error vs step (legend: time per Jacobian, × analytical)",
        &panels,
        2,
        (760, 560),
    )
}

/// `derivatives_cost.png`: per kernel, the best error each method reaches against its time
/// per Jacobian, one point per robot.
pub fn cost_png(st: &DerivativeStudy) -> Result<Vec<u8>, PlotError> {
    let panels: Vec<Panel> = Kernel::ALL
        .iter()
        .enumerate()
        .map(|(ki, &kernel)| {
            let by = |f: &dyn Fn(&KernelResult) -> (f64, f64)| -> Vec<(f64, f64)> {
                let mut p: Vec<(f64, f64)> = st.cases.iter().map(|c| f(&c.kernels[ki])).collect();
                p.sort_by(|a, b| a.0.total_cmp(&b.0));
                p
            };
            let mut series = vec![Series {
                label: "analytical (error vs reference)".into(),
                points: by(&|k| (k.analytical_ns.median * 1e-3, k.analytical_error)),
                color: analytical_color(kernel),
                dashed: false,
            }];
            for s in Scheme::ALL {
                series.push(Series {
                    label: format!("{} differences at their best step", s.as_str()),
                    points: by(&|k| (k.ns(s).median * 1e-3, st.best(k, s).1)),
                    color: color(kernel, s),
                    dashed: false,
                });
            }
            series.push(Series {
                label: "Ridders reference (its own estimate)".into(),
                points: by(&|k| (k.reference_ns.median * 1e-3, k.reference_estimate)),
                color: PALETTE[5],
                dashed: true,
            });
            Panel {
                title: format!("{} derivatives", kernel.as_str()),
                x_desc: "time per Jacobian (µs, median)".into(),
                y_desc: "max relative error".into(),
                log_x: true,
                log_y: true,
                series,
                legend: Legend::UpperRight,
                headroom: 0.45,
                ..Default::default()
            }
        })
        .collect();
    render_panels(
        "Dynamics derivatives: best error vs time per Jacobian (each point one robot, joined in order of time)",
        &panels,
        2,
        (760, 560),
    )
}

/// One table row: kernel, scheme and evaluations; the errors at [`TABLE_STEPS`]; the best
/// step and error; the time (ns) and the analytical time it is divided by.
fn row(
    s: &mut String,
    first: [&str; 3],
    errors: &[String],
    best: (String, String),
    ns: (f64, f64),
) {
    let _ = writeln!(
        s,
        "| {} | {} | {} | {} | {} | {:.1} |",
        first.join(" | "),
        errors.join(" | "),
        best.0,
        best.1,
        fmt_ns(ns.0),
        ns.0 / ns.1
    );
}

/// The table of one robot.
fn table(s: &mut String, st: &DerivativeStudy, c: &DerivativeCase) {
    let cols: Vec<String> = TABLE_STEPS
        .iter()
        .map(|h| format!("h = {}", sci(*h)))
        .collect();
    let _ = writeln!(
        s,
        "| kernel | scheme | evaluations | {} | best h | best error | time | × analytical |",
        cols.join(" | ")
    );
    let _ = writeln!(
        s,
        "|---|---|---:|{}---:|---:|---:|---:|",
        "---:|".repeat(cols.len())
    );
    let dash = vec!["–".to_string(); TABLE_STEPS.len()];
    for k in &c.kernels {
        let name = k.kernel.as_str();
        let an = k.analytical_ns.median;
        row(
            s,
            [name, "analytical", "1 call"],
            &dash,
            (
                "–".into(),
                format!("{} (vs reference)", sci(k.analytical_error)),
            ),
            (an, an),
        );
        for sc in Scheme::ALL {
            let errs: Vec<String> = TABLE_STEPS
                .iter()
                .map(|h| sci(st.error_at(k, sc, *h)))
                .collect();
            let (bh, be) = st.best(k, sc);
            row(
                s,
                [name, sc.as_str(), &sc.evaluations(c.nv).to_string()],
                &errs,
                (sci(bh), sci(be)),
                (k.ns(sc).median, an),
            );
        }
        row(
            s,
            [
                name,
                "Ridders reference",
                &ridders_evaluations(c.nv).to_string(),
            ],
            &dash,
            (
                "–".into(),
                format!("{} (own estimate)", sci(k.reference_estimate)),
            ),
            (k.reference_ns.median, an),
        );
    }
    let _ = writeln!(s);
}

/// The section (heading, description, table per robot, plots, reading).
pub fn section(s: &mut String, st: &DerivativeStudy) {
    let _ = writeln!(
        s,
        "## 7. Dynamics derivatives: analytical vs finite differences\n"
    );
    let _ = writeln!(
        s,
        "The analytical derivatives (Carpentier & Mansard): `rnea_derivatives` (∂τ/∂q, ∂τ/∂q̇ and M) and \
         `aba_derivatives` (∂q̈/∂q, ∂q̈/∂q̇ and M⁻¹), against difference quotients of the kernels they \
         differentiate: RNEA, and forward dynamics (`forward_dynamics`: ABA, or CRBA + Cholesky on a model \
         with mimic joints{}). **Forward** differences take 2·nv + 1 kernel calls per `nv × 2nv` Jacobian \
         [∂/∂q | ∂/∂q̇], **central** ones 4·nv; the step h is absolute (the inputs are O(1): q uniform in the \
         limits, q̇, q̈ uniform in [−1, 1], τ = RNEA(q, q̇, q̈)) and the divisor is the step actually taken. \
         **Error**: max |J − J_analytical| / max |J_analytical| (max-abs norms) for each block, the larger \
         of the two blocks, the worst of {} random states. **Analytical error**: the analytical Jacobian \
         against a careful reference, Ridders' extrapolation of central differences ({RIDDERS_LEVELS} \
         levels of ratio {RIDDERS_CON} from each of h = {:?}, entry by entry the largest start's estimate unless a \
         smaller start's error estimate is {RIDDERS_SWITCH}× smaller), \
         shown with the reference's own error estimate. **Time**: median per call over interleaved passes \
         (the differences timed at h = ε^½ and ε^⅓; their cost does not depend on h). The analytical call \
         also returns M (M⁻¹), which the differences do not compute, so the ratios favour the differences.\n",
        st.cases
            .iter()
            .filter(|c| c.mimic)
            .map(|c| format!(": the {}", c.name))
            .collect::<String>(),
        st.states,
        RIDDERS_STARTS
    );
    let _ = writeln!(s, "**Complex step.** {COMPLEX_STEP_NOTE}\n");
    for c in &st.cases {
        let _ = writeln!(
            s,
            "**{}** ({} DOF{}).\n",
            c.name,
            c.nv,
            if c.mimic {
                ", mimic joints: forward dynamics by CRBA + Cholesky"
            } else {
                ""
            }
        );
        table(s, st, c);
    }
    let _ = writeln!(
        s,
        "![finite-difference error vs step](derivatives_error.png)\n\n![best error vs time per Jacobian](derivatives_cost.png)\n"
    );
    let _ = writeln!(s, "**Reading.** {}\n", reading(st));
}

/// `a–b` of the finite values (one value when they coincide in print).
fn span(v: impl Iterator<Item = f64>, f: &dyn Fn(f64) -> String) -> String {
    let v: Vec<f64> = v.filter(|x| x.is_finite()).collect();
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if v.is_empty() {
        "–".into()
    } else if f(lo) == f(hi) {
        f(lo)
    } else if lo < 0.0 {
        format!("{} to {}", f(lo), f(hi))
    } else {
        format!("{}–{}", f(lo), f(hi))
    }
}

/// Fitted log-log slopes of the error of `scheme` on the truncation side (steps from
/// 100× the best step up to 1e-2) and on the round-off side (steps below 1/100 of the
/// best one).
pub fn slopes(
    st: &DerivativeStudy,
    k: &KernelResult,
    scheme: Scheme,
) -> (Option<f64>, Option<f64>) {
    let (best, _) = st.best(k, scheme);
    let pts = |keep: &dyn Fn(f64) -> bool| -> Vec<(f64, f64)> {
        st.steps
            .iter()
            .zip(k.errors(scheme))
            .filter(|(h, _)| keep(**h))
            .map(|(h, e)| (*h, *e))
            .collect()
    };
    (
        log_slope(&pts(&|h| h >= 100.0 * best && h <= 1.0001e-2)),
        log_slope(&pts(&|h| h <= best / 100.0)),
    )
}

/// The reading of one kernel across the robots.
fn kernel_reading(st: &DerivativeStudy, ki: usize) -> String {
    let ks: Vec<&KernelResult> = st.cases.iter().map(|c| &c.kernels[ki]).collect();
    let name = Kernel::ALL[ki].as_str();
    let f2 = |x: f64| format!("{x:.1}").replace('-', "−");
    let mut parts = Vec::new();
    for (sc, theory, order) in [
        (Scheme::Forward, f64::EPSILON.sqrt(), "ε^½"),
        (Scheme::Central, f64::EPSILON.cbrt(), "ε^⅓"),
    ] {
        let best: Vec<(f64, f64)> = ks.iter().map(|k| st.best(k, sc)).collect();
        let sl: Vec<(Option<f64>, Option<f64>)> = ks.iter().map(|k| slopes(st, k, sc)).collect();
        let smallest = st.steps.iter().copied().fold(f64::INFINITY, f64::min);
        parts.push(format!(
            "{} differences are most accurate at h = {} ({order} = {}), where they reach {}; the error falls \
             with slope {} on the truncation side and rises with slope {} on the round-off side, to {} at h = {}; \
             one Jacobian costs {}× the analytical call",
            sc.as_str(),
            span(best.iter().map(|b| b.0), &sci),
            sci(theory),
            span(best.iter().map(|b| b.1), &sci),
            span(sl.iter().filter_map(|s| s.0), &f2),
            span(sl.iter().filter_map(|s| s.1), &f2),
            span(ks.iter().map(|k| st.error_at(k, sc, smallest)), &sci),
            sci(smallest),
            span(ks.iter().map(|k| k.ns(sc).median / k.analytical_ns.median), &f2),
        ));
    }
    let floor_gap = ks
        .iter()
        .map(|k| st.best(k, Scheme::Central).1 / k.analytical_error.max(f64::MIN_POSITIVE))
        .fold(f64::INFINITY, f64::min);
    format!(
        "{name}: {}. The analytical Jacobians agree with the Ridders reference to {} (a bound on the two \
         errors together; the reference's own estimate is {}, and it costs {}× the analytical time), so no \
         difference step comes near them: the best central difference is at least {:.0}× further off.",
        parts.join("; "),
        span(ks.iter().map(|k| k.analytical_error), &sci),
        span(ks.iter().map(|k| k.reference_estimate), &sci),
        span(ks.iter().map(|k| k.reference_ns.median / k.analytical_ns.median), &|x| format!("{x:.0}")),
        floor_gap
    )
}

/// The generated reading.
pub fn reading(st: &DerivativeStudy) -> String {
    let mut out = vec![format!(
        "Ranges are over the {} robots. Each error curve is the classic V: truncation error (O(h) forward, \
         O(h²) central: slopes 1 and 2) above the best step, rounding of f divided by h (slope −1) below it.",
        st.cases.len()
    )];
    out.extend((0..Kernel::ALL.len()).map(|ki| kernel_reading(st, ki)));
    let chains: Vec<&DerivativeCase> = st
        .cases
        .iter()
        .filter(|c| c.name.starts_with("chain"))
        .collect();
    if let (Some(a), Some(b)) = (chains.first(), chains.last()) {
        if a.nv >= b.nv {
            return out.join(" ");
        }
        let growth = |f: &dyn Fn(&KernelResult) -> f64| {
            log_slope(
                &chains
                    .iter()
                    .map(|c| (c.nv as f64, f(&c.kernels[0])))
                    .collect::<Vec<_>>(),
            )
            .map_or("–".into(), |x| format!("n^{x:.1}"))
        };
        out.push(format!(
            "From the {}- to the {}-joint chain the RNEA Jacobian's time grows as {} analytically ({} → {}) and {} by \
             central differences ({} → {}).",
            a.nv,
            b.nv,
            growth(&|k| k.analytical_ns.median),
            fmt_ns(a.kernels[0].analytical_ns.median),
            fmt_ns(b.kernels[0].analytical_ns.median),
            growth(&|k| k.central_ns.median),
            fmt_ns(a.kernels[0].central_ns.median),
            fmt_ns(b.kernels[0].central_ns.median),
        ));
    }
    out.join(" ")
}
