//! Runs the analyses a linkage scenario asks for and writes the report: the JSON document
//! of `armsim run --json` and the text summary. The keys are listed in
//! `docs/mechanism.md`.

mod sweep_report;
mod sweep_rows;

use crate::io::report::Report;
use crate::machines::balancing::{self};
use crate::machines::flywheel;
use crate::machines::flywheel::machine_motion;
use crate::scenarios::linkage::linkage_scenario::{
    LinkageScenario, MachineScenario, RotorScenario,
};
use crate::scenarios::linkage::report::sweep_report::mechanism;
use serde_json::{json, Map, Value};
use std::fmt::Write;

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
    let mut v = json!({
        "corrections": corr.iter().map(|c| json!({"position": c.position, "radius": c.radius, "mass": c.mass, "angle_deg": c.angle.to_degrees()})).collect::<Vec<_>>(),
        "unbalance_before": {"force": f0.norm(), "moment": m0.norm()},
        "unbalance_after": {"force": f1.norm(), "moment": m1.norm()},
    });
    if let Some((w, [za, zb])) = r.bearings {
        let loads = |m: &[balancing::RotorMass]| {
            let f = balancing::bearing_forces(m, w, za, zb);
            json!({"force_N": [f[0].norm(), f[1].norm()],
                "angle_deg": [f[0].y.atan2(f[0].x).to_degrees(), f[1].y.atan2(f[1].x).to_degrees()]})
        };
        let (before, after) = (loads(&r.masses), loads(&all));
        let _ = writeln!(
            text,
            "  bearing loads at {:.1} rpm (A at z = {za} m, B at z = {zb} m): {:.4} / {:.4} N before, {:.2e} / {:.2e} N after",
            w * 30.0 / std::f64::consts::PI,
            before["force_N"][0].as_f64().unwrap_or(f64::NAN),
            before["force_N"][1].as_f64().unwrap_or(f64::NAN),
            after["force_N"][0].as_f64().unwrap_or(f64::NAN),
            after["force_N"][1].as_f64().unwrap_or(f64::NAN),
        );
        v["bearings"] = json!({"speed_rpm": w * 30.0 / std::f64::consts::PI, "omega": w,
            "positions": [za, zb], "centrifugal_force_N": f0.norm() * w * w,
            "before": before, "after": after});
    }
    json.insert("rotor_balance".into(), v);
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
