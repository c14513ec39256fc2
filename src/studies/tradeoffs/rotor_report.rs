//! Study 6's part of the trade-offs report: the table of critical-speed errors and solve
//! times against the element count, its plot (`rotor_error.png`) and the generated
//! reading (the fitted convergence order and the elements each mode needs for 0.1 %).

use crate::io::plots::panels::{render_panels, Legend, Panel, Series, PALETTE};
use crate::io::plots::plot_error::PlotError;
use crate::io::report::fmt_ns;
use crate::studies::tradeoffs::rotor_study::{RotorCase, RotorStudy, MODES};
use std::fmt::Write as _;

/// `rotor_error.png`: relative error against elements per mode (solid), per rotor.
pub fn png(st: &RotorStudy) -> Result<Vec<u8>, PlotError> {
    let panels: Vec<Panel> = st
        .cases
        .iter()
        .map(|c| Panel {
            title: format!("{} (reference: {})", c.name, c.reference_method),
            x_desc: "finite elements".into(),
            y_desc: "relative error of ω_cr".into(),
            log_x: true,
            log_y: true,
            series: (0..MODES)
                .map(|k| Series {
                    label: format!("mode {}", k + 1),
                    points: c
                        .rows
                        .iter()
                        .map(|r| (r.nodes as f64 - 1.0, r.relative_error[k]))
                        .collect(),
                    color: PALETTE[k],
                    dashed: false,
                })
                .collect(),
            legend: Legend::LowerLeft,
            ..Default::default()
        })
        .collect();
    render_panels(
        "Flexible rotor: critical-speed error vs finite elements",
        &panels,
        2,
        (700, 520),
    )
}

/// The fewest elements (as used) with every error of mode `k` from there on below `goal`.
pub fn elements_for(c: &RotorCase, k: usize, goal: f64) -> Option<usize> {
    let i = c
        .rows
        .iter()
        .rposition(|r| r.relative_error[k] >= goal)
        .map_or(0, |i| i + 1);
    c.rows.get(i).map(|r| r.nodes - 1)
}

/// The section (heading, table per rotor, plot, reading).
pub fn section(s: &mut String, st: &RotorStudy) {
    let _ = writeln!(s, "## 6. Flexible rotor: elements × critical-speed error\n");
    let _ = writeln!(
        s,
        "`fe_modes` (Hermite cubic beam elements, consistent mass, Cholesky + symmetric eigen-solver) for the \
         lowest {MODES} critical speeds against references that need no elements: the closed form on the uniform \
         pinned shaft of docs/reference_data.md FX-3, the exact transfer matrices on a stepped rotor with two \
         discs, an elastic and a rigid bearing. Elements as used (the rotor's stations add some); time of \
         one eigen-solve, median over rounds.\n"
    );
    for c in &st.cases {
        let refs: Vec<String> = c.reference.iter().map(|w| format!("{w:.3}")).collect();
        let _ = writeln!(
            s,
            "**{}**: reference ω = {} rad/s ({}).\n",
            c.name,
            refs.join(", "),
            c.reference_method
        );
        let _ = writeln!(
            s,
            "| elements | mode 1 error | mode 2 error | mode 3 error | solve | p99 |"
        );
        let _ = writeln!(s, "|---:|---:|---:|---:|---:|---:|");
        for r in &c.rows {
            let e: Vec<String> = r
                .relative_error
                .iter()
                .map(|x| format!("{x:.2e}"))
                .collect();
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} |",
                r.nodes - 1,
                e[0],
                e[1],
                e[2],
                fmt_ns(r.solve_ns.median),
                fmt_ns(r.solve_ns.p99)
            );
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s, "![critical-speed error vs elements](rotor_error.png)\n");
    let _ = writeln!(s, "**Reading.** {}\n", reading(st));
}

/// The generated reading.
pub fn reading(st: &RotorStudy) -> String {
    let mut parts = Vec::new();
    for c in &st.cases {
        let slopes: Vec<String> = c
            .slope
            .iter()
            .map(|x| x.map_or("–".into(), |v| format!("{v:.1}")))
            .collect();
        let need: Vec<String> = (0..MODES)
            .map(|k| {
                elements_for(c, k, 1e-3).map_or("more than the study ran".into(), |n| n.to_string())
            })
            .collect();
        let (first, last) = (c.rows.first(), c.rows.last());
        let cost = match (first, last) {
            (Some(a), Some(b)) => format!(
                "; one solve takes {} at {} elements and {} at {}",
                fmt_ns(a.solve_ns.median),
                a.nodes - 1,
                fmt_ns(b.solve_ns.median),
                b.nodes - 1
            ),
            _ => String::new(),
        };
        parts.push(format!(
            "on the {} the error falls with the element count at fitted slopes {} (modes 1–3; Hermite elements \
             converge as h⁴, slope −4, steeper before the asymptotic range); 0.1 % needs {} elements for modes \
             1, 2, 3{cost}",
            c.name,
            slopes.join(", "),
            need.join(", ")
        ));
    }
    let mut text = parts.join("; ");
    if let Some(c) = text.get(..1) {
        text = c.to_uppercase() + &text[1..];
    }
    format!(
        "{text}. Each higher mode has a shorter wavelength and needs more elements for the same error, while \
         the solve's cost grows faster than the node count: size the mesh for the highest mode of interest; a \
         finer one buys nothing the references can see."
    )
}
