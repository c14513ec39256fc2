//! Runs the analyses a linkage scenario asks for and writes the report: the JSON document
//! of `armsim run --json` and the text summary. The keys are listed in
//! `docs/mechanism.md`.

mod centres_report;
mod change_points;
mod counterweight_report;
mod guide_report;
mod sweep_report;
mod sweep_rows;

use crate::io::report::Report;
use crate::machines::balancing::{self};
use crate::machines::flywheel;
use crate::machines::flywheel::machine_motion;
use crate::machines::linkage::reduced;
use crate::scenarios::linkage::linkage_scenario::{
    LinkageScenario, MachineScenario, MechanismScenario, RotorScenario,
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

/// The linkage's reduced inertia over its full-turn sweep as a Hermite table
/// (`J_red`, `dJ_red/dφ` at every sample), or why not.
fn linkage_inertia_table(m: &MechanismScenario) -> Result<machine_motion::InertiaTable, String> {
    let l = &m.linkage;
    let (sw, _) = crate::machines::linkage::continuation::sweep_through(l, &m.assembly, &m.sweep)
        .map_err(|e| e.to_string())?;
    if let Some(e) = &sw.stopped {
        return Err(format!("the sweep stopped: {e}"));
    }
    let mut rows: Vec<(f64, f64, f64)> = sw
        .samples
        .iter()
        .map(|st| {
            let (j, dj) = reduced::reduced_inertia(l, &st.dq, &st.ddq);
            (st.s, j, dj)
        })
        .collect();
    rows.pop(); // the last sample repeats the first, a turn later
    if m.sweep.to < m.sweep.from {
        rows.reverse();
    }
    if rows.iter().all(|r| r.1 <= 0.0) {
        return Err("the linkage has no mass or inertia".into());
    }
    Ok(machine_motion::InertiaTable::hermite(
        rows.iter().map(|r| r.0).collect(),
        rows.iter().map(|r| r.1).collect(),
        rows.iter().map(|r| r.2).collect(),
        std::f64::consts::TAU,
    ))
}

/// The position-dependent inertia of a machine-motion section: its table, the linkage's
/// `J_red(φ)`, or none; the error says why the linkage's cannot be had.
fn machine_inertia_table(
    mm: &MachineScenario,
    mech: Option<&MechanismScenario>,
) -> Result<Option<machine_motion::InertiaTable>, String> {
    if mm.inertia_from_linkage {
        return mech
            .map_or(
                Err("no linkage in the file".to_string()),
                linkage_inertia_table,
            )
            .map(Some)
            .map_err(|e| format!("machine motion: inertia_from_linkage: {e}"));
    }
    Ok(mm.inertia_table.as_ref().map(|t| {
        machine_motion::InertiaTable::smooth(
            t.iter().map(|r| r.0).collect(),
            t.iter().map(|r| r.1).collect(),
            std::f64::consts::TAU,
        )
    }))
}

/// Machine motion `J(φ) ω̇ + ½ J'(φ) ω² = u M_d(u ω) − M_c` by RK4, against the closed
/// form for a linear drive characteristic and constant inertia, with the energy balance.
fn machine_motion_json(
    mm: &MachineScenario,
    mech: Option<&MechanismScenario>,
    json: &mut Map<String, Value>,
    text: &mut String,
) {
    let table = match machine_inertia_table(mm, mech) {
        Ok(t) => t,
        Err(why) => {
            json.insert("machine_motion".into(), json!({"error": why}));
            let _ = writeln!(text, "\n{why}");
            return;
        }
    };
    let load = machine_motion::Characteristic(vec![mm.load]);
    let machine = machine_motion::GearedMachine {
        ratio: mm.ratio,
        motor_inertia: mm.motor_inertia,
        inertia: mm.inertia,
        table: table.as_ref(),
        drive: &mm.drive,
        load: &load,
    };
    let h = machine_motion::integrate_geared(&machine, (0.0, mm.omega0), mm.t_end, mm.dt);
    let u = mm.ratio;
    let j_const = mm.inertia + mm.motor_inertia * u * u;
    let (j_lo, j_hi) = table.as_ref().map_or((0.0, 0.0), |t| t.range());
    // Linear motor M_d = a − b ω_motor: on the machine shaft u a − u² b ω.
    let linear = mm.drive.0.len() <= 2;
    let (a, b) = (
        u * mm.drive.0[0],
        u * u * mm.drive.0.get(1).map(|x| -x).unwrap_or(0.0),
    );
    let closed_ok = linear && b != 0.0 && table.is_none();
    let closed = |t: f64| {
        closed_ok.then(|| machine_motion::linear_speed(j_const, a, b, mm.load, mm.omega0, t))
    };
    let mut max_err: Option<f64> = None;
    for (t, w) in h.t.iter().zip(&h.omega) {
        if let Some(c) = closed(*t) {
            max_err = Some(max_err.unwrap_or(0.0).max((c - w).abs()));
        }
    }
    let every = (h.t.len() / 100).max(1);
    let series: Vec<Value> = (0..h.t.len())
        .filter(|k| k % every == 0 || *k + 1 == h.t.len())
        .map(|k| {
            json!({"t": h.t[k], "omega": h.omega[k], "omega_motor": u * h.omega[k], "phi": h.phi[k],
                   "reduced_inertia": machine.reduced_inertia(h.phi[k]).0, "omega_closed_form": closed(h.t[k])})
        })
        .collect();
    let n = h.t.len() - 1;
    let ke = |k: usize| 0.5 * machine.reduced_inertia(h.phi[k]).0 * h.omega[k] * h.omega[k];
    let (d_ke, work) = (ke(n) - ke(0), h.work[n]);
    let steady = closed_ok.then(|| (a - mm.load) / b);
    let _ = writeln!(
        text,
        "\nmachine motion: J = {} kg m²{}{}, M_d(ω) = {:?}, load {} N m, from ω0 = {}: ω({}) = {:.9} rad/s{}",
        mm.inertia,
        if u != 1.0 || mm.motor_inertia != 0.0 {
            format!(" + motor {} kg m² through u = {u} (J_motor u² = {})", mm.motor_inertia, mm.motor_inertia * u * u)
        } else {
            String::new()
        },
        if table.is_some() {
            format!(" + J(φ) in [{j_lo:.6}, {j_hi:.6}]")
        } else {
            String::new()
        },
        mm.drive.0,
        mm.load,
        mm.omega0,
        mm.t_end,
        h.omega[n],
        match (steady, max_err) {
            (Some(s), Some(e)) => format!(
                "; closed form ω(t) = {s} + ({} − {s}) e^(−{} t): largest RK4 error {e:.2e} rad/s",
                mm.omega0,
                b / j_const
            ),
            _ => String::new(),
        }
    );
    let _ = writeln!(
        text,
        "  energy: ½ J(φ) ω² changed by {d_ke:.6} J, work of the torques {work:.6} J"
    );
    json.insert(
        "machine_motion".into(),
        json!({
            "inertia": mm.inertia,
            "ratio": u,
            "motor_inertia": mm.motor_inertia,
            "reduced_inertia": {
                "source": if mm.inertia_from_linkage { "linkage" } else if table.is_some() { "table" } else { "constant" },
                "min": j_const + j_lo, "max": j_const + j_hi,
            },
            "drive": mm.drive.0,
            "load": mm.load,
            "omega0": mm.omega0,
            "dt": mm.dt,
            "steady_speed": steady,
            "time_constant": closed_ok.then(|| j_const / b),
            "max_error_vs_closed_form": max_err,
            "energy_check": {"kinetic_energy_change": d_ke, "work": work, "difference": d_ke - work},
            "final": {"t": h.t[n], "omega": h.omega[n], "omega_motor": u * h.omega[n], "phi": h.phi[n]},
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
        machine_motion_json(mm, sc.mechanism.as_ref(), &mut json, &mut text);
    }
    Report {
        json: Value::Object(json),
        text,
    }
}
