//! The structure and instant-centre parts of a linkage report: the Assur decomposition
//! ([`crate::machines::linkage::assur`]) and every relative instant centre `P_ij` at the
//! inputs asked for ([`crate::machines::instant_centres`]), with link names.

use crate::machines::instant_centres::{all_centres, three_centres_error, RelativeCentre};
use crate::machines::linkage::assur::decompose;
use crate::machines::linkage::description::Linkage;
use crate::machines::linkage::sweep::State;
use serde_json::{json, Map, Value};
use std::fmt::Write;

/// `"structure"`: the initial mechanism, the Assur groups and the class.
pub(super) fn structure_json(l: &Linkage, json: &mut Map<String, Value>, text: &mut String) {
    let s = decompose(l);
    let names = |v: &[usize]| v.iter().map(|&b| s.bodies[b].clone()).collect::<Vec<_>>();
    let pair_names = |v: &[usize]| {
        v.iter()
            .map(|&k| s.pairs[k].name.clone())
            .collect::<Vec<_>>()
    };
    let groups: Vec<Value> = s
        .groups
        .iter()
        .map(|g| {
            json!({
                "links": names(&g.links),
                "internal_pairs": pair_names(&g.internal),
                "external_pairs": pair_names(&g.external),
                "class": g.class,
                "order": g.order,
                "kind": g.kind.as_ref().map(|k| k.0.clone()),
                "kind_number": g.kind.as_ref().map(|k| k.1),
            })
        })
        .collect();
    let _ = writeln!(
        text,
        "structure: class {} mechanism; {}",
        s.class,
        s.groups
            .iter()
            .map(|g| format!(
                "group {} (class {}, order {}{})",
                names(&g.links).join("+"),
                g.class,
                g.order,
                g.kind
                    .as_ref()
                    .map(|k| format!(", {} kind {}", k.0, k.1))
                    .unwrap_or_default()
            ))
            .collect::<Vec<_>>()
            .join("; ")
    );
    let mut out = json!({
        "initial": s.initial.map(|(b, p)| json!({"link": s.bodies[b], "pair": s.pairs[p].name})),
        "groups": groups,
        "unassigned": names(&s.unassigned),
        "class": s.class,
    });
    if let Value::Object(o) = &mut out {
        crate::scenarios::linkage::contacts_report::structure_json(&s, o);
    }
    json.insert("structure".into(), out);
}

/// One state's relative centres as JSON, and the Aronhold–Kennedy collinearity error.
pub(super) fn centres_at(l: &Linkage, st: &State, sd: f64) -> (Vec<Value>, f64) {
    let c = all_centres(l, &st.q, &st.dq);
    let err = three_centres_error(&c);
    let v = c
        .iter()
        .map(|(i, j, p)| {
            let (point, dir) = match p {
                RelativeCentre::Point(p) => (json!([p.x, p.y]), Value::Null),
                RelativeCentre::AtInfinity(d) => (Value::Null, json!([d.x, d.y])),
                RelativeCentre::Undefined => (Value::Null, Value::Null),
            };
            let (bi, bj) = (l.body_name(*i), l.body_name(*j));
            let rate = |b: usize| {
                if b == crate::machines::linkage::GROUND {
                    0.0
                } else {
                    st.dq[3 * b + 2]
                }
            };
            json!({
                "links": [bi, bj],
                "label": format!("P({bi},{bj})"),
                "point": point,
                "direction_at_infinity": dir,
                "relative_omega": (rate(*i) - rate(*j)) * sd,
            })
        })
        .collect();
    (v, err)
}
