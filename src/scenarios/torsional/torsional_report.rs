//! The report of a torsional scenario (see [`super`]): the chain's table, undamped modes
//! with Holzer's and the LR check, mode shapes, damped modes, critical speeds, forced
//! response per order, the time-domain check and the damping identification.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::report::Report;
use crate::machines::vibration::torsional::damped::{damped_modes, DampedModes};
use crate::machines::vibration::torsional::forced::{
    critical_speeds, order_response, sweep, Excitation,
};
use crate::machines::vibration::torsional::holzer::holzer_frequencies;
use crate::machines::vibration::torsional::identify::identify_damping;
use crate::machines::vibration::torsional::lr::lr_eigenvalues;
use crate::machines::vibration::torsional::modes::{undamped_modes, Mode, CPM_PER_RAD_S};
use crate::machines::vibration::torsional::time::steady_state_by_integration;
use crate::machines::vibration::torsional::torsional_chain::TorsionalChain;
use crate::machines::vibration::torsional::GearedChain;
use crate::scenarios::torsional::torsional_scenario::{Identification, TorsionalScenario};
use serde_json::{json, Value};
use std::fmt::Write;

/// The chain's table: inertia, stiffness and dampers per disk.
fn chain_table(chain: &TorsionalChain, text: &mut String) {
    let _ = writeln!(
        text,
        "{:>3}  {:<22} {:>12} {:>14} {:>12} {:>12}",
        "#", "disk", "J (kg m²)", "c next (N m/rad)", "a (N m s)", "b next"
    );
    for (k, mass) in chain.names.iter().enumerate() {
        let _ = writeln!(
            text,
            "{:>3}  {:<22} {:>12.1} {:>14} {:>12.0} {:>12}",
            k + 1,
            mass,
            chain.inertia[k],
            chain
                .stiffness
                .get(k)
                .map_or("–".into(), |c| format!("{c:.4e}")),
            chain.absolute_damping[k],
            chain
                .relative_damping
                .get(k)
                .map_or("–".into(), |b| format!("{b:.0}")),
        );
    }
}

/// The undamped natural frequencies with Holzer's and the LR check beside them.
fn frequency_table(
    modes: &[Mode],
    (holzer_cpm, lr_cpm): (Option<&[f64]>, Option<&[f64]>),
    text: &mut String,
) {
    let _ = writeln!(
        text,
        "\nUndamped natural frequencies (K x = p² J x; Holzer and LR as checks)"
    );
    let _ = writeln!(
        text,
        "{:>4} {:>12} {:>12} {:>12} {:>12}",
        "mode", "cycles/min", "rad/s", "Holzer cpm", "LR cpm"
    );
    for (r, m) in modes.iter().enumerate() {
        let _ = writeln!(
            text,
            "{:>4} {:>12.2} {:>12.4} {:>12} {:>12}",
            r,
            m.frequency_cpm(),
            m.omega,
            holzer_cpm.map_or("–".into(), |v| format!("{:.2}", v[r])),
            lr_cpm.map_or("–".into(), |v| format!("{:.2}", v[r]))
        );
    }
}

/// The table of the first (up to five) mode shapes.
fn mode_shapes(modes: &[Mode], masses: &[String], text: &mut String) {
    let _ = writeln!(text, "\nMode shapes (max |x| = 1), first modes:");
    let show = modes.len().min(5);
    let _ = write!(text, "{:<22}", "disk");
    for m in modes.iter().take(show) {
        let _ = write!(text, " {:>10}", format!("{:.1} cpm", m.frequency_cpm()));
    }
    let _ = writeln!(text);
    for (k, mass) in masses.iter().enumerate() {
        let _ = write!(text, "{:<22}", mass);
        for m in modes.iter().take(show) {
            let _ = write!(text, " {:>10.4}", m.shape[k]);
        }
        let _ = writeln!(text);
    }
}

