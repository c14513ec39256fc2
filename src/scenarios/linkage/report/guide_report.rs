//! `"guide_contacts"` of a kinetostatics report point: each prismatic guide that bears at
//! two points (`[[sliders]] contacts`), its reaction as the two normal forces `N_a`, `N_b`
//! ([`crate::machines::friction::two_point_guide::split`]).

use crate::machines::friction::two_point_guide::{split, GuideReaction, TwoPointGuide};
use crate::machines::linkage::description::Linkage;
use crate::machines::linkage::kinetostatics::Kinetostatics;
use crate::scenarios::linkage::report::sweep_rows::v2;
use nalgebra::DVector;
use serde_json::{json, Value};
use std::fmt::Write;

/// One reaction's JSON: the joint, the points, `N_a`, `N_b` and the two forces.
pub(super) fn reaction_json(l: &Linkage, r: &GuideReaction) -> Value {
    json!({
        "joint": l.joints[r.joint].name(),
        "points": [v2(&r.points[0]), v2(&r.points[1])],
        "normal": v2(&r.normal),
        "normal_forces": r.forces,
        "forces": [v2(&(r.normal * r.forces[0])), v2(&(r.normal * r.forces[1]))],
    })
}

/// The guides' two-point reactions from `k` at `q`, with one text line each.
pub(super) fn guides_json(
    l: &Linkage,
    q: &DVector<f64>,
    k: &Kinetostatics,
    guides: &[TwoPointGuide],
    text: &mut String,
) -> Value {
    let mut out = Vec::new();
    for g in guides {
        let Some(r) = split(l, q, k, g) else { continue };
        if !(r.forces[0].is_finite() && r.forces[1].is_finite()) {
            continue;
        }
        let _ = writeln!(
            text,
            "  guide {} bearing at ({:.6}, {:.6}) and ({:.6}, {:.6}): N_a = {:.6} N, N_b = {:.6} N (along the normal ({:.4}, {:.4}))",
            l.joints[r.joint].name(),
            r.points[0].x,
            r.points[0].y,
            r.points[1].x,
            r.points[1].y,
            r.forces[0],
            r.forces[1],
            r.normal.x,
            r.normal.y
        );
        out.push(reaction_json(l, &r));
    }
    Value::Array(out)
}
