//! `"change_points"` of a linkage report: where the sweep passed a change point (two
//! assembly branches crossing) and which branch it went on. The rule is the smooth motion
//! (the analytic continuation through the point, [`crate::machines::linkage::continuation`]):
//! each group's sign before and after is listed, and for a four-bar with parallelogram
//! lengths (input = output, ground = coupler) whether it is the parallelogram or the
//! antiparallelogram after the point.

use crate::machines::linkage::continuation::{branch_crossings, BranchCrossing};
use crate::machines::linkage::sweep::{State, Sweep};
use crate::scenarios::linkage::report::sweep_rows::{point_world, ReportCtx};
use serde_json::{json, Map, Value};
use std::fmt::Write;

/// For a four-bar `[O, A, B, C]` with parallelogram lengths: `"parallelogram"` where
/// `A − O = B − C` (the input and output links parallel and alike), else
/// `"antiparallelogram"`; `None` for other lengths.
fn parallelogram_branch(ctx: &ReportCtx, st: &State) -> Option<&'static str> {
    let fb = ctx.m.four_bar.as_ref()?;
    let p: Vec<_> = fb.iter().map(|n| point_world(ctx.l, st, n)).collect();
    let (g, a, b, c) = (
        (p[3] - p[0]).norm(),
        (p[1] - p[0]).norm(),
        (p[2] - p[1]).norm(),
        (p[2] - p[3]).norm(),
    );
    let tol = 1e-9 * g.max(a).max(b).max(c);
    if (a - c).abs() > tol || (g - b).abs() > tol {
        return None;
    }
    let off = ((p[1] - p[0]) - (p[2] - p[3])).norm();
    Some(if off <= 1e-6 * a {
        "parallelogram"
    } else {
        "antiparallelogram"
    })
}

/// Inserts `"change_points"` and writes one summary line per crossing; returns them.
pub(super) fn change_points_json(
    ctx: &ReportCtx,
    sw: &Sweep,
    passed: &[f64],
    periodic: bool,
    json: &mut Map<String, Value>,
    text: &mut String,
) -> Vec<BranchCrossing> {
    let crossings = branch_crossings(sw, passed, periodic);
    let mut out = Vec::new();
    for c in &crossings {
        let signs = |v: &[i8]| -> Map<String, Value> {
            sw.groups
                .iter()
                .zip(v)
                .map(|(g, s)| (g.name.clone(), json!(s)))
                .collect()
        };
        let after = &sw.samples[c.after];
        let label = parallelogram_branch(ctx, after);
        let mut o = Map::new();
        o.insert(ctx.input_key().into(), json!(ctx.input(c.at)));
        o.insert("signs_before".into(), Value::Object(signs(&c.signs.0)));
        o.insert("signs_after".into(), Value::Object(signs(&c.signs.1)));
        o.insert("rule".into(), json!("smooth"));
        o.insert("restarted".into(), json!(c.restarted));
        if let Some(b) = label {
            o.insert("four_bar_branch".into(), json!(b));
            let before = parallelogram_branch(ctx, &sw.samples[c.before]);
            o.insert("four_bar_branch_before".into(), json!(before));
        }
        out.push(Value::Object(o));
        let flips: Vec<String> = sw
            .groups
            .iter()
            .enumerate()
            .filter(|(i, _)| c.signs.0[*i] != c.signs.1[*i])
            .map(|(i, g)| format!("{} {:+} → {:+}", g.name, c.signs.0[i], c.signs.1[i]))
            .collect();
        let _ = writeln!(
            text,
            "change point at input {:.4}{}: branches cross ({}); continued on the smooth motion{}",
            ctx.input(c.at),
            ctx.unit(),
            flips.join(", "),
            label.map_or(String::new(), |b| format!(": the {b} after it"))
        );
    }
    json.insert("change_points".into(), Value::Array(out));
    crossings
}
