//! Flexible rotors (`kind = "flexible_rotor"`): docs/reference_data.md §M7's checkpoints through
//! `armsim run --json`, finite elements against exact transfer matrices and the
//! pinned–pinned closed form, the direct unbalance response against modal superposition,
//! and located errors for broken files.

use armsim::machines::vibration::rotor::{
    fe_modes, pinned_pinned_speed, unbalance_response, Bearing, Disc, FlexibleRotor, Segment,
};
use armsim::machines::vibration::rotor_transfer::critical_speeds;
use serde_json::Value;

mod common;
use common::run_json;

fn close(a: &Value, b: f64, tol: f64, what: &str) {
    let a = a
        .as_f64()
        .unwrap_or_else(|| panic!("{what}: not a number: {a}"));
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

#[test]
fn uniform_shaft_critical_speed_is_283_6_rad_s() {
    let v = run_json("scenarios/flexible_rotor_uniform_shaft.toml");
    let m = &v["modes"];
    close(&m[0]["omega"], 283.6, 0.05, "ω1");
    close(&m[0]["rpm"], 2708.0, 0.5, "n1");
    close(&v["rigid_limit"], 227.0, 0.5, "0.8 ω1");
    assert_eq!(v["rigid"], false, "3000 rpm is above 0.8 ω1");
    // Closed form, written out: I = π d⁴/64, μ = ρ π d²/4.
    let (e, rho, d, l): (f64, f64, f64, f64) = (2.1e11, 7850.0, 0.05, 1.5);
    let i = std::f64::consts::PI * d.powi(4) / 64.0;
    let mu = rho * std::f64::consts::PI * d * d / 4.0;
    for n in 1..=3 {
        let exact = pinned_pinned_speed(n, e * i, mu, l);
        let fe = m[n - 1]["omega"].as_f64().unwrap();
        let tm = m[n - 1]["transfer_matrix_omega"].as_f64().unwrap();
        assert!(
            (tm - exact).abs() < 1e-9 * exact,
            "TM mode {n}: {tm} vs {exact}"
        );
        assert!(
            (fe - exact).abs() < 1e-5 * exact,
            "FE mode {n}: {fe} vs {exact}"
        );
    }
    close(
        &Value::from(m[1]["omega"].as_f64().unwrap() / m[0]["omega"].as_f64().unwrap()),
        4.0,
        1e-6,
        "ω2/ω1",
    );
}

#[test]
fn modal_balancing_masses_match_the_closed_forms() {
    let v = run_json("scenarios/flexible_rotor_modal_balancing.toml");
    let u = 1.0 / (2.0 * (72f64.to_radians().sin() - 36f64.to_radians().sin()));
    let x = &v["modal_balancing"]["masses"];
    for (k, want) in [u, -u, -u, u].iter().enumerate() {
        close(&x[k], *want, 1e-6, "mode 1 mass");
    }
    close(&x[0], 1.37638, 5e-6, "book-style value");
    let v = run_json("scenarios/flexible_rotor_modal_balancing_mode2.toml");
    let u = 1.0 / (2.0 * (3.0 * 36f64.to_radians().sin() - 72f64.to_radians().sin()));
    let x = &v["modal_balancing"]["masses"];
    for (k, want) in [u, -3.0 * u, 3.0 * u, -u].iter().enumerate() {
        close(&x[k], *want, 1e-6, "mode 2 mass");
    }
    close(&x[0], 0.61554, 5e-6, "book-style value");
    close(&v["modal_balancing"]["force_sum"], 0.0, 1e-12, "Σ X");
    close(&v["modal_balancing"]["moment_sum"], 0.0, 1e-12, "Σ x X");
}

fn overhung() -> FlexibleRotor {
    FlexibleRotor {
        segments: vec![
            Segment::circular(0.7, 0.06, 0.0, 2.1e11, 7850.0),
            Segment::circular(0.5, 0.04, 0.0, 2.1e11, 7850.0),
        ],
        discs: vec![
            Disc {
                at: 0.4,
                mass: 25.0,
                unbalance: 2.5e-4,
                phase: 0.0,
            },
            Disc {
                at: 1.2,
                mass: 8.0,
                unbalance: 1.0e-4,
                phase: 1.0,
            },
        ],
        bearings: vec![
            Bearing {
                at: 0.0,
                stiffness: None,
            },
            Bearing {
                at: 0.9,
                stiffness: Some(5e7),
            },
        ],
    }
}

#[test]
fn stepped_rotor_finite_elements_agree_with_transfer_matrices_and_converge() {
    let r = overhung();
    let fe = fe_modes(&r, 200, 3).unwrap();
    let tm = critical_speeds(&r, fe[2].omega * 1.2, 4000);
    for k in 0..3 {
        assert!(
            (fe[k].omega - tm[k]).abs() < 1e-6 * tm[k],
            "mode {k}: {} vs {}",
            fe[k].omega,
            tm[k]
        );
    }
    // h⁴ convergence: 4× the elements cut the error of mode 3 by well over 100.
    let e10 = (fe_modes(&r, 10, 3).unwrap()[2].omega - tm[2]).abs();
    let e40 = (fe_modes(&r, 40, 3).unwrap()[2].omega - tm[2]).abs();
    assert!(e10 / e40 > 100.0, "{e10} / {e40}");
    // An interior rigid bearing (three supports): both routes again.
    let mut r3 = overhung();
    r3.bearings.push(Bearing {
        at: 0.55,
        stiffness: None,
    });
    let fe = fe_modes(&r3, 200, 2).unwrap();
    let tm = critical_speeds(&r3, fe[1].omega * 1.2, 4000);
    for k in 0..2 {
        assert!(
            (fe[k].omega - tm[k]).abs() < 1e-6 * tm[k],
            "3 bearings, mode {k}"
        );
    }
}

#[test]
fn unbalance_response_equals_modal_superposition() {
    let r = overhung();
    let elements = 60;
    let omega = 2000.0 * std::f64::consts::PI / 30.0;
    let (x, amp) = unbalance_response(&r, elements, omega).unwrap();
    // Every mode: y = Σ φ (φᵀ F) / (m_n (ω_n² − ω²)), for the in-phase and quadrature parts.
    let modes = fe_modes(&r, elements, 10_000).unwrap();
    let node = |p: f64| x.iter().position(|&v| (v - p).abs() < 1e-12).unwrap();
    let mut y = [vec![0.0; x.len()], vec![0.0; x.len()]];
    for m in &modes {
        for (part, yy) in y.iter_mut().enumerate() {
            let f: f64 = r
                .discs
                .iter()
                .map(|d| {
                    let c = if part == 0 {
                        d.phase.cos()
                    } else {
                        d.phase.sin()
                    };
                    m.y[node(d.at)] * omega * omega * d.unbalance * c
                })
                .sum();
            let q = f / (m.modal_mass * (m.omega * m.omega - omega * omega));
            for (k, v) in yy.iter_mut().enumerate() {
                *v += m.y[k] * q;
            }
        }
    }
    for k in 0..x.len() {
        let a = y[0][k].hypot(y[1][k]);
        assert!(
            (a - amp[k]).abs() < 1e-6 * amp.iter().fold(0.0f64, |m, v| m.max(*v)),
            "node {k}: {a} vs {}",
            amp[k]
        );
    }
    // Through the scenario: the response peaks between the speeds around ω1.
    let v = run_json("scenarios/flexible_rotor_disc_overhang.toml");
    assert_eq!(v["response"].as_array().unwrap().len(), 12);
    let tm = v["modes"][0]["transfer_matrix_omega"].as_f64().unwrap();
    close(
        &v["modes"][0]["omega"],
        tm,
        1e-6 * tm,
        "FE vs TM in the scenario",
    );
}

const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "flexible_rotor_bearing_off_shaft.toml",
        12,
        "bearings[1].at",
        "outside the shaft",
    ),
    (
        "flexible_rotor_negative_disc_mass.toml",
        10,
        "discs[0].mass",
        "must not be negative",
    ),
    (
        "flexible_rotor_negative_speed.toml",
        15,
        "response.speeds_rpm[1]",
        "must be positive",
    ),
    (
        "flexible_rotor_no_material.toml",
        3,
        "shaft",
        "youngs_modulus",
    ),
    (
        "flexible_rotor_no_segments.toml",
        6,
        "shaft.segments",
        "at least one segment",
    ),
    (
        "flexible_rotor_one_bearing.toml",
        8,
        "bearings",
        "at least two bearings",
    ),
    (
        "flexible_rotor_plane_count.toml",
        15,
        "modal_balancing.planes",
        "4 needed",
    ),
    (
        "flexible_rotor_inner_diameter_without_diameter.toml",
        6,
        "shaft.segments[0].inner_diameter",
        "does not apply",
    ),
    (
        "flexible_rotor_segment_ambiguous.toml",
        6,
        "shaft.segments[0]",
        "give either",
    ),
    (
        "flexible_rotor_too_many_elements.toml",
        15,
        "analysis.elements",
        "must lie in",
    ),
    (
        "flexible_rotor_unknown_key.toml",
        7,
        "shaft.length",
        "unknown field",
    ),
    (
        "flexible_rotor_unknown_mode.toml",
        16,
        "modal_balancing.mode",
        "not among",
    ),
    (
        "flexible_rotor_zero_stiffness.toml",
        13,
        "bearings[1].stiffness",
        "must be positive",
    ),
    (
        "flexible_rotor_material_without_diameter.toml",
        6,
        "shaft.youngs_modulus",
        "applies to segments given by `diameter` only",
    ),
];

