//! The report of a `kind = "gear_train"` scenario: mobility and classification, every
//! member's speed and exact ratio, the meshes, Willis ratios, the geometric checks, the
//! torques, tooth forces and planet-bearing loads of the load case, and the train as a
//! transmission (ratio, forward and reverse efficiency, self-locking, reflected inertia).
//! JSON keys are listed in `docs/machines.md`.

use crate::io::report::Report;
use crate::machines::gearing::assembly::{planet_arm, Check, DerivedTeeth};
use crate::machines::gearing::rational::Ratio;
use crate::machines::gearing::torques::{solve_torques, Torques};
use crate::machines::gearing::train::{Element, GearTrain, TrainError};
use crate::machines::gearing::willis::{relative_ratio, Kinematics, Speeds};
use serde_json::{json, Value};
use std::fmt::Write;

/// A Willis query: `[from, to, carrier]` bodies and its index in the file.
#[derive(Clone, Debug)]
pub struct Query {
    /// Bodies `a`, `b`, carrier `H`.
    pub ids: [usize; 3],
    /// Index of the `[[willis]]` table.
    pub index: usize,
}

/// A parsed, checked gear-train scenario.
#[derive(Clone, Debug)]
pub struct TrainScenario {
    /// Scenario name.
    pub name: String,
    /// `"rpm"` or `"rad/s"`.
    pub unit: String,
    /// The train (tooth counts resolved).
    pub train: GearTrain,
    /// Tooth counts found from conditions.
    pub derived: Vec<DerivedTeeth>,
    /// Coaxiality, centre-distance, assembly and neighbour checks.
    pub checks: Vec<Check>,
    /// Motion space.
    pub kin: Kinematics,
    /// Speeds for the inputs.
    pub speeds: Speeds,
    /// Inputs (body, speed).
    pub inputs: Vec<(usize, f64)>,
    /// Given external torques (body, N m).
    pub torques: Vec<(usize, f64)>,
    /// Output member.
    pub output: Option<usize>,
    /// Willis queries.
    pub willis: Vec<Query>,
}

impl TrainScenario {
    /// rad/s per speed unit.
    pub fn to_rad_s(&self) -> f64 {
        if self.unit == "rpm" {
            std::f64::consts::PI / 30.0
        } else {
            1.0
        }
    }

    /// Body speeds in rad/s.
    pub fn omega(&self) -> Vec<f64> {
        let k = self.to_rad_s();
        self.speeds.values.iter().map(|v| v * k).collect()
    }
}

fn ratio_json(r: Option<Ratio>) -> Value {
    match r {
        Some(r) => json!({ "value": r.to_f64(), "exact": r.to_string() }),
        None => Value::Null,
    }
}

/// `ω_in / ω_b` exactly, for one degree of freedom.
fn ratio_to(sc: &TrainScenario, b: usize) -> Option<Ratio> {
    if sc.speeds.inputs.len() != 1 {
        return None;
    }
    Ratio::ONE.over(sc.speeds.map[b][0]).ok().flatten()
}

/// Efficiency of a load case: power out over power in (members with a torque).
fn efficiency_of(tq: &Torques, omega: &[f64]) -> Option<f64> {
    let (mut pin, mut pout) = (0.0, 0.0);
    for (t, w) in tq.body.iter().zip(omega) {
        let p = t * w;
        if p > 0.0 {
            pin += p;
        } else {
            pout -= p;
        }
    }
    (pin > 0.0).then(|| pout / pin)
}

