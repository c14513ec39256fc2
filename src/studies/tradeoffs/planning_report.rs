//! Study 8's part of the report ([`super::planning_study`]): the table of planning time
//! against path cost per planner and budget, the cost-against-time plot beside VAMP's
//! recorded figures, and a reading generated from the numbers.

use crate::io::plots::panels::{render_panels, Legend, Panel, Series, PALETTE};
use crate::io::plots::plot_error::PlotError;
use crate::studies::tradeoffs::planning_study::{PlanningRow, PlanningStudy, VampRecord};
use std::fmt::Write as _;

/// File name of the plot.
pub const PNG: &str = "planning_cost_time.png";

/// The Markdown section.
pub fn section(s: &mut String, st: &PlanningStudy) {
    let _ = writeln!(s, "## 8. Planning: path cost vs planning time\n");
    let _ = writeln!(
        s,
        "The first {} MotionBenchMaker `table_pick` problems of the spherized Panda and UR5 (bundled, \
         `assets/planning/mbm/`), {} seed(s) each, one thread. **RRT-Connect**: the first path, simplified. \
         **AORRTC**: the optimising mode (`armsim plan --planner aorrtc --budget-iterations B`), which keeps \
         searching for cheaper paths in the informed set until B iterations are spent. Time is planning plus \
         simplification of the solved queries (median and 95th percentile, nearest rank); cost is the median \
         joint-space length. **VAMP** cannot run inside armsim: its columns are the figures \
         `tools/planning_tradeoff_vamp.sh` recorded on the whole `table_pick` scene ({}), with armsim's of \
         that same run beside them, so their ratio is a same-machine ratio (its problems include the \
         bundled ones, so its medians differ from this run's).\n",
        st.robots.first().map_or(0, |r| r.problems.len()),
        st.seeds,
        st.vamp.first().map_or("no record", |v| v.measured.as_str()),
    );
    let _ = writeln!(
        s,
        "| robot | planner | budget | solved | time median | p95 | cost median | VAMP solved | VAMP time median | VAMP p95 | VAMP cost | recorded armsim / VAMP time | recorded armsim / VAMP cost |"
    );
    let _ = writeln!(
        s,
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for rb in &st.robots {
        for row in &rb.rows {
            let v = vamp_for(st, &rb.robot, row);
            let (vs, vt, vp, vc, rt, rc) = match v {
                Some(v) => (
                    format!("{}/{}", v.solved[0], v.valid),
                    us(v.vamp[0]),
                    us(v.vamp[1]),
                    format!("{:.3}", v.vamp[2]),
                    format!("{:.2}", v.armsim[0] / v.vamp[0]),
                    format!("{:.3}", v.armsim[2] / v.vamp[2]),
                ),
                None => Default::default(),
            };
            let _ = writeln!(
                s,
                "| {} | {} | {} | {}/{} | {} | {} | {:.3} | {vs} | {vt} | {vp} | {vc} | {rt} | {rc} |",
                rb.robot,
                row.planner,
                row.budget.map_or("–".into(), |b| b.to_string()),
                row.solved,
                row.queries,
                us(row.time_median_us),
                us(row.time_p95_us),
                row.cost_median,
            );
        }
    }
    let _ = writeln!(
        s,
        "\n![path cost against planning time](planning_cost_time.png)\n"
    );
    let _ = writeln!(s, "**Reading.** {}\n", reading(st));
}

/// `1234 µs` or `12.3 ms`.
fn us(x: f64) -> String {
    if !x.is_finite() {
        "–".into()
    } else if x >= 1e4 {
        format!("{:.1} ms", x * 1e-3)
    } else {
        format!("{x:.0} µs")
    }
}

/// VAMP's recorded line for this row (RRT-Connect is budget 0).
fn vamp_for<'a>(st: &'a PlanningStudy, robot: &str, row: &PlanningRow) -> Option<&'a VampRecord> {
    let (planner, budget) = match row.budget {
        Some(b) => ("aorrtc", b),
        None => ("rrtc", 0),
    };
    st.vamp
        .iter()
        .find(|v| v.robot == robot && v.planner == planner && v.budget == budget)
}

