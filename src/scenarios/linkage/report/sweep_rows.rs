//! The rows of a mechanism sweep and the context that turns them into the report: the
//! input's key and unit, each state's velocities, accelerations and kinetostatics, a
//! sample's JSON, the extremes over the sweep, and the state at a given input.

use crate::machines::linkage::description::Linkage;
use crate::machines::linkage::fourbar;
use crate::machines::linkage::kinetostatics::{self, Loads};
use crate::machines::linkage::reduced;
use crate::machines::linkage::sweep::{stationary_states, State, Tracker};
use crate::machines::linkage::virtual_power;
use crate::machines::linkage::Vec2;
use crate::scenarios::linkage::linkage_scenario::MechanismScenario;
use nalgebra::DVector;
use serde_json::{json, Map, Value};
use std::f64::consts::TAU;

pub(super) fn v2(v: &Vec2) -> Value {
    json!([v.x, v.y])
}

/// Angle in degrees in `[0, 360)` (values within 1e-9° of 360 read 0).
pub(super) fn deg360(a: f64) -> f64 {
    let d = a.to_degrees().rem_euclid(360.0);
    if 360.0 - d < 1e-9 {
        0.0
    } else {
        d
    }
}

/// Everything computed for one state of a sweep.
pub(super) struct Row {
    pub(super) st: State,
    pub(super) qd: DVector<f64>,
    pub(super) qdd: DVector<f64>,
    pub(super) kin: Option<(kinetostatics::Kinetostatics, Option<f64>)>,
}

/// The moving links' points, each once: `(name, link, local point)`.
pub(super) fn named_points(l: &Linkage) -> Vec<(String, usize, Vec2)> {
    let mut v: Vec<(String, usize, Vec2)> = Vec::new();
    for (i, k) in l.links.iter().enumerate() {
        for (n, p) in &k.points {
            if !v.iter().any(|(m, _, _)| m == n) && !l.ground.iter().any(|(g, _)| g == n) {
                v.push((n.clone(), i, *p));
            }
        }
    }
    v
}

pub(super) fn point_world(l: &Linkage, st: &State, name: &str) -> Vec2 {
    let (b, p) = l.find_point(name).expect("validated point");
    l.point_position(&st.q, b, &p)
}

pub(super) struct ReportCtx<'a> {
    pub(super) m: &'a MechanismScenario,
    pub(super) l: &'a Linkage,
    pub(super) points: Vec<(String, usize, Vec2)>,
}

