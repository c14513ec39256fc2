//! Centrodes (`kind = "centrodes"`): docs/reference_data.md §M9's checkpoints through
//! `armsim run --json` — the antiparallelogram's elliptic centrodes (272) and the
//! isosceles slider-crank's Cardan circles (273) — checked point by point against the
//! closed-form curves, against Kennedy's construction, and by the rolling condition
//! (equal arc lengths); located errors for broken files.

use serde_json::Value;

mod common;
use common::run_json;

fn points(v: &Value) -> Vec<(f64, f64)> {
    v.as_array()
        .unwrap()
        .iter()
        .filter(|p| !p.is_null())
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect()
}

#[test]
fn antiparallelogram_272_centrodes_are_equal_ellipses() {
    let v = run_json("scenarios/centrodes_antiparallelogram_272.toml");
    let fixed = points(&v["fixed"]);
    let moving = points(&v["moving"]);
    assert!(fixed.len() >= 150, "{}", fixed.len());
    let d = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1);
    // Fixed: foci A (0, 0) and D (0.03, 0); moving: foci at the coupler's pins B (0, 0)
    // and C (0.03, 0) in its frame; PA + PB = L = 0.06.
    for (ps, what) in [(&fixed, "fixed"), (&moving, "moving")] {
        for &p in ps.iter() {
            let s = d(p, (0.0, 0.0)) + d(p, (0.03, 0.0));
            assert!((s - 0.06).abs() < 1e-9, "{what}: {s}");
        }
        // Semi-axes 0.030 and 0.0260 about the centre (0.015, 0).
        let far = ps
            .iter()
            .map(|&p| d(p, (0.015, 0.0)))
            .fold(0.0f64, f64::max);
        let near = ps
            .iter()
            .map(|&p| d(p, (0.015, 0.0)))
            .fold(f64::INFINITY, f64::min);
        assert!((far - 0.030).abs() < 2e-4, "{what}: semi-major {far}");
        assert!((near - 0.0260).abs() < 1e-4, "{what}: semi-minor {near}");
    }
    assert!(v["kennedy_max_error"].as_f64().unwrap() < 1e-12);
    let (af, am) = (
        v["arc_length_fixed"].as_f64().unwrap(),
        v["arc_length_moving"].as_f64().unwrap(),
    );
    assert!((af - am).abs() < 1e-6 * af, "rolling: {af} vs {am}");
}

#[test]
fn isosceles_slider_crank_273_has_cardan_circles() {
    let v = run_json("scenarios/centrodes_isosceles_slider_crank_273.toml");
    assert!(v["stopped"].is_null());
    let fixed = points(&v["fixed"]);
    let moving = points(&v["moving"]);
    assert_eq!(fixed.len(), 361);
    for &(x, y) in &fixed {
        assert!((x.hypot(y) - 0.04).abs() < 1e-12, "fixed: circle (A, 2r)");
    }
    for &(x, y) in &moving {
        assert!((x.hypot(y) - 0.02).abs() < 1e-12, "moving: circle (B, r)");
    }
    // The moving circle (radius r) rolls twice round inside the fixed one (radius 2r)
    // while the crank turns once: both arcs are 2π · 2r.
    let (af, am) = (
        v["arc_length_fixed"].as_f64().unwrap(),
        v["arc_length_moving"].as_f64().unwrap(),
    );
    let full = 2.0 * std::f64::consts::PI * 0.04;
    assert!(
        (af - full).abs() < 1e-4 * full && (am - full).abs() < 1e-3 * full,
        "{af} {am}"
    );
    assert!(v["kennedy_max_error"].as_f64().unwrap() < 1e-12);
}

#[test]
fn isosceles_slotted_lever_274_has_circles_a_25_and_b_50() {
    let v = run_json("scenarios/centrodes_isosceles_slotted_lever_274.toml");
    assert_eq!(v["mechanism"], "slotted_lever");
    assert_eq!(v["link"], "block");
    let r = 0.025;
    let input: Vec<f64> = v["input_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let mut n = 0;
    for (k, phi) in input.iter().enumerate() {
        let (f, m) = (&v["fixed"][k], &v["moving"][k]);
        if f.is_null() {
            continue;
        }
        n += 1;
        let (x, y) = (f[0].as_f64().unwrap(), f[1].as_f64().unwrap());
        // Closed form: P = 2A − B, the point of the circle (A, AB) opposite the pin.
        let p = phi.to_radians();
        assert!(
            (x + r * p.cos()).abs() < 1e-9 && (y + r * p.sin()).abs() < 1e-9,
            "fixed at {phi}°: ({x}, {y})"
        );
        let (u, w) = (m[0].as_f64().unwrap(), m[1].as_f64().unwrap());
        assert!(
            (u.hypot(w) - 2.0 * r).abs() < 1e-9,
            "moving: circle (B, 2r)"
        );
    }
    assert!(n >= 355, "{n} finite points");
    assert!(v["kennedy_max_error"].as_f64().unwrap() < 1e-12);
    // Rolling: over one crank turn the fixed circle (radius r), inside the moving one
    // (radius 2r), is rolled on once, and half the moving circle: both arcs 2π r.
    let (af, am) = (
        v["arc_length_fixed"].as_f64().unwrap(),
        v["arc_length_moving"].as_f64().unwrap(),
    );
    let full = 2.0 * std::f64::consts::PI * r;
    assert!((af - full).abs() < 2e-2 * full, "fixed arc {af}");
    assert!((af - am).abs() < 1e-3 * af, "rolling: {af} vs {am}");
}

const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "centrodes_crank_out_of_scale.toml",
        7,
        "four_bar.crank",
        "1e-20 is 3.3333333333333334e-19 times four_bar.frame (0.03): the lengths of one mechanism lie within a factor 1e9",
    ),
    (
        "centrodes_bad_assembly.toml",
        8,
        "four_bar.assembly",
        "1 or -1",
    ),
    (
        "centrodes_cannot_close.toml",
        3,
        "four_bar",
        "does not close",
    ),
    (
        "centrodes_crank_cannot_turn.toml",
        3,
        "slider_crank",
        "cannot turn",
    ),
    (
        "centrodes_missing_rocker.toml",
        3,
        "four_bar.rocker",
        "missing field",
    ),
    (
        "centrodes_negative_crank.toml",
        5,
        "four_bar.crank",
        "must be positive",
    ),
    ("centrodes_no_mechanism.toml", 1, "file", "no mechanism"),
    (
        "centrodes_slotted_lever_at_pivot.toml",
        4,
        "slotted_lever",
        "on the lever pivot",
    ),
    (
        "centrodes_two_mechanisms.toml",
        9,
        "slider_crank",
        "not both",
    ),
    (
        "centrodes_unknown_key.toml",
        6,
        "slider_crank.length",
        "unknown field",
    ),
    (
        "centrodes_wrong_type.toml",
        4,
        "slider_crank.crank",
        "invalid type",
    ),
    (
        "centrodes_zero_step.toml",
        2,
        "step_deg",
        "strictly between",
    ),
    (
        "centrodes_start_out_of_range.toml",
        10,
        "four_bar.start_deg",
        "strictly between -3600 and 3600",
    ),
];

#[test]
fn broken_centrode_scenarios_give_located_errors() {
    common::assert_broken_scenarios("centrodes_", BROKEN, common::CheckSays::NotAsked);
}