/// The damped modes' table and JSON (eigenvalue, frequencies, damping ratio, complex
/// shape, phases).
fn damped_report(damped: &DampedModes, text: &mut String) -> Vec<Value> {
    let _ = writeln!(
        text,
        "\nDamped modes ((λ² J + λ B + K) x = 0, state-space form)"
    );
    let _ = writeln!(
        text,
        "{:>4} {:>12} {:>12} {:>12} {:>10} {:>14}",
        "mode", "Re λ (1/s)", "Im λ (1/s)", "Im λ cpm", "ζ", "phase spread°"
    );
    for (r, d) in damped.oscillatory.iter().enumerate() {
        let ph = d.phase_deg();
        // Spread of phases about 0/180 (a real mode has none).
        let spread = ph
            .iter()
            .zip(&d.shape)
            .filter(|(_, z)| z.norm() > 1e-3)
            .map(|(p, _)| {
                let q = p.rem_euclid(180.0);
                q.min(180.0 - q)
            })
            .fold(0.0_f64, f64::max);
        let _ = writeln!(
            text,
            "{:>4} {:>12.4} {:>12.4} {:>12.2} {:>10.5} {:>14.2}",
            r + 1,
            d.eigenvalue.re,
            d.eigenvalue.im,
            d.damped_frequency_cpm(),
            d.damping_ratio(),
            spread
        );
    }
    if !damped.real_eigenvalues.is_empty() {
        let _ = writeln!(
            text,
            "real eigenvalues (rigid-body / overdamped): {}",
            damped
                .real_eigenvalues
                .iter()
                .map(|v| format!("{v:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    damped
        .oscillatory
        .iter()
        .map(|d| {
            json!({
                "eigenvalue": [d.eigenvalue.re, d.eigenvalue.im],
                "damped_frequency_cpm": d.damped_frequency_cpm(),
                "natural_frequency_cpm": d.natural_frequency_cpm(),
                "damping_ratio": d.damping_ratio(),
                "shape": d.shape.iter().map(|z| [z.re, z.im]).collect::<Vec<_>>(),
                "phase_deg": d.phase_deg(),
                "residual": d.residual,
            })
        })
        .collect()
}

/// The critical speeds (order × mode) with their relative excitation, flagged when in
/// the sweep's `range` (rpm).
fn critical_report(
    modes: &[Mode],
    ex: &Excitation,
    range: Option<(f64, f64)>,
    text: &mut String,
) -> Value {
    let crit = critical_speeds(modes, ex);
    let in_range = |v: f64| range.is_none_or(|(lo, hi)| v >= lo && v <= hi);
    let _ = writeln!(
        text,
        "\nCritical speeds in the speed range (relative excitation = |Σ x e^(ikα)| / Σ|x| over the cylinders)"
    );
    let _ = writeln!(
        text,
        "{:>6} {:>5} {:>12} {:>10} {:>10} {:>10}",
        "order", "mode", "f (cpm)", "n (rpm)", "|Σ|", "relative"
    );
    for c in crit.iter().filter(|c| in_range(c.speed_rpm)) {
        let _ = writeln!(
            text,
            "{:>6} {:>5} {:>12.2} {:>10.2} {:>10.4} {:>10.4}{}",
            c.order,
            c.mode,
            c.frequency_cpm,
            c.speed_rpm,
            c.phase_sum,
            c.relative,
            if ex.cylinders.len() > 1 && c.relative > 0.99 {
                "  major (in phase)"
            } else {
                ""
            }
        );
    }
    Value::Array(
        crit.iter()
            .map(|c| {
                json!({
                    "order": c.order,
                    "mode": c.mode,
                    "frequency_cpm": c.frequency_cpm,
                    "speed_rpm": c.speed_rpm,
                    "phase_sum": c.phase_sum,
                    "relative_excitation": c.relative,
                    "in_speed_range": in_range(c.speed_rpm),
                })
            })
            .collect(),
    )
}

/// The critical speeds (those in the sweep's range flagged) and the forced response per
/// order: peak over the sweep and, at the rated speed, the largest shaft torque.
fn forced_report(
    chain: &TorsionalChain,
    modes: &[Mode],
    ex: &Excitation,
    (speeds, rated): (Option<&[f64]>, Option<f64>),
    text: &mut String,
    json: &mut Value,
) {
    let shafts = chain.shaft_names();
    let range = speeds.map(|s| (s[0], s[s.len() - 1]));
    json["critical_speeds"] = critical_report(modes, ex, range, text);
    let mut forced = Vec::new();
    let sweeps = speeds.map(|s| sweep(chain, ex, s));
    let _ = writeln!(
        text,
        "\nForced response per order (amplitudes per cylinder)"
    );
    let _ = writeln!(
        text,
        "{:>6} {:>11} {:>26} {:>10} {:>14}{}",
        "order",
        "A (N m)",
        "peak shaft",
        "at rpm",
        "peak T (N m)",
        if rated.is_some() {
            "   max T at rated (N m)"
        } else {
            ""
        }
    );
    for (i, &order) in ex.orders.iter().enumerate() {
        let mut o = json!({ "order": order, "amplitude_Nm": ex.amplitudes[i] });
        let mut line = format!("{:>6} {:>11.4e}", order, ex.amplitudes[i]);
        if let Some(sw) = sweeps.as_ref().map(|s| &s[i]) {
            o["speeds_rpm"] = json!(sw.speeds_rpm);
            o["shaft_torque_Nm"] = json!(sw.shaft_torque);
        }
        if let Some((sw, (si, sh, tq))) = sweeps
            .as_ref()
            .and_then(|s| s[i].peak().map(|p| (&s[i], p)))
        {
            let at_peak = order_response(chain, ex, i, sw.speeds_rpm[si]);
            o["peak"] = json!({
                "speed_rpm": sw.speeds_rpm[si],
                "shaft": shafts[sh],
                "torque_Nm": tq,
                "mass_amplitude_rad": at_peak.as_ref().map(|r| r.amplitudes()),
                "shaft_torque_Nm": at_peak.as_ref().map(|r| r.shaft_torques(chain)),
            });
            let _ = write!(
                line,
                " {:>26} {:>10.2} {:>14.4e}",
                shafts[sh], sw.speeds_rpm[si], tq
            );
        }
        if let Some(rpm) = rated {
            if let Some(r) = order_response(chain, ex, i, rpm) {
                let t = r.shaft_torques(chain);
                let tmax = t.iter().fold(0.0_f64, |m, v| m.max(*v));
                o["at_rated"] = json!({
                    "speed_rpm": rpm,
                    "mass_amplitude_rad": r.amplitudes(),
                    "shaft_torque_Nm": t,
                });
                let _ = write!(line, "   {tmax:>14.4e}");
            }
        }
        let _ = writeln!(text, "{line}");
        forced.push(o);
    }
    json["forced"] = Value::Array(forced);
    if let Some(rpm) = rated {
        json["rated_speed_rpm"] = json!(rpm);
    }
}

/// The time-domain check: RK4 from rest against the harmonic solution of one order.
fn time_check_report(
    chain: &TorsionalChain,
    ex: &Excitation,
    (oi, sp, periods, spp): (usize, f64, usize, usize),
    text: &mut String,
    json: &mut Value,
) {
    let n = chain.len();
    let order = ex.orders[oi];
    let (ms, mc) = ex.torque_vectors(n, oi);
    let harmonic = order_response(chain, ex, oi, sp);
    let nu = order * sp * crate::machines::vibration::torsional::forced::RAD_S_PER_RPM;
    let td = steady_state_by_integration(chain, nu, &ms, &mc, periods, spp);
    if let Some(h) = harmonic {
        let scale = h.amplitudes().iter().fold(0.0_f64, |m, v| m.max(*v));
        let diff = h
            .sin
            .iter()
            .zip(&td.sin)
            .chain(h.cos.iter().zip(&td.cos))
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        let rel = diff / scale;
        let _ = writeln!(
            text,
            "\nTime-domain check: order {order} at {sp} rpm, RK4 from rest over {periods} periods × {spp} steps ({:.2} s): \
             last-period Fourier coefficients differ from the harmonic solution by {rel:.2e} (relative to the largest amplitude)",
            periods as f64 * 60.0 / (order * sp)
        );
        json["time_check"] = json!({
            "order": order,
            "speed_rpm": sp,
            "periods": periods,
            "steps_per_period": spp,
            "simulated_s": periods as f64 * 60.0 / (order * sp),
            "max_relative_difference": rel,
            "harmonic_amplitude_rad": h.amplitudes(),
            "time_domain_amplitude_rad": td.amplitudes(),
        });
    }
}

/// The damping identification: estimates, standard errors and covariance.
fn identification_report(
    file: &str,
    id: &Identification,
    ex: &Excitation,
    text: &mut String,
    json: &mut Value,
) -> Result<(), ScenarioError> {
    let Identification {
        base,
        params,
        data,
        initial,
        nominal,
        line,
    } = id;
    let est = identify_damping(base, ex, params, data, initial)
        .map_err(|e| ScenarioError::new(file, Some(*line), "identification", e.to_string()))?;
    let _ = writeln!(
        text,
        "\nDamping identification ({} measured shaft-torque amplitudes, Levenberg–Marquardt, {} iterations, residual σ = {:.3} %)",
        data.len(),
        est.iterations,
        100.0 * est.sigma
    );
    let _ = writeln!(
        text,
        "{:<24} {:>14} {:>14} {:>14} {:>10}",
        "parameter", "estimate", "std error", "in [chain]", "(est−chain)/se"
    );
    let mut pj = Vec::new();
    for (j, p) in params.iter().enumerate() {
        let z = (est.values[j] - nominal[j]) / est.std_errors[j];
        let _ = writeln!(
            text,
            "{:<24} {:>14.1} {:>14.1} {:>14.1} {:>10.2}",
            p.name, est.values[j], est.std_errors[j], nominal[j], z
        );
        pj.push(json!({
            "name": p.name,
            "estimate": est.values[j],
            "std_error": est.std_errors[j],
            "initial": initial[j],
            "chain_value": nominal[j],
        }));
    }
    json["identification"] = json!({
        "parameters": pj,
        "measurements": data.len(),
        "iterations": est.iterations,
        "residual_sigma": est.sigma,
        "covariance": (0..params.len())
            .map(|i| (0..params.len()).map(|j| est.covariance[(i, j)]).collect::<Vec<_>>())
            .collect::<Vec<_>>(),
    });
    Ok(())
}

/// The analyses of a parsed scenario: modes, damped modes, forced response, time-domain
/// check and identification.
pub fn report(sc: &TorsionalScenario, kind_name: &str) -> Result<Report, ScenarioError> {
    let TorsionalScenario {
        file,
        name,
        chain,
        rated,
        exc,
        speeds,
        time_check,
        ident,
    } = sc;
    let (chain, rated, time_check) = (chain, *rated, *time_check);
    let n = chain.len();
    let masses = chain.names.clone();
    let shafts = chain.shaft_names();
    let modes = undamped_modes(chain);
    // Holzer's field matrices divide by c: only for chains without zero-stiffness shafts.
    let holzer: Option<Vec<f64>> = chain
        .stiffness
        .iter()
        .all(|c| *c > 0.0)
        .then(|| holzer_frequencies(&GearedChain::from(chain.clone())));
    let lr = lr_eigenvalues(chain, 1_000_000).ok();
    let damped = damped_modes(chain);
    let mut text = String::new();
    let _ = writeln!(text, "{name}");
    let _ = writeln!(text, "{n} disks, {} shafts\n", n - 1);
    chain_table(chain, &mut text);

    // Modes.
    let holzer_cpm: Option<Vec<f64>> = holzer
        .as_ref()
        .map(|h| h.iter().map(|w| w * CPM_PER_RAD_S).collect());
    let lr_cpm: Option<Vec<f64>> = lr.as_ref().map(|v| {
        v.iter()
            .map(|p2| p2.max(0.0).sqrt() * CPM_PER_RAD_S)
            .collect()
    });
    frequency_table(
        &modes,
        (holzer_cpm.as_deref(), lr_cpm.as_deref()),
        &mut text,
    );
    mode_shapes(&modes, &masses, &mut text);
    let modes_json: Vec<Value> = modes
        .iter()
        .enumerate()
        .map(|(r, m)| {
            json!({
                "index": r,
                "frequency_cpm": m.frequency_cpm(),
                "frequency_rad_s": m.omega,
                "rigid_body": m.is_rigid_body(),
                "shape": m.shape,
            })
        })
        .collect();

    let damped_json = damped_report(&damped, &mut text);

    let mut json = json!({
        "scenario": name,
        "kind": kind_name,
        "masses": masses,
        "shafts": shafts,
        "modes": modes_json,
        "frequency_checks": {
            "holzer_cpm": holzer_cpm,
            "lr_cpm": lr_cpm,
        },
        "damped_modes": damped_json,
        "real_eigenvalues": damped.real_eigenvalues,
    });

    if let Some(ex) = exc {
        forced_report(
            chain,
            &modes,
            ex,
            (speeds.as_deref(), rated),
            &mut text,
            &mut json,
        );
    }
    if let (Some(tc), Some(ex)) = (time_check, exc) {
        time_check_report(chain, ex, tc, &mut text, &mut json);
    }
    if let (Some(id), Some(ex)) = (ident, exc) {
        identification_report(file, id, ex, &mut text, &mut json)?;
    }
    Ok(Report { json, text })
}