impl ReportCtx<'_> {
    pub(super) fn input_key(&self) -> &'static str {
        if self.m.angle_input {
            "input_deg"
        } else {
            "input"
        }
    }

    pub(super) fn input(&self, s: f64) -> f64 {
        if self.m.angle_input {
            s.to_degrees()
        } else {
            s
        }
    }

    pub(super) fn unit(&self) -> &'static str {
        if self.m.angle_input {
            "°"
        } else {
            " m"
        }
    }

    pub(super) fn row(&self, st: &State, loads: Option<&Loads>) -> Row {
        let qd = st.qd(self.m.speed);
        let qdd = st.qdd(self.m.speed, self.m.acceleration);
        let kin = loads.map(|ld| {
            let mut k = kinetostatics::solve(self.l, &st.q, &qdd, ld);
            let vp = virtual_power::driving_effort(self.l, &st.q, &qd, &qdd, ld, self.m.speed);
            // At a singular position the multipliers are not determined (the joint forces
            // grow without bound toward it): the driving effort is the virtual-power one,
            // from the limits of the velocities along the branch.
            if let (true, Some(v)) = (st.singular, vp.filter(|v| v.is_finite())) {
                k.driving = v;
            }
            (k, vp)
        });
        Row {
            st: st.clone(),
            qd,
            qdd,
            kin,
        }
    }

    pub(super) fn transmission(&self, st: &State) -> Option<f64> {
        self.m.four_bar.as_ref().map(|fb| {
            let a = point_world(self.l, st, &fb[1]);
            let b = point_world(self.l, st, &fb[2]);
            let c = point_world(self.l, st, &fb[3]);
            fourbar::transmission_angle(&a, &b, &c).to_degrees()
        })
    }

    pub(super) fn sample_json(
        &self,
        r: &Row,
        groups: &[crate::machines::linkage::branch::StructuralGroup],
        dead: &[String],
    ) -> Value {
        let l = self.l;
        let mut pts = Map::new();
        for (n, b, p) in &self.points {
            pts.insert(
                n.clone(),
                json!({
                    "p": v2(&l.point_position(&r.st.q, *b, p)),
                    "v": v2(&l.point_velocity(&r.st.q, &r.qd, *b, p)),
                    "a": v2(&l.point_acceleration(&r.st.q, &r.qd, &r.qdd, *b, p)),
                }),
            );
        }
        let mut links = Map::new();
        for (i, k) in l.links.iter().enumerate() {
            links.insert(
                k.name.clone(),
                json!({
                    "angle_deg": deg360(r.st.q[3 * i + 2]),
                    "omega": r.qd[3 * i + 2],
                    "alpha": r.qdd[3 * i + 2],
                }),
            );
        }
        let mut o = Map::new();
        o.insert(self.input_key().into(), json!(self.input(r.st.s)));
        o.insert("points".into(), Value::Object(pts));
        o.insert("links".into(), Value::Object(links));
        if let Some(mu) = self.transmission(&r.st) {
            o.insert("transmission_angle_deg".into(), json!(mu));
        }
        let mut br = Map::new();
        for (g, x) in groups.iter().zip(&r.st.indicators) {
            br.insert(
                g.name.clone(),
                json!(crate::machines::linkage::branch::sign(*x)),
            );
        }
        o.insert("branch".into(), Value::Object(br));
        o.insert("singular".into(), json!(r.st.singular));
        if r.st.singular {
            o.insert("locked".into(), json!(r.st.locked));
        }
        o.insert(
            "condition".into(),
            if r.st.conditioning.condition.is_finite() {
                json!(r.st.conditioning.condition)
            } else {
                Value::Null
            },
        );
        o.insert("residual".into(), json!(r.st.residual));
        let (jr, djr) = reduced::reduced_inertia(l, &r.st.dq, &r.st.ddq);
        o.insert("reduced_inertia".into(), json!(jr));
        o.insert("reduced_inertia_derivative".into(), json!(djr));
        if let Some(k) = &self.m.kinetostatics {
            o.insert(
                "reduced_moment".into(),
                json!(reduced::reduced_moment(l, &r.st.q, &r.st.dq, &k.loads)),
            );
        }
        o.insert("dead_centre".into(), json!(dead));
        if let Some(c) = crate::scenarios::linkage::contacts_report::state_json(l, &r.st.q, &r.qd) {
            o.insert("contacts".into(), c);
        }
        if let Some((k, vp)) = &r.kin {
            o.insert("driving".into(), json!(k.driving));
            o.insert("driving_virtual_power".into(), json!(vp));
            // At a singular position the joint forces, hence the frame's, are not determined.
            let (f, m) = if r.st.singular {
                (Value::Null, Value::Null)
            } else {
                (v2(&k.shaking_force), json!(k.shaking_moment))
            };
            o.insert("shaking_force".into(), f);
            o.insert("shaking_moment".into(), m);
        }
        Value::Object(o)
    }

    pub(super) fn kinetostatics_json(&self, r: &Row) -> Value {
        let l = self.l;
        let (k, vp) = r.kin.as_ref().expect("kinetostatics computed");
        let forces: Vec<Value> = k
            .joint_forces
            .iter()
            .map(|f| {
                json!({
                    "joint": f.name,
                    "on": l.body_name(f.on),
                    "by": l.body_name(f.by),
                    "force": v2(&f.force),
                    "magnitude": f.force.norm(),
                    "couple": f.couple,
                })
            })
            .collect();
        let mut inertia = Map::new();
        for (i, (f, c)) in k.inertia.iter().enumerate() {
            inertia.insert(
                l.links[i].name.clone(),
                json!({"force": v2(f), "magnitude": f.norm(), "couple": c}),
            );
        }
        if r.st.singular {
            return json!({
                self.input_key(): self.input(r.st.s),
                "singular": true,
                "driving": k.driving,
                "driving_virtual_power": vp,
                "difference": vp.map(|v| v - k.driving),
                "joint_forces": null,
                "inertia_forces": inertia,
                "shaking_force": null,
                "shaking_moment": null,
                "statically_determinate": false,
            });
        }
        let contact_forces =
            crate::scenarios::linkage::contacts_report::forces_json(l, &r.st.q, &r.qd, k, &|_| 0.0);
        let mut out = json!({
            self.input_key(): self.input(r.st.s),
            "singular": false,
            "driving": k.driving,
            "driving_virtual_power": vp,
            "difference": vp.map(|v| v - k.driving),
            "joint_forces": forces,
            "inertia_forces": inertia,
            "shaking_force": v2(&k.shaking_force),
            "shaking_moment": k.shaking_moment,
            "statically_determinate": k.rank == l.nrows(),
        });
        if !contact_forces.is_empty() {
            out["contact_forces"] = Value::Array(contact_forces);
        }
        out
    }
}

/// Min/max of `f` over states, with where.
pub(super) fn extreme(ctx: &ReportCtx, states: &[&State], f: &dyn Fn(&State) -> f64) -> Value {
    let mut lo = (f64::INFINITY, 0.0);
    let mut hi = (f64::NEG_INFINITY, 0.0);
    for st in states {
        let v = f(st);
        if v < lo.0 {
            lo = (v, st.s);
        }
        if v > hi.0 {
            hi = (v, st.s);
        }
    }
    let unit = if ctx.m.angle_input { "_deg" } else { "" };
    let mut o = Map::new();
    o.insert("min".into(), json!(lo.0));
    o.insert(format!("min_at{unit}"), json!(ctx.input(lo.1)));
    o.insert("max".into(), json!(hi.0));
    o.insert(format!("max_at{unit}"), json!(ctx.input(hi.1)));
    Value::Object(o)
}

