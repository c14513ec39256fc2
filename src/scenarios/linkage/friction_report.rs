//! The `friction` part of a linkage scenario's kinetostatics (`[kinetostatics]`
//! `friction_coefficient`, `pin_radius`, `pin_radii`): every joint with friction circles
//! ([`crate::machines::friction::friction_circle`]) at every sample of the sweep; the driving
//! effort with and without friction, the friction power and the instantaneous efficiency at the
//! reported inputs, and over a full turn the works of the driver and of friction per turn and the
//! cycle efficiency `1 − W_f/W_d` (powers summed over equal steps of the input, i.e. equal
//! times at constant speed).

use crate::machines::friction::friction_circle::{solve_with_friction, JointFriction};
use crate::machines::friction::two_point_guide::{solve_with_guides, TwoPointGuide};
use crate::machines::linkage::description::{Linkage, PlanarJoint};
use crate::machines::linkage::kinetostatics::Loads;
use crate::scenarios::linkage::linkage_scenario::PinFriction;
use nalgebra::DVector;
use serde_json::{json, Value};
use std::fmt::Write;

/// One sample: input `s` and `(q, q̇, q̈)`.
pub type FrictionSample<'a> = (f64, &'a DVector<f64>, &'a DVector<f64>, &'a DVector<f64>);

/// Iteration limits of the friction solve.
const TOL: f64 = 1e-10;
const MAX_ITER: usize = 100;

/// The report (JSON value and summary lines); `speed` is the driver's rate, `report_at`
/// the inputs listed, `full_turn` whether the samples cover one turn of the crank,
/// `angle_input` whether the input is an angle (shown in degrees; else metres).
#[allow(clippy::too_many_arguments)]
pub fn report(
    l: &Linkage,
    samples: &[FrictionSample],
    loads: &Loads,
    speed: f64,
    pins: &PinFriction,
    report_at: &[f64],
    (full_turn, angle_input): (bool, bool),
    guides: &[TwoPointGuide],
    text: &mut String,
) -> Value {
    let coefficient = pins.coefficient;
    let fr: Vec<JointFriction> = (0..l.joints.len())
        .map(|joint| JointFriction {
            joint,
            coefficient: match &l.joints[joint] {
                PlanarJoint::Contact(c) => c.friction.unwrap_or(coefficient),
                _ => coefficient,
            },
            pin_radius: pins.radii[joint],
        })
        .collect();
    let (mut wd, mut wf, mut worst, mut all_converged, mut most) =
        (0.0, 0.0, f64::INFINITY, true, 0);
    let mut at = Vec::new();
    let mut jams = Vec::new();
    for (k, &(s, q, qd, qdd)) in samples.iter().enumerate() {
        let gf = (!guides.is_empty())
            .then(|| solve_with_guides(l, (q, qd, qdd), loads, speed, &fr, guides, TOL, MAX_ITER));
        let w = match &gf {
            Some(g) => g.with.clone(),
            None => solve_with_friction(l, q, qd, qdd, loads, speed, &fr, TOL, MAX_ITER),
        };
        let jammed = gf.as_ref().is_some_and(|g| g.jammed);
        if jammed {
            jams.push(if angle_input { s.to_degrees() } else { s });
        }
        all_converged &= w.converged;
        most = most.max(w.iterations);
        // The last sample of a full turn repeats the first.
        if !(full_turn && k + 1 == samples.len() && samples.len() > 1) {
            wd += w.driving_power;
            wf += w.friction_power;
        }
        if let Some(e) = w.efficiency {
            worst = worst.min(e);
        }
        if report_at
            .iter()
            .any(|r| (r - s).abs() < 1e-9 * (1.0 + r.abs()))
        {
            let shown = if angle_input {
                format!("{:.4}°", s.to_degrees())
            } else {
                format!("{s:.6} m")
            };
            if jammed {
                let _ = writeln!(
                    text,
                    "  friction at input {shown}: the guide jams (self-locking: no driving effort overcomes the friction of its two bearing points); ideal driving {:.6}",
                    w.ideal.driving
                );
            } else {
                let _ = writeln!(
                    text,
                    "  friction at input {shown}: driving {:.6} (ideal {:.6}), friction power {:.4} W, efficiency {}",
                    w.real.driving,
                    w.ideal.driving,
                    w.friction_power,
                    w.efficiency.map_or("– (the driver does no work)".into(), |e| format!("{e:.6}"))
                );
            }
            let mut guide_json = Vec::new();
            for (r, f) in gf.iter().flat_map(|g| g.reactions.iter().zip(&g.friction)) {
                if jammed {
                    break;
                }
                let _ = writeln!(
                    text,
                    "    guide {}: N_a = {:.6} N, N_b = {:.6} N, friction f(|N_a| + |N_b|) = {:.6} N",
                    l.joints[r.joint].name(),
                    r.forces[0],
                    r.forces[1],
                    f
                );
                guide_json.push(
                    json!({"joint": l.joints[r.joint].name(), "normal_forces": r.forces,
                    "points": [[r.points[0].x, r.points[0].y], [r.points[1].x, r.points[1].y]],
                    "friction_force": f}),
                );
            }
            let contact_forces =
                crate::scenarios::linkage::contacts_report::forces_json(l, q, qd, &w.real, &|c| {
                    c.friction.unwrap_or(coefficient)
                });
            if !guides.is_empty() {
                at.push(json!({
                    "contact_forces": contact_forces,
                    "input": s,
                    "driving_ideal": w.ideal.driving,
                    "driving": (!jammed).then_some(w.real.driving),
                    "friction_power": (!jammed).then_some(w.friction_power),
                    "driving_power": (!jammed).then_some(w.driving_power),
                    "efficiency": w.efficiency,
                    "iterations": w.iterations,
                    "converged": w.converged,
                    "jammed": jammed,
                    "guide_contacts": guide_json,
                }));
                continue;
            }
            at.push(json!({
                "contact_forces": contact_forces,
                "input": s,
                "driving_ideal": w.ideal.driving,
                "driving": w.real.driving,
                "friction_power": w.friction_power,
                "driving_power": w.driving_power,
                "efficiency": w.efficiency,
                "iterations": w.iterations,
                "converged": w.converged,
            }));
        }
    }
    let cycle = (full_turn && wd > 0.0 && jams.is_empty()).then(|| 1.0 - wf / wd);
    // Works per turn: powers times the time of one input step at constant speed.
    let dt = match samples {
        [a, b, ..] if speed != 0.0 => ((b.0 - a.0) / speed).abs(),
        _ => 0.0,
    };
    if let Some(c) = cycle {
        let _ = writeln!(
            text,
            "  friction over the turn: efficiency 1 − W_f/W_d = {c:.6}"
        );
    }
    let named: serde_json::Map<String, Value> = pins
        .named
        .iter()
        .map(|(n, r)| (n.clone(), json!(r)))
        .collect();
    json!({
        "coefficient": coefficient,
        "pin_radius": pins.default_radius,
        "friction_circle_radius": coefficient * pins.default_radius,
        "pin_radii": named,
        "at": at,
        "cycle_efficiency": cycle,
        "work_per_turn": full_turn.then(|| json!({ "driver": wd * dt, "friction": wf * dt })),
        "min_efficiency": worst.is_finite().then_some(worst),
        "all_converged": all_converged,
        "jammed_at": jams,
        "max_iterations": most,
    })
}
