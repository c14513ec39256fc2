//! The report of a `kind = "cam"` scenario: the follower's `s, v, a, jerk` and the
//! pressure angle over the turn, the pitch and working profiles with their curvature
//! checks (undercut of a roller, a negative radius under a flat face, concave parts under
//! a knife edge), the infinite-jerk points, and the minimum base radius and best offset
//! for given pressure-angle limits. JSON keys are listed in `docs/machines.md`.

use crate::io::report::Report;
use crate::machines::cams::eccentric::{
    eval as ecc_eval, initial_theta, Eccentric, EccentricFollower,
};
use crate::machines::cams::laws::Displacement;
use crate::machines::cams::motion_table::CamMotion;
use crate::machines::cams::profile::{
    min_flat_base_radius, min_prime_radius, optimum_offset, sample, CamFollower,
};
use serde_json::{json, Value};
use std::f64::consts::PI;
use std::fmt::Write;

/// The cam.
#[derive(Clone, Debug, PartialEq)]
pub enum Cam {
    /// Driven by a motion law.
    Law(CamMotion, CamFollower),
    /// An eccentric disc.
    Eccentric(Eccentric),
}

/// A parsed cam scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct CamScenario {
    /// Name.
    pub name: String,
    /// Cam speed (rad/s).
    pub omega: f64,
    /// Samples per turn.
    pub steps: usize,
    /// The cam.
    pub cam: Cam,
    /// Allowed pressure angles (rise, return), rad.
    pub limits: Option<(f64, f64)>,
}

fn extreme(values: &[f64], phis: &[f64], pick: impl Fn(usize) -> bool) -> Value {
    let best = (0..values.len())
        .filter(|&k| pick(k))
        .max_by(|&a, &b| values[a].abs().total_cmp(&values[b].abs()));
    match best {
        Some(k) => {
            json!({ "value_deg": values[k].abs().to_degrees(), "at_deg": phis[k].to_degrees() })
        }
        None => Value::Null,
    }
}

/// Angles (deg) where `s'` (order 1: infinite acceleration) or `s''` (order 2: infinite
/// jerk) jumps.
fn jumps(m: &CamMotion, order: usize) -> Vec<f64> {
    let mut out = Vec::new();
    let scale = m.derivative_scale(order);
    for x in m.breakpoints() {
        let (l, r) = (
            m.eval((x - 1e-9).rem_euclid(2.0 * PI))[order],
            m.eval(x + 1e-9)[order],
        );
        let deg = x.to_degrees().rem_euclid(360.0);
        if (l - r).abs() > 1e-6 * scale && !out.iter().any(|d: &f64| (d - deg).abs() < 1e-6) {
            out.push(deg);
        }
    }
    out
}

