//! Vibration isolation (`kind = "isolation"`): docs/reference_data.md §M8's checkpoints through
//! `armsim run --json`, the closed forms against numerical peak searches, the impact
//! formula against an RK4 run, Den Hartog's formula against a direct two-mass solve, and
//! located errors for broken files.

use armsim::machines::vibration::isolator as iso;
use serde_json::Value;

mod common;
use common::run_json;

fn close(a: &Value, b: f64, tol: f64, what: &str) {
    let a = a
        .as_f64()
        .unwrap_or_else(|| panic!("{what}: not a number: {a}"));
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

/// Golden-section search for the maximum of `f` on `[a, b]`.
fn argmax(f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64) -> (f64, f64) {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let (c, d) = (b - r * (b - a), a + r * (b - a));
        if f(c) > f(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let x = 0.5 * (a + b);
    (x, f(x))
}

#[test]
fn absorber_mu_0_2_invariant_points_heights_and_optimum() {
    let v = run_json("scenarios/isolation_absorber.toml");
    let a = &v["absorber"];
    close(&a["optimum_tuning"], 0.8333, 5e-5, "f opt");
    close(&a["invariant_points"][0], 0.7629, 5e-5, "q1");
    close(&a["invariant_points"][1], 1.0414, 5e-5, "q2");
    let (q1, q2) = (
        a["invariant_points"][0].as_f64().unwrap(),
        a["invariant_points"][1].as_f64().unwrap(),
    );
    assert!((1.2 * (q1 * q1 + q2 * q2) - 2.0).abs() < 1e-12);
    close(&a["invariant_heights"][0], 3.317, 5e-4, "height 1");
    close(
        &a["invariant_heights"][1],
        (1.0f64 + 2.0 / 0.2).sqrt(),
        1e-9,
        "height 2 = sqrt(1 + 2/μ)",
    );
    close(&a["rigid_resonance"], 0.9129, 5e-5, "rigid absorber");
    close(&a["optimum_damping"], 0.2083, 5e-5, "Den Hartog ζ");
    // Invariance: at q1, q2 the amplitude does not depend on the damping.
    for q in [q1, q2] {
        for z in [0.0, 0.05, 0.3, 5.0] {
            let h = iso::absorber_amplitude(q, 0.2, 1.0 / 1.2, z);
            assert!((h - 11f64.sqrt()).abs() < 1e-9, "q {q} ζ {z}: {h}");
        }
    }
    // Den Hartog's formula equals the direct two-mass solve.
    for r in a["response"].as_array().unwrap() {
        close(
            &r["amplitude_factor"],
            r["amplitude_factor_direct"].as_f64().unwrap(),
            1e-9,
            "formula vs direct",
        );
    }
    // The optimally damped response peaks only slightly above the invariant height.
    let peak = a["peak"]["amplitude_factor"].as_f64().unwrap();
    assert!(
        peak >= 11f64.sqrt() - 1e-9 && peak < 11f64.sqrt() * 1.01,
        "{peak}"
    );
}

#[test]
fn transmissibility_values_and_peaks() {
    let v = run_json("scenarios/isolation_transmissibility.toml");
    let c = &v["curves"];
    let e1 = &c[0];
    close(
        &e1["at"][0]["transmissibility"],
        0.14537,
        5e-6,
        "TR(3), ε 0.1",
    );
    close(&e1["at"][1]["transmissibility"], 1.0, 1e-12, "TR(√2)");
    close(&e1["peak"]["q"], 0.99033, 5e-6, "q*");
    close(&e1["peak"]["transmissibility"], 5.123, 5e-4, "TR peak");
    close(
        &e1["amplitude_peak"]["q"],
        0.98995,
        5e-6,
        "amplitude peak q",
    );
    close(
        &e1["amplitude_peak"]["amplitude_factor"],
        5.025,
        5e-4,
        "amplitude peak",
    );
    close(&e1["at"][1]["unbalance_force_ratio"], 2.0, 1e-9, "R0/Q(√2)");
    close(
        &e1["at"][2]["unbalance_force_ratio"],
        1.472,
        5e-4,
        "R0/Q(5)",
    );
    let e3 = &c[1];
    close(&e3["peak"]["q"], 0.93018, 5e-6, "q*, ε 0.3");
    close(
        &e3["peak"]["transmissibility"],
        1.995,
        5e-4,
        "TR peak, ε 0.3",
    );
    close(
        &e3["at"][0]["transmissibility"],
        0.2511,
        5e-5,
        "TR(3), ε 0.3",
    );
    // The closed-form peaks against a golden-section search.
    for eps in [0.05, 0.1, 0.3, 0.6] {
        let (q, t) = argmax(&|q| iso::transmissibility(q, eps), 0.1, 1.4);
        let (qc, tc) = iso::transmissibility_peak(eps);
        assert!((q - qc).abs() < 1e-6 && (t - tc).abs() < 1e-9, "ε {eps}");
        if eps < 0.7 {
            let (q, a) = argmax(&|q| iso::amplitude_factor(q, eps), 0.0, 1.4);
            let (qc, ac) = iso::amplitude_peak(eps);
            assert!((q - qc).abs() < 1e-6 && (a - ac).abs() < 1e-9, "ε {eps}");
        }
    }
    // Rubber: resonance exactly at q = 1.
    let (q, _) = argmax(&|q| iso::transmissibility_hysteretic(q, 0.1), 0.2, 1.4);
    assert!((q - 1.0).abs() < 1e-6);
}

#[test]
fn isolator_selection_for_tr_0_1_at_1500_rpm() {
    let v = run_json("scenarios/isolation_selection.toml");
    let s = &v["selection"];
    close(&s["frequency_ratio_min"], 3.317, 5e-4, "q");
    close(&s["natural_frequency_max"], 47.36, 5e-3, "p");
    close(&s["stiffness_max"], 1.12e6, 5e3, "c");
    close(
        &s["static_deflection_min"],
        4.37e-3,
        5e-6,
        "static deflection",
    );
    // The mount built with that stiffness transmits 10 % of the force.
    close(
        &v["mount"]["excitation"]["transmissibility"],
        0.1,
        1e-4,
        "TR of the chosen mount",
    );
    // With damping, the bisection meets TR = target exactly.
    let q = iso::required_ratio(0.1, 0.2).unwrap();
    assert!((iso::transmissibility(q, 0.2) - 0.1).abs() < 1e-12);
}

#[test]
fn impact_peak_closed_form_agrees_with_rk4_and_the_optimum() {
    let v = run_json("scenarios/isolation_impact.toml");
    let i = &v["impact"];
    close(
        &i["velocity"],
        1.5 * 200.0 * 5.0 / 2200.0,
        1e-12,
        "v after the blow",
    );
    close(
        &i["peak_force_ratio"],
        i["peak_force_ratio_by_integration"].as_f64().unwrap(),
        1e-6,
        "R max",
    );
    for eps in [0.05, 0.2, 0.45, 0.5, 0.8] {
        let rk = iso::impact_peak_by_integration(eps, 200_000).0;
        assert!((rk - iso::impact_peak(eps)).abs() < 1e-6, "ε {eps}");
    }
    let (th, eo) = iso::impact_optimum();
    assert!(((2.0 * th).sin() + 2.0 * th - std::f64::consts::PI / 3.0).abs() < 1e-12);
    close(&i["optimum"]["damping_ratio"], eo, 1e-12, "optimum ε");
}

/// The damping sweep of a shock mount: each ratio's peak by (17.44) (`2ε` from 0.5 on,
/// the force at t = 0) written out here, the RK4 run agreeing, and the least peak of the
/// sweep at the optimum `sin 2θ + 2θ = π/3`.
#[test]
fn impact_damping_sweep_follows_17_44_and_is_least_at_the_optimum() {
    let v = run_json("scenarios/isolation_impact_damping_sweep.toml");
    let i = &v["impact"];
    assert!(
        i.get("peak_force").is_none(),
        "no single damping ratio given"
    );
    let rows = i["sweep"].as_array().unwrap();
    assert_eq!(rows.len(), 10);
    let (m, p, vel) = (
        2000.0,
        (4.0e7_f64 / 2000.0).sqrt(),
        1.5 * 200.0 * 5.0 / 2200.0,
    );
    let mut least = (f64::INFINITY, 0.0);
    for r in rows {
        let eps = r["damping_ratio"].as_f64().unwrap();
        let th = eps.asin();
        let expected = if eps < 0.5 {
            (-(std::f64::consts::FRAC_PI_2 - 3.0 * th) * th.tan()).exp()
        } else {
            2.0 * eps
        };
        close(&r["peak_force_ratio"], expected, 1e-12, "17.44");
        close(&r["peak_force_ratio_by_integration"], expected, 1e-6, "RK4");
        close(&r["peak_force"], expected * m * p * vel, 1e-6, "R max (N)");
        if expected < least.0 {
            least = (expected, eps);
        }
    }
    close(
        &i["optimum"]["damping_ratio"],
        least.1,
        1e-5,
        "least peak at the optimum",
    );
}

const BROKEN: &[(&str, usize, &str, &str)] = &[
    ("isolation_nothing.toml", 1, "file", "nothing to compute"),
    (
        "isolation_zero_mass.toml",
        4,
        "mount.mass",
        "must be positive",
    ),
    ("isolation_two_dampings.toml", 3, "mount", "at most one"),
    (
        "isolation_excitation_without_mount.toml",
        3,
        "excitation",
        "needs a [mount]",
    ),
    ("isolation_two_loads.toml", 7, "excitation", "exactly one"),
    ("isolation_no_speed.toml", 7, "excitation", "speed_rpm"),
    (
        "isolation_target_above_one.toml",
        6,
        "selection.max_transmissibility",
        "strictly between",
    ),
    (
        "isolation_negative_damping_ratio.toml",
        4,
        "curves.damping_ratios[1]",
        "at least 0",
    ),
    (
        "isolation_overdamped_impact.toml",
        6,
        "impact.damping_ratio",
        "strictly between",
    ),
    (
        "isolation_impact_without_velocity.toml",
        3,
        "impact",
        "striking_velocity",
    ),
    (
        "isolation_unknown_key.toml",
        5,
        "absorber.tune",
        "unknown field",
    ),
    (
        "isolation_wrong_type.toml",
        4,
        "absorber.mass_ratio",
        "invalid type",
    ),
    (
        "isolation_restitution_with_velocity.toml",
        8,
        "impact.restitution",
        "applies to a striking mass only",
    ),
];

#[test]
fn broken_isolation_scenarios_give_located_errors() {
    common::assert_broken_scenarios("isolation_", BROKEN, common::CheckSays::SameKey);
}

/// Without damping the transmissibility peak at resonance is unbounded: the report says so
/// in words (`"unbounded": true`, text "unbounded"), and the plotted curve leaves out the
/// pole instead of printing `inf`.
#[test]
fn an_undamped_peak_is_reported_unbounded_not_inf() {
    let dir = std::env::temp_dir().join(format!("armsim_undamped_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("undamped.toml");
    std::fs::write(
        &f,
        "kind = \"isolation\"\n[curves]\ndamping_ratios = [0.0, 0.1]\nfrequency_ratios = [3.0]\n",
    )
    .unwrap();
    let o = common::armsim(&["run", f.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        text.contains("ε = 0: TR peak unbounded (no damping) at q = 1.00000"),
        "{text}"
    );
    let v = common::cli_json(&["run", f.to_str().unwrap(), "--json"]);
    let curves = v["curves"].as_array().unwrap_or_else(|| panic!("{v}"));
    assert_eq!(curves[0]["peak"]["unbounded"], true);
    assert_eq!(curves[1]["peak"]["unbounded"], false);
    // ε = 0.1: TR_max = sqrt(1 + 4ε²q²)/sqrt((1-q²)² + 4ε²q²) at its peak, finite.
    assert!(curves[1]["peak"]["transmissibility"].as_f64().unwrap() > 5.0);
    let _ = std::fs::remove_dir_all(&dir);
}
