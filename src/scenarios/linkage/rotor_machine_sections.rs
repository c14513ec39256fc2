//! The `[rotor_balance]` and `[machine_motion]` sections: the rotor's masses and
//! correction planes (and the speed and bearings for the bearing loads), and the machine's inertia, drive characteristic and time steps.

use crate::core::diag::{all_finite, LocatedError as ScenarioError};
use crate::machines::balancing::RotorMass;
use crate::machines::flywheel::machine_motion::Characteristic;
use crate::scenarios::linkage::linkage_scenario::{MachineScenario, RotorScenario};
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
) -> Result<MachineScenario, ScenarioError> {
    let span = m.span();
    let s = m.get_ref();
    if !(s.inertia.is_finite() && s.inertia > 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "inertia"),
            "machine_motion.inertia",
            "must be positive",
        ));
    }
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
        inertia: s.inertia,
        drive: Characteristic(s.drive.clone()),
        load: s.load,
        omega0: s.omega0,
        t_end: s.t_end,
        dt,
    })
}
