//! The cam-contact parts of a linkage report ([`crate::machines::linkage::higher_pair`]):
//! each contact's point, common normal and sliding velocity at a state; its force (normal
//! force `N` along the common normal, with friction `f |N|` along the tangent against the
//! sliding, so the total leans by `atan f`); and the structure's higher pairs replaced by
//! lower pairs.

use crate::machines::linkage::assur::Structure;
use crate::machines::linkage::contact_rows;
use crate::machines::linkage::description::{Linkage, PlanarJoint};
use crate::machines::linkage::higher_pair::HigherPair;
use crate::machines::linkage::kinetostatics::Kinetostatics;
use crate::machines::linkage::{perp, Vec2};
use nalgebra::DVector;
use serde_json::{json, Map, Value};

fn v2(v: &Vec2) -> Value {
    json!([v.x, v.y])
}

/// The contacts of `l` with their joint index.
fn contacts(l: &Linkage) -> impl Iterator<Item = (usize, &HigherPair)> {
    l.joints.iter().enumerate().filter_map(|(k, j)| match j {
        PlanarJoint::Contact(c) => Some((k, c)),
        _ => None,
    })
}

/// `"contacts"` of a sweep row: `{name: {"point", "normal", "sliding_velocity"}}`, `None`
/// without contacts.
pub(crate) fn state_json(l: &Linkage, q: &DVector<f64>, qd: &DVector<f64>) -> Option<Value> {
    let mut m = Map::new();
    for (_, c) in contacts(l) {
        let g = contact_rows::geometry(l, q, c);
        m.insert(
            c.name.clone(),
            json!({
                "point": v2(&g.point),
                "normal": v2(&g.normal),
                "sliding_velocity": contact_rows::sliding_velocity(l, q, qd, c),
            }),
        );
    }
    (!m.is_empty()).then_some(Value::Object(m))
}

/// `"contact_forces"` of a kinetostatic solution `k`: for each contact the force on `a`
/// (the body with the circle) by `b`: the normal force `N = λ` (`> 0` presses the
/// profiles together; `"separates"` when negative), with `coefficient(c)` the friction
/// force `−sgn(u) f |N| perp(ν)` against the sliding velocity `u`, the total force, its
/// magnitude and the contact point.
pub(crate) fn forces_json(
    l: &Linkage,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    k: &Kinetostatics,
    coefficient: &dyn Fn(&HigherPair) -> f64,
) -> Vec<Value> {
    contacts(l)
        .filter_map(|(j, c)| {
            let jf = k.joint_forces.iter().find(|f| f.joint == j)?;
            let g = contact_rows::geometry(l, q, c);
            let n = g.normal.dot(&jf.force) * if jf.on == c.a { 1.0 } else { -1.0 };
            let u = contact_rows::sliding_velocity(l, q, qd, c);
            let f = coefficient(c);
            let friction = if u == 0.0 {
                Vec2::zeros()
            } else {
                perp(&g.normal) * (-u.signum() * f * n.abs())
            };
            let total = g.normal * n + friction;
            Some(json!({
                "contact": c.name,
                "on": l.body_name(c.a),
                "by": l.body_name(c.b),
                "normal_force": n,
                "normal": v2(&g.normal),
                "friction_force": v2(&friction),
                "force": v2(&total),
                "magnitude": total.norm(),
                "point": v2(&g.point),
                "sliding_velocity": u,
                "separates": n < 0.0,
            }))
        })
        .collect()
}

/// The structure's `"p4"` and `"higher_pairs"`: each contact, its replacing link, the two
/// lower pairs (name, kind R/P, bodies) and the link's length.
pub(crate) fn structure_json(s: &Structure, out: &mut Map<String, Value>) {
    let pair = |k: usize| {
        let p = &s.pairs[k];
        json!({"name": p.name, "kind": p.kind.to_string(),
               "bodies": [s.bodies[p.bodies.0], s.bodies[p.bodies.1]]})
    };
    let hp: Vec<Value> = s
        .higher_pairs
        .iter()
        .map(|r| {
            json!({
                "contact": r.contact,
                "link": s.bodies[r.link],
                "pairs": [pair(r.pairs[0]), pair(r.pairs[1])],
                "length": r.length,
            })
        })
        .collect();
    out.insert("p4".into(), json!(hp.len()));
    out.insert("higher_pairs".into(), Value::Array(hp));
}
