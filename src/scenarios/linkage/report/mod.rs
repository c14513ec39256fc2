//! Runs the analyses a linkage scenario asks for and writes the report: the JSON document
//! of `armsim run --json` and the text summary. The keys are listed in
//! `docs/mechanism.md`.

mod sweep_report;

use crate::io::report::Report;
use crate::machines::balancing::{self, add_point_mass, SliderCrankMasses};
use crate::machines::flywheel;
use crate::machines::flywheel::machine_motion;
use crate::machines::linkage::description::{Linkage, PlanarJoint, GROUND};
use crate::machines::linkage::fourbar;
use crate::machines::linkage::kinetostatics::{self, Loads};
use crate::machines::linkage::sweep::{stationary_states, State, Tracker};
use crate::machines::linkage::virtual_power;
use crate::machines::linkage::Vec2;
use crate::scenarios::linkage::report::sweep_report::mechanism;
use crate::scenarios::linkage::{
    LinkageScenario, MachineScenario, MechanismScenario, RotorScenario,
};
use nalgebra::DVector;
use serde_json::{json, Map, Value};
use std::f64::consts::TAU;
use std::fmt::Write;

fn v2(v: &Vec2) -> Value {
    json!([v.x, v.y])
}

/// Angle in degrees in `[0, 360)` (values within 1e-9° of 360 read 0).
fn deg360(a: f64) -> f64 {
    let d = a.to_degrees().rem_euclid(360.0);
    if 360.0 - d < 1e-9 {
        0.0
    } else {
        d
    }
}

/// Everything computed for one state of a sweep.
struct Row {
    st: State,
    qd: DVector<f64>,
    qdd: DVector<f64>,
    kin: Option<(kinetostatics::Kinetostatics, Option<f64>)>,
}

/// The moving links' points, each once: `(name, link, local point)`.
fn named_points(l: &Linkage) -> Vec<(String, usize, Vec2)> {
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

fn point_world(l: &Linkage, st: &State, name: &str) -> Vec2 {
    let (b, p) = l.find_point(name).expect("validated point");
    l.point_position(&st.q, b, &p)
}

struct ReportCtx<'a> {
    m: &'a MechanismScenario,
    l: &'a Linkage,
    points: Vec<(String, usize, Vec2)>,
}

impl ReportCtx<'_> {
    fn input_key(&self) -> &'static str {
        if self.m.angle_input {
            "input_deg"
        } else {
            "input"
        }
    }

    fn input(&self, s: f64) -> f64 {
        if self.m.angle_input {
            s.to_degrees()
        } else {
            s
        }
    }

    fn unit(&self) -> &'static str {
        if self.m.angle_input {
            "°"
        } else {
            " m"
        }
    }

    fn row(&self, st: &State, loads: Option<&Loads>) -> Row {
        let qd = st.qd(self.m.speed);
        let qdd = st.qdd(self.m.speed, self.m.acceleration);
        let kin = loads.map(|ld| {
            let k = kinetostatics::solve(self.l, &st.q, &qdd, ld);
            let vp = virtual_power::driving_effort(self.l, &st.q, &qd, &qdd, ld, self.m.speed);
            (k, vp)
        });
        Row {
            st: st.clone(),
            qd,
            qdd,
            kin,
        }
    }

    fn transmission(&self, st: &State) -> Option<f64> {
        self.m.four_bar.as_ref().map(|fb| {
            let a = point_world(self.l, st, &fb[1]);
            let b = point_world(self.l, st, &fb[2]);
            let c = point_world(self.l, st, &fb[3]);
            fourbar::transmission_angle(&a, &b, &c).to_degrees()
        })
    }

    fn sample_json(
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
        o.insert("dead_centre".into(), json!(dead));
        if let Some((k, vp)) = &r.kin {
            o.insert("driving".into(), json!(k.driving));
            o.insert("driving_virtual_power".into(), json!(vp));
            o.insert("shaking_force".into(), v2(&k.shaking_force));
            o.insert("shaking_moment".into(), json!(k.shaking_moment));
        }
        Value::Object(o)
    }

    fn kinetostatics_json(&self, r: &Row) -> Value {
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
        json!({
            self.input_key(): self.input(r.st.s),
            "driving": k.driving,
            "driving_virtual_power": vp,
            "difference": vp.map(|v| v - k.driving),
            "joint_forces": forces,
            "inertia_forces": inertia,
            "shaking_force": v2(&k.shaking_force),
            "shaking_moment": k.shaking_moment,
            "statically_determinate": k.rank == l.nrows(),
        })
    }
}

