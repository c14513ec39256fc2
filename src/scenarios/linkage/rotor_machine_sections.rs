//! The `[rotor_balance]` and `[machine_motion]` sections: the rotor's masses and
//! correction planes (and the speed and bearings for the bearing loads), and the machine's
//! inertia (constant, tabulated or the linkage's own, a motor behind a gear ratio), drive
//! characteristic and time steps.

use crate::core::diag::{all_finite, LocatedError as ScenarioError};
use crate::machines::balancing::RotorMass;
use crate::machines::flywheel::machine_motion::Characteristic;
use crate::scenarios::linkage::linkage_scenario::{
    MachineScenario, MechanismScenario, RotorScenario,
};
use crate::scenarios::linkage::linkage_spec::{MachineSpec, RotorSpec};
use crate::scenarios::source::Source;
use toml::Spanned;

pub(super) fn parse_rotor(
    cx: &Source,
    r: &Spanned<RotorSpec>,
) -> Result<RotorScenario, ScenarioError> {
    let span = r.span();
    let s = r.get_ref();
    let n = s.masses.len();
    for (k, v) in [
        ("radii", &s.radii),
        ("angles_deg", &s.angles_deg),
        ("positions", &s.positions),
    ] {
        if v.len() != n {
            return Err(cx.err(
                cx.key_line(&span, k),
                format!("rotor_balance.{k}"),
                format!("has {} values, `masses` has {n}", v.len()),
            ));
        }
    }
    for (k, v) in [
        ("masses", &s.masses),
        ("radii", &s.radii),
        ("angles_deg", &s.angles_deg),
        ("positions", &s.positions),
        ("planes", &s.planes),
        ("plane_radii", &s.plane_radii),
    ] {
        if !all_finite(v) {
            return Err(cx.err(
                cx.key_line(&span, k),
                format!("rotor_balance.{k}"),
                "non-finite value",
            ));
        }
    }
    if n == 0 {
        return Err(cx.err(
            cx.key_line(&span, "masses"),
            "rotor_balance.masses",
            "no masses",
        ));
    }
    if s.planes.is_empty() || s.planes.len() > 2 || s.plane_radii.len() != s.planes.len() {
        return Err(cx.err(
            cx.key_line(&span, "planes"),
            "rotor_balance.planes",
            "give one (static) or two (dynamic) correction planes and as many `plane_radii`",
        ));
    }
    if s.plane_radii.iter().any(|&x| x <= 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "plane_radii"),
            "rotor_balance.plane_radii",
            "must be positive",
        ));
    }
    if s.planes.len() == 2 && s.planes[0] == s.planes[1] {
        return Err(cx.err(
            cx.key_line(&span, "planes"),
            "rotor_balance.planes",
            "the two planes coincide",
        ));
    }
    let bearings = match (s.speed_rpm, s.bearings) {
        (None, None) => None,
        (Some(n), Some([a, b])) => {
            if !(n.is_finite() && (0.0..=1e7).contains(&n)) {
                return Err(cx.err(
                    cx.key_line(&span, "speed_rpm"),
                    "rotor_balance.speed_rpm",
                    "must be a speed in [0, 1e7] rpm",
                ));
            }
            if !(a.is_finite() && b.is_finite() && a != b) {
                return Err(cx.err(
                    cx.key_line(&span, "bearings"),
                    "rotor_balance.bearings",
                    "give two different, finite bearing positions [z_A, z_B] (m)",
                ));
            }
            Some((n * std::f64::consts::PI / 30.0, [a, b]))
        }
        (Some(_), None) | (None, Some(_)) => {
            let k = if s.speed_rpm.is_some() {
                "speed_rpm"
            } else {
                "bearings"
            };
            return Err(cx.err(
                cx.key_line(&span, k),
                format!("rotor_balance.{k}"),
                "give speed_rpm and bearings = [z_A, z_B] together (for the bearing loads)",
            ));
        }
    };
    Ok(RotorScenario {
        bearings,
        masses: (0..n)
            .map(|k| RotorMass {
                mass: s.masses[k],
                radius: s.radii[k],
                angle: s.angles_deg[k].to_radians(),
                position: s.positions[k],
            })
            .collect(),
        planes: s
            .planes
            .iter()
            .copied()
            .zip(s.plane_radii.iter().copied())
            .collect(),
    })
}