#[test]
fn broken_flexible_rotor_scenarios_give_located_errors() {
    common::assert_broken_scenarios("flexible_rotor_", BROKEN, common::CheckSays::SameKey);
}

/// Issue 28: a response speed exactly at a critical speed gives the documented
/// `"critical": true` row (with the mode), never a null amplification.
#[test]
fn response_at_a_critical_speed_is_marked_critical() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let src = root.join("scenarios/flexible_rotor_disc_overhang.toml");
    let first = armsim::scenarios::run_file(&src).unwrap();
    let rpm = first.json["modes"][0]["rpm"].as_f64().unwrap();
    let text = std::fs::read_to_string(&src).unwrap();
    let line = text.lines().find(|l| l.starts_with("speeds_rpm")).unwrap();
    let text = text.replace(line, &format!("speeds_rpm = [1000.0, {rpm:?}]"));
    let dir = std::env::temp_dir().join(format!("armsim_critical_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("critical.toml");
    std::fs::write(&p, text).unwrap();
    let r = armsim::scenarios::run_file(&p).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    let rows = r.json["response"].as_array().unwrap();
    assert!(rows[0]["amplification"]
        .as_array()
        .unwrap()
        .iter()
        .all(|a| a.is_f64()));
    assert_eq!(rows[1]["critical"], true, "{}", rows[1]);
    assert_eq!(rows[1]["critical_mode"], 1, "{}", rows[1]);
    assert!(rows[1].get("amplification").is_none(), "{}", rows[1]);
}

/// Speeds given as multiples of ω1 (`response.speed_ratios`): each row's first-mode
/// amplification is the closed form `r²/(1 − r²)`, its `frequency_ratio` is `r`, and the
/// rows equal those of the same speeds given in rpm (ω1 from the first run).
#[test]
fn response_speeds_as_multiples_of_the_first_critical_speed() {
    let v = run_json("scenarios/flexible_rotor_speed_ratios.toml");
    let w1 = v["modes"][0]["omega"].as_f64().unwrap();
    let rows = v["response"].as_array().unwrap();
    let ratios = [0.5, 0.8, 1.2, 2.0];
    assert_eq!(rows.len(), ratios.len());
    for (row, r) in rows.iter().zip(ratios) {
        close(&row["frequency_ratio"], r, 1e-12, "ω/ω1");
        close(
            &row["amplification"][0],
            r * r / (1.0 - r * r),
            1e-9,
            "first-mode amplification",
        );
        close(
            &row["speed_rpm"],
            r * w1 * 30.0 / std::f64::consts::PI,
            1e-9,
            "rpm",
        );
    }
    // The same speeds in rpm give the same rows.
    let path = common::root().join("scenarios/flexible_rotor_speed_ratios.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let rpm: Vec<String> = ratios
        .iter()
        .map(|r| format!("{:.17e}", r * w1 * 30.0 / std::f64::consts::PI))
        .collect();
    let by_rpm = text.replace(
        "speed_ratios = [0.5, 0.8, 1.2, 2.0]",
        &format!("speeds_rpm = [{}]", rpm.join(", ")),
    );
    assert_ne!(by_rpm, text);
    let dir = std::env::temp_dir().join(format!("armsim_ratios_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let copy = dir.join("by_rpm.toml");
    std::fs::write(&copy, by_rpm).unwrap();
    let w = common::cli_json(&["run", copy.to_str().unwrap(), "--json"]);
    std::fs::remove_dir_all(&dir).ok();
    for (a, b) in rows.iter().zip(w["response"].as_array().unwrap()) {
        let (x, y) = (
            a["max_amplitude"].as_f64().unwrap(),
            b["max_amplitude"].as_f64().unwrap(),
        );
        assert!((x - y).abs() <= 1e-9 * x.abs(), "{x} vs {y}");
    }
}