/// Min/max of `f` over states, with where.
fn extreme(ctx: &ReportCtx, states: &[&State], f: &dyn Fn(&State) -> f64) -> Value {
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

fn extremes_json(ctx: &ReportCtx, tracker: &Tracker, rows: &[Row]) -> Value {
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
fn state_at(tracker: &Tracker, samples: &[State], s: f64) -> Option<State> {
    let near = samples
        .iter()
        .min_by(|a, b| (a.s - s).abs().total_cmp(&(b.s - s).abs()))?;
    if (near.s - s).abs() <= 1e-12 * (1.0 + s.abs()) {
        return Some(near.clone());
    }
    tracker.state_near(near, s)
}

fn counterweight(
    m: &MechanismScenario,
    ctx: &ReportCtx,
    cw: &crate::scenarios::linkage::CounterweightScenario,
    rows: &[Row],
    json: &mut Map<String, Value>,
    text: &mut String,
) {
    let l = ctx.l;
    let crank = &l.links[cw.crank];
    let rod = &l.links[cw.rod];
    // The crank's ground pivot, the crank pin (crank–rod) and the piston pin (rod–slider).
    let pin = |a: usize, b: usize| {
        l.joints.iter().find_map(|j| match j {
            PlanarJoint::Revolute {
                a: x, pa, b: y, pb, ..
            } if (*x == a && *y == b) => Some((*pa, *pb)),
            PlanarJoint::Revolute {
                a: x, pa, b: y, pb, ..
            } if (*x == b && *y == a) => Some((*pb, *pa)),
            _ => None,
        })
    };
    let (Some((pivot, _)), Some((crank_pin, rod_b)), Some((rod_c, _))) = (
        pin(cw.crank, GROUND),
        pin(cw.crank, cw.rod),
        pin(cw.rod, cw.slider),
    ) else {
        json.insert("counterweight".into(), json!({"error": "counterweight: the crank, rod and slider must be pinned ground–crank–rod–slider"}));
        return;
    };
    let r = (crank_pin - pivot).norm();
    let u = (crank_pin - pivot) / r;
    let rod_len = (rod_c - rod_b).norm();
    let masses = SliderCrankMasses {
        crank_radius: r,
        crank_mass: crank.mass,
        crank_com: (crank.com - pivot).dot(&u),
        rod_length: rod_len,
        rod_mass: rod.mass,
        rod_com: (rod.com - rod_b).dot(&((rod_c - rod_b) / rod_len)),
        slider_mass: l.links[cw.slider].mass,
    };
    let c = balancing::slider_crank_counterweight(&masses, cw.fraction, cw.radius);
    let mut balanced = l.clone();
    add_point_mass(&mut balanced.links[cw.crank], c.mass, pivot - u * cw.radius);
    let loads = Loads {
        gravity: Vec2::zeros(),
        ..Default::default()
    };
    let (sd, sdd) = (m.speed, m.acceleration);
    let mut before: f64 = 0.0;
    let mut after: f64 = 0.0;
    let mut formula_dev: f64 = 0.0;
    let mut series = Vec::new();
    for row in rows {
        let st = &row.st;
        let f0 = kinetostatics::solve(l, &st.q, &row.qdd, &loads).shaking_force;
        let (q1, _, qdd1) = l.transfer_motion(&balanced, &st.q, &row.qd, &row.qdd);
        let f1 = kinetostatics::solve(&balanced, &q1, &qdd1, &loads).shaking_force;
        before = before.max(f0.norm());
        after = after.max(f1.norm());
        // Exact residual with the two-mass rod: −m_rec a_C − k m_rec r ω² (cos φ, sin φ).
        let a_c = l.point_acceleration(&st.q, &row.qd, &row.qdd, cw.rod, &rod_c);
        let phi = st.q[3 * cw.crank + 2];
        let dir = crate::machines::linkage::rotate(phi, &u.clone());
        let formula =
            -a_c * c.reciprocating_mass - dir * (cw.fraction * c.reciprocating_mass * r * sd * sd);
        if sdd == 0.0 {
            formula_dev = formula_dev.max((formula - f1).norm());
        }
        series.push(json!({ctx.input_key(): ctx.input(st.s), "before": v2(&f0), "after": v2(&f1)}));
    }
    json.insert(
        "counterweight".into(),
        json!({
            "masses": masses,
            "counterweight": c,
            "position_on_crank": v2(&(pivot - u * cw.radius)),
            "max_shaking_force_before": before,
            "max_shaking_force_after": after,
            "primary_reciprocating_amplitude": c.reciprocating_mass * r * sd * sd,
            "deviation_from_two_mass_formula": if sdd == 0.0 { json!(formula_dev) } else { Value::Null },
            "shaking_force": series,
        }),
    );
    let _ = writeln!(
        text,
        "\ncounterweight: rotating mass {:.4} kg, reciprocating {:.4} kg at r = {r} m; with {:.0}% of the reciprocating mass: m_cw r_cw = {:.6} kg m → {:.4} kg at {} m\n  max shaking force {:.3} N → {:.3} N (deviation from the two-mass formula {:.2e} N)",
        c.rotating_mass,
        c.reciprocating_mass,
        cw.fraction * 100.0,
        c.mass_radius,
        c.mass,
        cw.radius,
        before,
        after,
        formula_dev
    );
}

/// Rotor balancing: the corrections in one or two planes and the unbalance before and
/// after.
fn rotor_balance(r: &RotorScenario, json: &mut Map<String, Value>, text: &mut String) {
    let (f0, m0) = balancing::resultant(&r.masses, r.planes[0].0);
    let corr: Vec<balancing::Correction> = if r.planes.len() == 1 {
        vec![balancing::single_plane(
            &r.masses,
            r.planes[0].0,
            r.planes[0].1,
        )]
    } else {
        balancing::two_plane(&r.masses, r.planes[0], r.planes[1]).to_vec()
    };
    let mut all = r.masses.clone();
    all.extend(corr.iter().map(|c| c.as_mass()));
    let (f1, m1) = balancing::resultant(&all, r.planes[0].0);
    let _ = writeln!(
        text,
        "\nrotor balancing ({} plane{}):",
        corr.len(),
        if corr.len() > 1 { "s" } else { "" }
    );
    let _ = writeln!(
        text,
        "  unbalance before: force {:.6} kg m, moment {:.6} kg m²",
        f0.norm(),
        m0.norm()
    );
    for c in &corr {
        let _ = writeln!(
            text,
            "  correction in plane z = {} m at r = {} m: {:.6} kg at {:.3}°",
            c.position,
            c.radius,
            c.mass,
            c.angle.to_degrees()
        );
    }
    let _ = writeln!(
        text,
        "  unbalance after: force {:.2e} kg m, moment {:.2e} kg m²",
        f1.norm(),
        m1.norm()
    );
    json.insert(
        "rotor_balance".into(),
        json!({
            "corrections": corr.iter().map(|c| json!({"position": c.position, "radius": c.radius, "mass": c.mass, "angle_deg": c.angle.to_degrees()})).collect::<Vec<_>>(),
            "unbalance_before": {"force": f0.norm(), "moment": m0.norm()},
            "unbalance_after": {"force": f1.norm(), "moment": m1.norm()},
        }),
    );
}

/// Machine motion `J ω̇ = M_d(ω) − M_c` by RK4, against the closed form for a linear
/// drive characteristic.
fn machine_motion_json(mm: &MachineScenario, json: &mut Map<String, Value>, text: &mut String) {
    let load = machine_motion::Characteristic(vec![mm.load]);
    let h = machine_motion::integrate(mm.inertia, &mm.drive, &load, mm.omega0, mm.t_end, mm.dt);
    let linear = mm.drive.0.len() <= 2;
    let (a, b) = (mm.drive.0[0], mm.drive.0.get(1).map(|x| -x).unwrap_or(0.0));
    let closed = |t: f64| {
        (linear && b != 0.0)
            .then(|| machine_motion::linear_speed(mm.inertia, a, b, mm.load, mm.omega0, t))
    };
    let mut max_err: Option<f64> = None;
    for (t, w) in h.t.iter().zip(&h.omega) {
        if let Some(c) = closed(*t) {
            max_err = Some(max_err.unwrap_or(0.0).max((c - w).abs()));
        }
    }
    let every = (h.t.len() / 100).max(1);
    let series: Vec<Value> = h
        .t
        .iter()
        .zip(&h.omega)
        .zip(&h.phi)
        .enumerate()
        .filter(|(k, _)| k % every == 0 || *k + 1 == h.t.len())
        .map(|(_, ((t, w), p))| json!({"t": t, "omega": w, "phi": p, "omega_closed_form": closed(*t)}))
        .collect();
    let steady = (linear && b != 0.0).then(|| (a - mm.load) / b);
    let _ = writeln!(
        text,
        "\nmachine motion: J = {} kg m², M_d(ω) = {:?}, load {} N m, from ω0 = {}: ω({}) = {:.9} rad/s{}",
        mm.inertia,
        mm.drive.0,
        mm.load,
        mm.omega0,
        mm.t_end,
        h.omega.last().copied().unwrap_or(f64::NAN),
        match (steady, max_err) {
            (Some(s), Some(e)) => format!(
                "; closed form ω(t) = {s} + ({} − {s}) e^(−{} t): largest RK4 error {e:.2e} rad/s",
                mm.omega0,
                b / mm.inertia
            ),
            _ => String::new(),
        }
    );
    json.insert(
        "machine_motion".into(),
        json!({
            "inertia": mm.inertia,
            "drive": mm.drive.0,
            "load": mm.load,
            "omega0": mm.omega0,
            "dt": mm.dt,
            "steady_speed": steady,
            "time_constant": (linear && b != 0.0).then(|| mm.inertia / b),
            "max_error_vs_closed_form": max_err,
            "final": {"t": h.t.last(), "omega": h.omega.last(), "phi": h.phi.last()},
            "series": series,
        }),
    );
}

/// Builds the report of a parsed scenario.
pub fn report(sc: &LinkageScenario, kind_name: &str) -> Report {
    let mut json = Map::new();
    let mut text = String::new();
    json.insert("name".into(), json!(sc.name));
    json.insert("kind".into(), json!(kind_name));
    let _ = writeln!(text, "{} ({})", sc.name, sc.file);
    if let Some(d) = &sc.description {
        json.insert("description".into(), json!(d));
        for line in d.lines() {
            let _ = writeln!(text, "  {line}");
        }
    }
    let drive = sc
        .mechanism
        .as_ref()
        .and_then(|m| mechanism(m, &mut json, &mut text));
    if let Some(f) = &sc.flywheel {
        let series: Option<Vec<(f64, f64)>> = f.table.clone().or(drive);
        match series {
            None => {
                json.insert(
                    "flywheel".into(),
                    json!({"error": "no driving torque over a full turn"}),
                );
                let _ = writeln!(text, "flywheel: no driving torque over a full turn");
            }
            Some(s) => {
                let phi: Vec<f64> = s.iter().map(|x| x.0).collect();
                let m: Vec<f64> = s.iter().map(|x| x.1).collect();
                let fw = flywheel::size(&phi, &m, f.load, f.speed, f.delta);
                let _ = writeln!(
                    text,
                    "\nflywheel: mean driving torque {:.6} N m, energy fluctuation ΔE = {:.6} J (max at {:.2}°, min at {:.2}°); δ = {} at ω = {} rad/s → J = {:.6} kg m²",
                    fw.mean_torque,
                    fw.energy_fluctuation,
                    fw.max_at.to_degrees(),
                    fw.min_at.to_degrees(),
                    f.delta,
                    f.speed,
                    fw.inertia
                );
                let mut v = serde_json::to_value(&fw).unwrap_or(Value::Null);
                v["speed_fluctuation"] = json!(f.delta);
                v["speed"] = json!(f.speed);
                json.insert("flywheel".into(), v);
            }
        }
    }
    if let Some(r) = &sc.rotor {
        rotor_balance(r, &mut json, &mut text);
    }
    if let Some(mm) = &sc.machine {
        machine_motion_json(mm, &mut json, &mut text);
    }
    Report {
        json: Value::Object(json),
        text,
    }
}