/// Member `b`'s table row and JSON: kind, gears, speed, ratio from the input, and its
/// torque and power under load.
fn member_json(
    sc: &TrainScenario,
    b: usize,
    omega: &[f64],
    torque: Option<f64>,
    text: &mut String,
) -> Value {
    let t = &sc.train;
    let body = &t.bodies[b];
    let gears: Vec<Value> = t
        .gears_on(b)
        .map(|g| json!({ "name": t.gears[g].name, "teeth": t.z(g), "internal": t.gears[g].internal }))
        .collect();
    let gl: Vec<String> = t
        .gears_on(b)
        .map(|g| format!("{}({})", t.gears[g].name, t.z(g)))
        .collect();
    let kind = if body.is_carrier {
        "carrier"
    } else if body.carrier.is_some() {
        "planet"
    } else {
        "gear"
    };
    let r = ratio_to(sc, b);
    let _ = writeln!(
        text,
        "{:<10} {:<8} {:<16} {:>14.6} {:>16} {:>12} {:>12}{}",
        body.name,
        if body.fixed { "fixed" } else { kind },
        gl.join(" "),
        sc.speeds.values[b],
        r.map_or("—".into(), |r| format!("{:.6}", r.to_f64())),
        torque.map_or("".into(), |x| format!("{x:.4}")),
        torque.map_or("".into(), |x| format!("{:.3}", x * omega[b] + 0.0)),
        if sc.kin.sense_defined[b] {
            ""
        } else {
            "  (sense not defined: non-parallel axes)"
        }
    );
    let mut m = json!({
        "name": body.name,
        "kind": kind,
        "fixed": body.fixed,
        "gears": gears,
        "carrier": body.carrier.map(|c| t.bodies[c].name.clone()),
        "speed": sc.speeds.values[b],
        "speed_rad_s": omega[b],
        "sense_defined": sc.kin.sense_defined[b],
        "speed_per_input": sc.speeds.map[b].iter().map(|r| json!({"value": r.to_f64(), "exact": r.to_string()})).collect::<Vec<_>>(),
        "ratio_from_input": ratio_json(r),
    });
    if let Some(c) = body.carrier {
        m["speed_relative_to_carrier"] = json!(sc.speeds.values[b] - sc.speeds.values[c]);
    }
    if let Some(x) = torque {
        m["torque_Nm"] = json!(x);
        m["power_W"] = json!(x * omega[b]);
    }
    m
}

/// The Willis (relative) ratios asked for, as text lines and JSON.
fn willis_json(sc: &TrainScenario, text: &mut String) -> Result<Vec<Value>, TrainError> {
    let t = &sc.train;
    let mut willis = Vec::new();
    for q in &sc.willis {
        let [a, b, h] = q.ids;
        let r = relative_ratio(t, a, b, h)?;
        let _ = writeln!(
            text,
            "Willis: i_{}{}^{} = (ω_{} − ω_{})/(ω_{} − ω_{}) = {}",
            t.bodies[a].name,
            t.bodies[b].name,
            t.bodies[h].name,
            t.bodies[a].name,
            t.bodies[h].name,
            t.bodies[b].name,
            t.bodies[h].name,
            r.map_or("—".into(), |r| format!("{r} = {:.6}", r.to_f64()))
        );
        willis.push(json!({
            "from": t.bodies[a].name, "to": t.bodies[b].name, "carrier": t.bodies[h].name,
            "ratio": ratio_json(r),
        }));
    }
    Ok(willis)
}

/// The report (see the module docs).
pub fn report(sc: &TrainScenario, kind_name: &str) -> Result<Report, TrainError> {
    let t = &sc.train;
    let omega = sc.omega();
    let mut text = String::new();
    let (w, n, p5, p4) = t.structural_mobility();
    let dof = sc.kin.dof();
    let class = t.classify(dof);
    let _ = writeln!(text, "Gear train '{}': {class}", sc.name);
    let _ = writeln!(
        text,
        "Mobility W = 3n − 2p5 − p4 = 3·{n} − 2·{p5} − {p4} = {w}; kinematic degrees of freedom (null space of the mesh equations) = {dof}"
    );
    for d in &sc.derived {
        let _ = writeln!(
            text,
            "Derived: z('{}') = {} from {}",
            t.gears[d.gear].name, d.teeth, d.from
        );
    }
    let load = if sc.torques.is_empty() {
        None
    } else {
        Some(solve_torques(t, &omega, &sc.torques, &sc.speeds.inputs)?)
    };
    let _ = writeln!(
        text,
        "\n{:<10} {:<8} {:<16} {:>14} {:>16} {:>12} {:>12}",
        "member",
        "kind",
        "gears (z)",
        &format!("speed ({})", sc.unit),
        "ratio ω_in/ω",
        "torque N m",
        "power W"
    );
    let mut members = Vec::new();
    for b in 0..t.bodies.len() {
        let torque = load.as_ref().map(|l| l.body[b]);
        members.push(member_json(sc, b, &omega, torque, &mut text));
    }
    let meshes = mesh_json(sc, load.as_ref(), &mut text)?;
    let willis = willis_json(sc, &mut text)?;
    if !sc.checks.is_empty() {
        let _ = writeln!(text, "\nChecks");
        for c in &sc.checks {
            let _ = writeln!(
                text,
                "  [{}] {}: {}",
                if c.ok { "ok" } else { "FAILS" },
                c.kind,
                c.detail
            );
        }
    }
    let mut json = json!({
        "scenario": sc.name,
        "kind": kind_name,
        "classification": class,
        "speed_unit": sc.unit,
        "mobility": { "structural": w, "kinematic": dof, "moving_links": n, "lower_pairs": p5, "gear_meshes": p4 },
        "inputs": sc.inputs.iter().map(|&(b, v)| json!({"member": t.bodies[b].name, "speed": v})).collect::<Vec<_>>(),
        "derived_teeth": sc.derived.iter().map(|d| json!({"gear": t.gears[d.gear].name, "teeth": d.teeth, "from": d.from})).collect::<Vec<_>>(),
        "members": members,
        "meshes": meshes,
        "willis": willis,
        "checks": sc.checks.iter().map(|c| json!({"kind": c.kind, "detail": c.detail, "ok": c.ok})).collect::<Vec<_>>(),
    });
    if let Some(l) = &load {
        json["load"] = load_json(sc, l, &omega, &mut text);
    }
    if let Some(o) = sc.output {
        json["transmission"] = transmission(sc, o, &omega, &mut text)?;
    }
    Ok(Report { json, text })
}

