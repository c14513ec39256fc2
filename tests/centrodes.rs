//! Centrodes (`kind = "centrodes"`): docs/reference_data.md §M9's checkpoints through
//! `armsim run --json` — the antiparallelogram's elliptic centrodes (272) and the
//! isosceles slider-crank's Cardan circles (273) — checked point by point against the
//! closed-form curves, against Kennedy's construction, and by the rolling condition
//! (equal arc lengths); located errors for broken files.

use serde_json::Value;

mod common;
use common::run_json;

/// The input angles (deg) of a centrode report.
fn input_deg(v: &Value) -> Vec<f64> {
    v["input_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

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
    // The sweep passes the change point at 180° (all links in line) on the crossed
    // motion and closes the ellipses over the whole turn.
    assert!(v["stopped"].is_null(), "{}", v["stopped"]);
    assert_eq!(v["continued_through_deg"], serde_json::json!([180.0]));
    assert_eq!(fixed.len(), 361, "{}", fixed.len());
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
    let input = input_deg(&v);
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

#[test]
fn scotch_yoke_crank_rolls_on_the_yoke_as_a_cardan_pair() {
    let v = run_json("scenarios/centrodes_scotch_yoke.toml");
    assert_eq!(v["mechanism"], "scotch_yoke");
    assert_eq!(
        (v["link"].as_str(), v["relative_to"].as_str()),
        (Some("AB"), Some("yoke"))
    );
    let r = 0.1;
    let input = input_deg(&v);
    assert_eq!(input.len(), 361);
    for (k, phi) in input.iter().enumerate() {
        let p = phi.to_radians();
        // Fixed (yoke frame): (−r cos φ, r sin φ); moving (crank frame): (r sin²φ, r sin φ cos φ).
        let (f, m) = (&v["fixed"][k], &v["moving"][k]);
        let (x, y) = (f[0].as_f64().unwrap(), f[1].as_f64().unwrap());
        assert!(
            (x + r * p.cos()).abs() < 1e-12 && (y - r * p.sin()).abs() < 1e-12,
            "{phi}"
        );
        let (u, w) = (m[0].as_f64().unwrap(), m[1].as_f64().unwrap());
        assert!(
            (u - r * p.sin() * p.sin()).abs() < 1e-12 && (w - r * p.sin() * p.cos()).abs() < 1e-12,
            "{phi}"
        );
    }
    let circle = |what: &str| {
        let c = &v["fit"][what];
        assert_eq!(c["kind"], "circle", "{what}: {c}");
        let c = &c["circle"];
        (
            c["centre"][0].as_f64().unwrap(),
            c["centre"][1].as_f64().unwrap(),
            c["radius"].as_f64().unwrap(),
        )
    };
    let (x, y, rad) = circle("fixed");
    assert!(x.abs() < 1e-12 && y.abs() < 1e-12 && (rad - r).abs() < 1e-12);
    let (x, y, rad) = circle("moving");
    assert!((x - r / 2.0).abs() < 1e-12 && y.abs() < 1e-12 && (rad - r / 2.0).abs() < 1e-12);
    // Kennedy's four-bar construction does not apply; the three-centres lines do.
    assert!(v["kennedy_max_error"].is_null());
    assert!(v["three_centres_max_error"].as_f64().unwrap() < 1e-12);
    // Rolling: one crank turn moves the contact once round the yoke's circle (2π r) and
    // twice round the crank's (2 · 2π r/2): both arcs 2π r.
    let full = 2.0 * std::f64::consts::PI * r;
    for k in ["arc_length_fixed", "arc_length_moving"] {
        let a = v[k].as_f64().unwrap();
        assert!((a - full).abs() < 1e-4 * full, "{k}: {a}");
    }
}

#[test]
fn antiparallelogram_272_long_links_relative_centrodes_are_hyperbolas() {
    let v = run_json("scenarios/centrodes_antiparallelogram_272_long_links.toml");
    assert!(v["stopped"].is_null(), "{}", v["stopped"]);
    let d = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1);
    // Foci A (0, 0), B (0.06, 0) on the crank; D (0, 0), C (0.06, 0) on the rocker:
    // |PF1 − PF2| = s = 0.03 (focal distance L = 0.06).
    for what in ["fixed", "moving"] {
        let ps = points(&v[what]);
        assert!(ps.len() >= 350, "{what}: {}", ps.len());
        for &p in &ps {
            let diff = (d(p, (0.0, 0.0)) - d(p, (0.06, 0.0))).abs();
            assert!(
                (diff - 0.03).abs() < 1e-9 * (1.0 + d(p, (0.0, 0.0)) / 0.06),
                "{what}: {p:?} {diff}"
            );
        }
        assert_eq!(v["fit"][what]["kind"], "curve");
    }
    // Through infinity where the short links are parallel: crank at 60° and 300°.
    let inf: Vec<f64> = v["at_infinity_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(inf.len(), 2, "{inf:?}");
    assert!(
        (inf[0] - 60.0).abs() < 1e-9 && (inf[1] - 300.0).abs() < 1e-9,
        "{inf:?}"
    );
    assert!(v["three_centres_max_error"].as_f64().unwrap() < 1e-12);
}

#[test]
fn rocker_relative_to_crank_is_the_inverted_mechanisms_coupler_centrode() {
    use armsim::machines::instant_centres::centrodes;
    use armsim::machines::linkage::catalog;
    use armsim::machines::linkage::position::NewtonOptions;
    use armsim::machines::linkage::sweep::{sweep, SweepOptions};
    let v = run_json("scenarios/centrodes_four_bar_rocker_vs_crank.toml");
    assert!(v["stopped"].is_null());
    let fixed = &v["fixed"];
    let moving = &v["moving"];
    // The inversion with the crank AB fixed: frame AB 0.04, crank AD 0.10, coupler DC
    // 0.08, rocker BC 0.12; its input ψ (AD from AB) is −φ. Its coupler's fixed centrode
    // is in AB's frame (A origin, B on +x), its moving one in DC's frame (D origin, C on
    // +x), the frames of the relative centrodes.
    let (g, a, b, c) = (0.04, 0.10, 0.08, 0.12);
    let l = catalog::four_bar(g, a, b, c);
    let opts = SweepOptions {
        from: 0.0,
        to: std::f64::consts::TAU,
        step: 1f64.to_radians(),
        assemble_at: 1f64.to_radians(),
        newton: NewtonOptions::default(),
    };
    let mut best = f64::INFINITY;
    for mode in [1.0, -1.0] {
        let q = catalog::four_bar_guess(&l, (g, a, b, c), opts.assemble_at, mode).unwrap();
        let sw = sweep(&l, &q, &opts).unwrap();
        assert!(sw.stopped.is_none());
        let inv = centrodes(&l, 1, &sw.samples);
        assert_eq!(inv.len(), 361);
        let mut worst = 0.0f64;
        for k in 0..=360 {
            let (p, rel_f, rel_m) = (&inv[(360 - k) % 360], &fixed[k], &moving[k]);
            let (pf, pm) = (p.fixed.unwrap(), p.moving.unwrap());
            worst = worst
                .max(
                    (pf.x - rel_f[0].as_f64().unwrap()).abs()
                        + (pf.y - rel_f[1].as_f64().unwrap()).abs(),
                )
                .max(
                    (pm.x - rel_m[0].as_f64().unwrap()).abs()
                        + (pm.y - rel_m[1].as_f64().unwrap()).abs(),
                );
        }
        best = best.min(worst);
    }
    assert!(best < 1e-9, "inversion mismatch {best}");
    // Adjacent links: the coupler relative to the crank is the pin B itself.
    let text = std::fs::read_to_string(
        common::root().join("scenarios/centrodes_four_bar_rocker_vs_crank.toml"),
    )
    .unwrap()
    .replace("link = \"DC\"", "link = \"BC\"");
    let sc = armsim::scenarios::centrodes::parse("x.toml", &text).unwrap();
    let ctx = armsim::scenarios::source::Source::new("x.toml", &text);
    let r = armsim::scenarios::centrodes::report(&ctx, &sc, None).unwrap();
    let fit = &r.json["fit"];
    assert_eq!(fit["fixed"]["kind"], "point");
    assert!((fit["fixed"]["mean"][0].as_f64().unwrap() - 0.04).abs() < 1e-12);
    assert_eq!(fit["moving"]["kind"], "point");
    assert!(fit["moving"]["mean"][0].as_f64().unwrap().abs() < 1e-12);
}

const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "centrodes_unknown_link.toml",
        3,
        "link",
        "no link 'XY' in the four_bar (its links: ground, AB, BC, DC)",
    ),
    (
        "centrodes_same_link.toml",
        4,
        "relative_to",
        "both 'AB'",
    ),
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