pub(super) fn extremes_json(ctx: &ReportCtx, tracker: &Tracker, rows: &[Row]) -> Value {
    let l = ctx.l;
    let samples: Vec<State> = rows.iter().map(|r| r.st.clone()).collect();
    let all: Vec<&State> = samples.iter().collect();
    let (sd, sdd) = (ctx.m.speed, ctx.m.acceleration);
    let mut pts = Map::new();
    for (n, b, p) in &ctx.points {
        let (b, p) = (*b, *p);
        let mut o = Map::new();
        for (axis, name) in [(0usize, "x"), (1, "y")] {
            let refined = stationary_states(tracker, &samples, &|st| {
                l.point_velocity(&st.q, &st.dq, b, &p)[axis]
            });
            let mut cand = all.clone();
            cand.extend(refined.iter());
            o.insert(
                name.into(),
                extreme(ctx, &cand, &|st| l.point_position(&st.q, b, &p)[axis]),
            );
        }
        o.insert(
            "speed".into(),
            extreme(ctx, &all, &|st| {
                l.point_velocity(&st.q, &st.qd(sd), b, &p).norm()
            }),
        );
        o.insert(
            "acceleration".into(),
            extreme(ctx, &all, &|st| {
                l.point_acceleration(&st.q, &st.qd(sd), &st.qdd(sd, sdd), b, &p)
                    .norm()
            }),
        );
        pts.insert(n.clone(), Value::Object(o));
    }
    let mut links = Map::new();
    for (i, k) in l.links.iter().enumerate() {
        let mut o = Map::new();
        let th: Vec<f64> = samples.iter().map(|s| s.q[3 * i + 2]).collect();
        let span = th.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
            - th.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        if span >= TAU - 1e-9 {
            o.insert("rotates".into(), json!(true));
        } else {
            let refined = stationary_states(tracker, &samples, &|st| st.dq[3 * i + 2]);
            let mut cand = all.clone();
            cand.extend(refined.iter());
            o.insert(
                "angle_deg".into(),
                extreme(ctx, &cand, &|st| st.q[3 * i + 2].to_degrees()),
            );
        }
        o.insert(
            "omega".into(),
            extreme(ctx, &all, &|st| st.dq[3 * i + 2] * sd),
        );
        o.insert(
            "alpha".into(),
            extreme(ctx, &all, &|st| {
                st.ddq[3 * i + 2] * sd * sd + st.dq[3 * i + 2] * sdd
            }),
        );
        links.insert(k.name.clone(), Value::Object(o));
    }
    let mut out = Map::new();
    out.insert("points".into(), Value::Object(pts));
    out.insert("links".into(), Value::Object(links));
    out.insert(
        "reduced_inertia".into(),
        extreme(ctx, &all, &|st| {
            reduced::reduced_inertia(l, &st.dq, &st.ddq).0
        }),
    );
    if ctx.m.four_bar.is_some() {
        out.insert(
            "transmission_angle_deg".into(),
            extreme(ctx, &all, &|st| ctx.transmission(st).unwrap_or(f64::NAN)),
        );
    }
    if rows.iter().any(|r| r.kin.is_some()) {
        let drive: Vec<(f64, f64)> = rows
            .iter()
            .filter_map(|r| r.kin.as_ref().map(|(k, _)| (r.st.s, k.driving)))
            .collect();
        let (mut lo, mut hi) = ((f64::INFINITY, 0.0), (f64::NEG_INFINITY, 0.0));
        for &(s, d) in &drive {
            if d < lo.0 {
                lo = (d, s);
            }
            if d > hi.0 {
                hi = (d, s);
            }
        }
        out.insert(
            "driving".into(),
            json!({"min": lo.0, "min_at": ctx.input(lo.1), "max": hi.0, "max_at": ctx.input(hi.1)}),
        );
        let sf = rows
            .iter()
            .filter_map(|r| r.kin.as_ref().map(|(k, _)| k.shaking_force.norm()))
            .fold(0.0, f64::max);
        out.insert("shaking_force_max".into(), json!(sf));
    }
    Value::Object(out)
}

/// The state at input `s` on the swept branch (a sample, or solved from the nearest).
pub(super) fn state_at(tracker: &Tracker, samples: &[State], s: f64) -> Option<State> {
    let near = samples
        .iter()
        .min_by(|a, b| (a.s - s).abs().total_cmp(&(b.s - s).abs()))?;
    if (near.s - s).abs() <= 1e-12 * (1.0 + s.abs()) {
        return Some(near.clone());
    }
    tracker.state_near(near, s)
}