fn mesh_json(
    sc: &TrainScenario,
    load: Option<&Torques>,
    text: &mut String,
) -> Result<Vec<Value>, TrainError> {
    let t = &sc.train;
    let mut out = Vec::new();
    for (e, m) in t.meshes.iter().enumerate() {
        let f = t.mesh_frame(e)?;
        let [a, b] = m.gears;
        let base = Ratio::new(t.z(b) as i128, t.z(a) as i128).unwrap_or(Ratio::ZERO);
        let rel = f.sign.map(|s| if s < 0 { base.negated() } else { base });
        let planets = f.carrier.map_or(1, |c| t.bodies[c].planets);
        let mut v = json!({
            "gears": [t.gears[a].name, t.gears[b].name],
            "kind": m.kind.name(),
            "sign": f.sign,
            "seen_from": f.carrier.map_or("frame".to_string(), |c| t.bodies[c].name.clone()),
            "relative_ratio": ratio_json(rel),
            "centre_distance_mm": t.centre_distance(e),
            "efficiency": m.efficiency,
        });
        if let Some(l) = load {
            let ra = t.radius(a);
            v["tooth_torque_Nm"] = json!(l.mesh[e]);
            v["first_gear_drives"] = json!(l.first_drives[e]);
            v["relative_power_W"] = json!(l.relative_power[e]);
            v["tooth_force_N"] = json!(ra.map(|r| l.mesh[e].abs() / (r / 1000.0) / planets as f64));
        }
        out.push(v);
    }
    if load.is_some() {
        let _ = writeln!(text);
    }
    Ok(out)
}

fn load_json(sc: &TrainScenario, l: &Torques, omega: &[f64], text: &mut String) -> Value {
    let t = &sc.train;
    let eff = efficiency_of(l, omega);
    let mut bearings = Vec::new();
    for (c, body) in t.bodies.iter().enumerate().filter(|(_, b)| b.is_carrier) {
        let Some(p) = (0..t.bodies.len()).find(|&p| t.bodies[p].carrier == Some(c)) else {
            continue;
        };
        let Some(arm) = planet_arm(t, p) else {
            continue;
        };
        let r = l.body[c].abs() / (arm / 1000.0) / body.planets as f64;
        let _ = writeln!(
            text,
            "Planet bearing on '{}': R = |M_{}| / (r_C n) = {:.4} / ({:.4} m · {}) = {r:.3} N",
            t.bodies[p].name,
            body.name,
            l.body[c].abs(),
            arm / 1000.0,
            body.planets
        );
        bearings.push(json!({"planet": t.bodies[p].name, "carrier": body.name, "arm_mm": arm, "planets": body.planets, "load_N": r}));
    }
    if let Some(e) = eff {
        let _ = writeln!(
            text,
            "Load case efficiency (power out / power in) = {e:.6} ({} direction iteration{})",
            l.iterations,
            if l.iterations == 1 { "" } else { "s" }
        );
    }
    json!({
        "efficiency": eff,
        "iterations": l.iterations,
        "converged": l.converged,
        "planet_bearings": bearings,
    })
}