fn law_report(sc: &CamScenario, m: &CamMotion, f: &CamFollower, text: &mut String) -> Value {
    let w = sc.omega;
    let samples: Vec<_> = (0..=sc.steps)
        .map(|k| sample(m, f, 2.0 * PI * k as f64 / sc.steps as f64))
        .collect();
    let phis: Vec<f64> = samples.iter().map(|s| s.phi).collect();
    let alpha: Vec<f64> = samples.iter().map(|s| s.pressure_angle).collect();
    let rise = |k: usize| samples[k].s[1] > 1e-12;
    let ret = |k: usize| samples[k].s[1] < -1e-12;
    let roller = match *f {
        CamFollower::Translating { roller, .. } | CamFollower::Oscillating { roller, .. } => roller,
        CamFollower::Flat { .. } => 0.0,
    };
    let rho_min = samples
        .iter()
        .map(|s| s.rho_pitch)
        .filter(|r| *r > 0.0)
        .fold(f64::INFINITY, f64::min);
    // A straight flank of a given profile has ρ = ±∞ up to round-off (|ρ| ~ 1e10): only a
    // radius below 1e6 strokes counts.
    let flat_limit = 1e6 * m.stroke();
    let negative = |r: f64| r < 0.0 && r > -flat_limit;
    let rho_min = if rho_min > flat_limit {
        f64::INFINITY
    } else {
        rho_min
    };
    let concave = samples.iter().any(|s| negative(s.rho_pitch));
    let undercut = match f {
        CamFollower::Flat { .. } => samples.iter().any(|s| negative(s.rho_pitch)),
        _ => roller > 0.0 && rho_min < roller,
    };
    let mut summary = json!({
        "stroke": m.stroke(),
        "max_pressure_angle": { "rise": extreme(&alpha, &phis, rise), "return": extreme(&alpha, &phis, ret) },
        "min_convex_rho_pitch": if rho_min.is_finite() { json!(rho_min) } else { Value::Null },
        "min_convex_rho_working": if rho_min.is_finite() { json!(rho_min - roller) } else { Value::Null },
        "concave_parts": concave,
        "undercut": undercut,
        "infinite_acceleration_at_deg": jumps(m, 1),
        "infinite_jerk_at_deg": jumps(m, 2),
    });
    if let CamFollower::Flat { face_angle, .. } = f {
        summary["min_flat_base_radius"] =
            json!(min_flat_base_radius(m, *face_angle, sc.steps.max(3600)));
    }
    if let (Some((ar, aret)), CamFollower::Translating { offset, .. }) = (sc.limits, f) {
        let n = sc.steps.max(3600);
        let (e_opt, r_opt) = optimum_offset(m, ar, aret, n);
        summary["min_base_radius"] = json!(min_prime_radius(m, *offset, ar, aret, n));
        summary["optimum_offset"] = json!({ "offset": e_opt, "base_radius": r_opt });
    }
    if let (Some((ar, _)), CamFollower::Oscillating { arm, .. }) = (sc.limits, f) {
        let x = arm * (0..=sc.steps).map(|k| samples[k].s[1]).fold(0.0, f64::max);
        summary["book_lowest_position_radius"] = json!(x / ar.tan());
    }
    let _ = writeln!(
        text,
        "Stroke {:.4}; max pressure angle rise {} / return {}",
        m.stroke(),
        crate::io::report::human_json(&summary["max_pressure_angle"]["rise"]),
        crate::io::report::human_json(&summary["max_pressure_angle"]["return"])
    );
    let _ = writeln!(
        text,
        "Smallest convex radius of curvature: pitch {rho_min:.4}, working {:.4}{}{}",
        rho_min - roller,
        if undercut { "  UNDERCUT (cusp)" } else { "" },
        if concave {
            "; the profile has concave parts"
        } else {
            ""
        }
    );
    for k in [
        "min_flat_base_radius",
        "min_base_radius",
        "optimum_offset",
        "book_lowest_position_radius",
        "infinite_acceleration_at_deg",
        "infinite_jerk_at_deg",
    ] {
        if let Some(v) = summary.get(k) {
            let _ = writeln!(text, "{k}: {}", crate::io::report::human_json(v));
        }
    }
    json!({
        // What `s` measures: the follower's travel (translating, flat) or its swing in rad.
        "follower_motion": if matches!(f, CamFollower::Oscillating { .. }) { "oscillating" } else { "translating" },
        "samples": {
            "phi_deg": phis.iter().map(|p| p.to_degrees()).collect::<Vec<_>>(),
            "s": samples.iter().map(|s| s.s[0]).collect::<Vec<_>>(),
            "v": samples.iter().map(|s| w * s.s[1]).collect::<Vec<_>>(),
            "a": samples.iter().map(|s| w * w * s.s[2]).collect::<Vec<_>>(),
            "jerk": samples.iter().map(|s| w * w * w * s.s[3]).collect::<Vec<_>>(),
            "pressure_angle_deg": alpha.iter().map(|a| a.to_degrees()).collect::<Vec<_>>(),
            "rho_pitch": samples.iter().map(|s| if s.rho_pitch.is_finite() { json!(s.rho_pitch) } else { Value::Null }).collect::<Vec<_>>(),
        },
        "profile": {
            "pitch": samples.iter().map(|s| s.pitch).collect::<Vec<_>>(),
            "working": samples.iter().map(|s| s.working).collect::<Vec<_>>(),
        },
        "summary": summary,
    })
}

fn eccentric_report(sc: &CamScenario, c: &Eccentric, text: &mut String) -> Value {
    let n = sc.steps;
    let mut theta = initial_theta(c);
    let (mut s, mut alpha, mut phis) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..=n {
        let phi = 2.0 * PI * k as f64 / n as f64;
        if let Some((x, a)) = ecc_eval(c, phi, theta) {
            theta = x;
            s.push(x);
            alpha.push(a);
            phis.push(phi);
        }
    }
    let oscillating = matches!(c.follower, EccentricFollower::OscillatingFlat { .. });
    let lo = s.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = s.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let all = |_: usize| true;
    let max_alpha = extreme(&alpha, &phis, all);
    let _ = writeln!(
        text,
        "Eccentric disc R = {}, a = {}: {} {:.4}{}; max pressure angle {}",
        c.radius,
        c.eccentricity,
        if oscillating { "swing" } else { "stroke" },
        if oscillating {
            (hi - lo).to_degrees()
        } else {
            hi - lo
        },
        if oscillating { "°" } else { "" },
        crate::io::report::human_json(&max_alpha)
    );
    let mut v = json!({
        "samples": {
            "phi_deg": phis.iter().map(|p| p.to_degrees()).collect::<Vec<_>>(),
            "pressure_angle_deg": alpha.iter().map(|a| a.to_degrees()).collect::<Vec<_>>(),
        },
        "summary": { "max_pressure_angle": max_alpha },
    });
    if oscillating {
        v["samples"]["face_angle_deg"] =
            json!(s.iter().map(|x| x.to_degrees()).collect::<Vec<_>>());
        v["summary"]["swing_deg"] = json!((hi - lo).to_degrees());
    } else {
        v["samples"]["s"] = json!(s);
        v["summary"]["stroke"] = json!(hi - lo);
    }
    v
}

/// The report (see the module docs).
pub fn report(sc: &CamScenario, kind_name: &str) -> Report {
    let mut text = format!("Cam '{}'\n", sc.name);
    let (body, kind) = match &sc.cam {
        Cam::Law(m, f) => (
            law_report(sc, m, f, &mut text),
            if matches!(m, CamMotion::Profile(_)) {
                "profile"
            } else {
                "law"
            },
        ),
        Cam::Eccentric(c) => (eccentric_report(sc, c, &mut text), "eccentric"),
    };
    let mut json =
        json!({ "scenario": sc.name, "kind": kind_name, "cam": kind, "omega_rad_s": sc.omega });
    if let (Value::Object(dst), Value::Object(src)) = (&mut json, body) {
        dst.extend(src);
    }
    Report { json, text }
}