pub(super) fn parse_machine(
    cx: &Source,
    m: &Spanned<MachineSpec>,
    mechanism: Option<&MechanismScenario>,
) -> Result<MachineScenario, ScenarioError> {
    let span = m.span();
    let s = m.get_ref();
    let (inertia, ratio, motor_inertia, inertia_table, from_linkage) =
        parse_machine_inertia(cx, &span, s, mechanism)?;
    if s.drive.is_empty() || !all_finite(&s.drive) {
        return Err(cx.err(
            cx.key_line(&span, "drive"),
            "machine_motion.drive",
            "give the coefficients of M_d(ω) = c0 + c1 ω + …",
        ));
    }
    if !(s.t_end.is_finite() && s.t_end > 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "t_end"),
            "machine_motion.t_end",
            "must be positive",
        ));
    }
    let dt = s.dt.unwrap_or(s.t_end / 1000.0);
    if !(dt.is_finite() && dt > 0.0) || s.t_end / dt > 1e7 {
        return Err(cx.err(
            cx.key_line(&span, "dt"),
            "machine_motion.dt",
            "must be positive (and at most 1e7 steps)",
        ));
    }
    if !(s.load.is_finite() && s.omega0.is_finite()) {
        return Err(cx.err(
            cx.line(&span),
            "machine_motion",
            "non-finite load or omega0",
        ));
    }
    Ok(MachineScenario {
        inertia,
        ratio,
        motor_inertia,
        inertia_table,
        inertia_from_linkage: from_linkage,
        drive: Characteristic(s.drive.clone()),
        load: s.load,
        omega0: s.omega0,
        t_end: s.t_end,
        dt,
    })
}

/// The machine-motion inertia keys: `(J_0, u, J_motor, table, from_linkage)`. Every
/// number finite; `J_0`, `J_motor` and the table's values non-negative, `u` positive;
/// the total at least somewhere positive; `inertia_from_linkage` needs a linkage driven
/// by an angle over a full turn.
#[allow(clippy::type_complexity)]
fn parse_machine_inertia(
    cx: &Source,
    span: &std::ops::Range<usize>,
    s: &MachineSpec,
    mechanism: Option<&MechanismScenario>,
) -> Result<(f64, f64, f64, Option<Vec<(f64, f64)>>, bool), ScenarioError> {
    let err = |key: &str, msg: &str| {
        cx.err(
            cx.key_line(span, key),
            format!("machine_motion.{key}"),
            msg.to_string(),
        )
    };
    let inertia = s.inertia.unwrap_or(0.0);
    if !(inertia.is_finite() && inertia >= 0.0) {
        return Err(err("inertia", "must be a finite number ≥ 0 (kg m²)"));
    }
    let ratio = s.ratio.unwrap_or(1.0);
    if !(ratio.is_finite() && ratio > 0.0 && (1e-6..=1e6).contains(&ratio)) {
        return Err(err(
            "ratio",
            "must be a positive number between 1e-6 and 1e6 (ω_motor / ω_machine)",
        ));
    }
    let motor_inertia = s.motor_inertia.unwrap_or(0.0);
    if !(motor_inertia.is_finite() && motor_inertia >= 0.0) {
        return Err(err("motor_inertia", "must be a finite number ≥ 0 (kg m²)"));
    }
    let table = match &s.inertia_deg {
        None => None,
        Some(rows) => {
            if rows.is_empty() {
                return Err(err("inertia_deg", "give at least one [angle_deg, J] row"));
            }
            for (k, r) in rows.iter().enumerate() {
                if !all_finite(r) || r[1] < 0.0 || !(0.0..360.0).contains(&r[0]) {
                    return Err(cx.err(
                        cx.key_line(span, "inertia_deg"),
                        format!("machine_motion.inertia_deg[{k}]"),
                        "each row is [angle_deg in [0, 360), J ≥ 0 (kg m²)]",
                    ));
                }
                if k > 0 && r[0] <= rows[k - 1][0] {
                    return Err(cx.err(
                        cx.key_line(span, "inertia_deg"),
                        format!("machine_motion.inertia_deg[{k}]"),
                        "the angles must increase",
                    ));
                }
            }
            Some(rows.iter().map(|r| (r[0].to_radians(), r[1])).collect())
        }
    };
    let from_linkage = s.inertia_from_linkage.unwrap_or(false);
    if from_linkage {
        if table.is_some() {
            return Err(err(
                "inertia_from_linkage",
                "give inertia_deg or inertia_from_linkage, not both",
            ));
        }
        let full_turn = mechanism.is_some_and(|m| {
            m.angle_input
                && ((m.sweep.to - m.sweep.from).abs() - std::f64::consts::TAU).abs() < 1e-9
        });
        if !full_turn {
            return Err(err(
                "inertia_from_linkage",
                "needs a linkage in the file driven by an angle over a full turn (sweep 360°)",
            ));
        }
    }
    let table_max = table.as_ref().map_or(0.0, |t: &Vec<(f64, f64)>| {
        t.iter().map(|r| r.1).fold(0.0, f64::max)
    });
    let table_min = table.as_ref().map_or(0.0, |t: &Vec<(f64, f64)>| {
        t.iter().map(|r| r.1).fold(f64::INFINITY, f64::min)
    });
    if inertia + motor_inertia * ratio * ratio + table_min <= 0.0 && !from_linkage {
        return Err(err(
            "inertia",
            if table_max > 0.0 {
                "the reduced inertia J_0 + J_motor u² + J_table(φ) must be positive at every angle"
            } else {
                "must be positive (or give motor_inertia, inertia_deg or inertia_from_linkage)"
            },
        ));
    }
    Ok((inertia, ratio, motor_inertia, table, from_linkage))
}