/// The train between its single input and its `output` as a transmission (an arm
/// joint's gearbox): ratio, efficiencies, self-locking and inertia referred to the input.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Transmission {
    /// Input member (the motor side).
    pub input: String,
    /// Output member (the joint side).
    pub output: String,
    /// `N = ω_in/ω_out` (signed).
    pub gear_ratio: f64,
    /// `N` exactly.
    pub gear_ratio_exact: String,
    /// Power out over power in, the input driving.
    pub efficiency_forward: f64,
    /// The output driving (0 when it cannot).
    pub efficiency_reverse: f64,
    /// The output cannot drive the input.
    pub self_locking: bool,
    /// `Σ J_b (ω_b/ω_in)²` (kg m²), planets counted `n` times with their orbiting mass.
    pub inertia_input_side: f64,
}

/// See [`Transmission`]; needs one degree of freedom and an output that turns.
pub fn transmission_of(sc: &TrainScenario, o: usize) -> Result<Transmission, TrainError> {
    let t = &sc.train;
    let omega = sc.omega();
    let i = sc.speeds.inputs[0];
    let ratio = ratio_to(sc, o)
        .ok_or_else(|| TrainError::new(Element::Train, "output", "the output does not turn"))?;
    let sgn = |x: f64| if x < 0.0 { -1.0 } else { 1.0 };
    let fwd = solve_torques(t, &omega, &[(o, -sgn(omega[o]))], &[i])?;
    let rev = solve_torques(t, &omega, &[(i, -sgn(omega[i]))], &[o])?;
    let ef = efficiency_of(&fwd, &omega).unwrap_or(0.0);
    let er = efficiency_of(&rev, &omega);
    // Reverse drive: the output must deliver power for the input's load to move.
    let er_val = er.filter(|_| rev.body[o] * omega[o] > 0.0).unwrap_or(0.0);
    let locking = er_val <= 0.0 || !rev.converged;
    // Inertia referred to the input: Σ J (ω_b/ω_in)² (+ planets' orbiting mass).
    let win = omega[i];
    let mut j_in = 0.0;
    for (b, body) in t.bodies.iter().enumerate() {
        let r = omega[b] / win;
        let copies = body.carrier.map_or(1.0, |c| t.bodies[c].planets as f64);
        let jb: f64 = t.gears_on(b).map(|g| t.gears[g].inertia).sum::<f64>() + body.inertia;
        j_in += copies * jb * r * r;
        if let (Some(c), Some(arm)) = (body.carrier, planet_arm(t, b)) {
            let m: f64 = t.gears_on(b).map(|g| t.gears[g].mass).sum();
            let rc = omega[c] / win;
            j_in += copies * m * (arm / 1000.0).powi(2) * rc * rc;
        }
    }
    Ok(Transmission {
        input: t.bodies[i].name.clone(),
        output: t.bodies[o].name.clone(),
        gear_ratio: ratio.to_f64(),
        gear_ratio_exact: ratio.to_string(),
        efficiency_forward: ef,
        efficiency_reverse: er_val,
        self_locking: locking,
        inertia_input_side: j_in,
    })
}

fn transmission(
    sc: &TrainScenario,
    o: usize,
    _omega: &[f64],
    text: &mut String,
) -> Result<Value, TrainError> {
    let tr = transmission_of(sc, o)?;
    let (n, ef, er_val, j_in) = (
        tr.gear_ratio,
        tr.efficiency_forward,
        tr.efficiency_reverse,
        tr.inertia_input_side,
    );
    let _ = writeln!(
        text,
        "\nTransmission '{}' → '{}': i = ω_in/ω_out = {} = {n:.6}; efficiency {ef:.6} forward, {er_val:.6} reverse{}; inertia referred to the input {j_in:.6e} kg m² (to the output {:.6e})",
        tr.input, tr.output, tr.gear_ratio_exact,
        if tr.self_locking { " (self-locking: the output cannot drive the input)" } else { "" },
        j_in * n * n
    );
    Ok(json!({
        "input": tr.input,
        "output": tr.output,
        "gear_ratio": { "value": n, "exact": tr.gear_ratio_exact },
        "efficiency_forward": ef,
        "efficiency_reverse": er_val,
        "self_locking": tr.self_locking,
        "inertia_input_side": j_in,
        "inertia_output_side": j_in * n * n,
        "rotor_inertia": { "gear_ratio": n.abs(), "efficiency": ef },
    }))
}