/// The generated reading.
pub fn reading(st: &PlanningStudy) -> String {
    let mut out = Vec::new();
    for rb in &st.robots {
        let (Some(first), Some(last)) = (rb.rows.first(), rb.rows.last()) else {
            continue;
        };
        if first.cost_median.is_finite() && last.cost_median.is_finite() && last.budget.is_some() {
            out.push(format!(
                "On the {}, {} iterations of AORRTC bring the median cost from {:.3} (RRT-Connect, {}) to {:.3} \
                 ({:.1} % shorter) at a median of {}.",
                rb.robot,
                last.budget.unwrap_or(0),
                first.cost_median,
                us(first.time_median_us),
                last.cost_median,
                100.0 * (1.0 - last.cost_median / first.cost_median),
                us(last.time_median_us)
            ));
        }
        let rec: Vec<&VampRecord> = st.vamp.iter().filter(|v| v.robot == rb.robot).collect();
        let ratio = |v: &&VampRecord, k: usize| v.armsim[k] / v.vamp[k];
        let optimising: Vec<&&VampRecord> = rec.iter().filter(|v| v.planner == "aorrtc").collect();
        let span = |k: usize| {
            let r = optimising.iter().map(|v| ratio(v, k));
            (
                r.clone().fold(f64::INFINITY, f64::min),
                r.fold(0.0, f64::max),
            )
        };
        if let (Some(first), false) = (
            rec.iter().find(|v| v.planner == "rrtc"),
            optimising.is_empty(),
        ) {
            let ((tlo, thi), (clo, chi)) = (span(0), span(2));
            out.push(format!(
                "In the recorded side-by-side run ({} problems, one seed), armsim's RRT-Connect took \
                 {:.2}× VAMP's median time; at the same AORRTC budgets armsim took {tlo:.2}–{thi:.2}× VAMP's \
                 median time for {clo:.3}–{chi:.3}× its median cost.",
                first.valid,
                ratio(first, 0)
            ));
        }
    }
    if out.is_empty() {
        "No planning figures.".into()
    } else {
        out.join(" ")
    }
}

/// Cost against time, one panel per robot: this run's RRT-Connect and AORRTC, and the
/// recorded VAMP and armsim figures of the side-by-side run.
pub fn png(st: &PlanningStudy) -> Result<Vec<u8>, PlotError> {
    let panels: Vec<Panel> = st.robots.iter().map(|rb| panel(st, rb)).collect();
    render_panels(
        "Path cost vs planning time: RRT-Connect, then AORRTC at growing iteration budgets",
        &panels,
        panels.len().max(1),
        (760, 560),
    )
}

fn panel(
    st: &PlanningStudy,
    rb: &crate::studies::tradeoffs::planning_study::RobotPlanning,
) -> Panel {
    let live: Vec<(f64, f64)> = rb
        .rows
        .iter()
        .filter(|r| r.time_median_us.is_finite() && r.cost_median.is_finite())
        .map(|r| (r.time_median_us, r.cost_median))
        .collect();
    let recorded = |pick: &dyn Fn(&VampRecord) -> (f64, f64)| -> Vec<(f64, f64)> {
        let mut v: Vec<&VampRecord> = st.vamp.iter().filter(|v| v.robot == rb.robot).collect();
        v.sort_by_key(|v| v.budget);
        v.into_iter().map(pick).collect()
    };
    let highest = |pts: &[(f64, f64)]| pts.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    let vamp_top = highest(&recorded(&|v| (v.vamp[0], v.vamp[2])));
    let top_is_live = highest(&live) >= vamp_top;
    Panel {
        title: format!("{} (table_pick, {} problems)", rb.robot, rb.problems.len()),
        x_desc: "median planning + simplification time (µs)".into(),
        y_desc: "median path cost (joint-space length)".into(),
        log_x: true,
        series: vec![
            Series {
                label: "armsim, this run: bundled problems × seeds (first point RRT-Connect)"
                    .into(),
                points: live,
                color: PALETTE[0],
                dashed: false,
            },
            Series {
                label: "VAMP, recorded on the whole scene (first point RRT-Connect)".into(),
                points: recorded(&|v| (v.vamp[0], v.vamp[2])),
                color: PALETTE[1],
                dashed: false,
            },
            Series {
                label: "armsim, recorded beside VAMP on the whole scene".into(),
                points: recorded(&|v| (v.armsim[0], v.armsim[2])),
                color: PALETTE[0],
                dashed: true,
            },
        ],
        // The legend goes where the lines are not: low when this run's first point (its
        // highest) tops the panel.
        legend: if top_is_live {
            Legend::LowerLeft
        } else {
            Legend::UpperRight
        },
        ..Default::default()
    }
}
