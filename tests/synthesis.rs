//! Four-bar and slider-crank synthesis (`kind = "synthesis"`): the problem book's
//! checkpoints (docs/reference_data.md §M5) through `armsim run --json` on the bundled
//! scenarios, each result also run through the linkage solver, plus closed forms written
//! out here (circle intersections, the stroke equation) and located errors for broken
//! files.

use armsim::machines::linkage::fourbar;
use armsim::machines::synthesis::verify::structural_error;
use armsim::machines::synthesis::{self as syn, Function, FunctionMap};
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
fn crank_rocker_188_reproduces_the_book_and_the_true_pressure_maximum() {
    let v = run_json("scenarios/synthesis_crank_rocker_188.toml");
    let s = &v["crank_rocker"]["solutions"][0];
    assert_eq!(v["crank_rocker"]["solutions"].as_array().unwrap().len(), 1);
    close(&s["extended"], 0.826, 5e-4, "AC'");
    close(&s["folded"], 0.492, 5e-4, "AC''");
    close(&s["crank"], 0.1668, 5e-5, "a");
    close(&s["coupler"], 0.6593, 5e-5, "b");
    close(&s["theta_deg"], 19.91, 5e-3, "θ");
    close(&s["time_ratio"], 1.249, 5e-4, "K");
    close(
        &s["pressure_at_limits_deg"][0],
        54.8,
        0.05,
        "pressure at C'",
    );
    close(
        &s["pressure_at_limits_deg"][1],
        14.7,
        0.05,
        "pressure at C''",
    );
    assert_eq!(s["grashof"], "crank-rocker");
    // The linkage solver: the rocker swings the 60° it was synthesised for, with the
    // same time ratio; the largest pressure angle is 58.1° at crank angle 0°, not at a
    // limit, and matches the closed form at 0°.
    let c = &s["check"];
    close(&c["swing_deg"], 60.0, 1e-6, "swing");
    close(
        &c["time_ratio"],
        s["time_ratio"].as_f64().unwrap(),
        1e-7,
        "K by the solver",
    );
    close(
        &c["max_pressure_angle_deg"],
        58.1,
        0.05,
        "largest pressure angle",
    );
    close(&c["max_pressure_at_crank_deg"], 0.0, 1e-9, "where");
    close(
        &s["pressure_angle_at_crank_0_deg"],
        c["max_pressure_angle_deg"].as_f64().unwrap(),
        1e-9,
        "closed form at 0°",
    );
    close(&s["pressure_angle_at_crank_180_deg"], 8.8, 0.05, "at 180°");
}

#[test]
fn time_ratio_synthesis_returns_every_pivot_and_each_keeps_its_time_ratio() {
    let v = run_json("scenarios/synthesis_crank_rocker_time_ratio.toml");
    let sols = v["crank_rocker"]["solutions"].as_array().unwrap();
    assert_eq!(sols.len(), 4);
    for s in sols {
        // Independent: the pivot is at the frame distance and sees C'C'' under θ.
        let (x, y) = (
            s["pivot"][0].as_f64().unwrap(),
            s["pivot"][1].as_f64().unwrap(),
        );
        close(&Value::from(x.hypot(y)), 0.55, 1e-12, "AD");
        let c1 = (
            0.4 * 60f64.to_radians().cos(),
            0.4 * 60f64.to_radians().sin(),
        );
        let c2 = (
            0.4 * 120f64.to_radians().cos(),
            0.4 * 120f64.to_radians().sin(),
        );
        let (u, w) = ((c1.0 - x, c1.1 - y), (c2.0 - x, c2.1 - y));
        let seen = (u.0 * w.1 - u.1 * w.0)
            .abs()
            .atan2(u.0 * w.0 + u.1 * w.1)
            .to_degrees();
        close(
            &Value::from(seen),
            180.0 * 0.24868 / 2.24868,
            1e-9,
            "θ seen",
        );
        close(&s["check"]["time_ratio"], 1.24868, 1e-6, "K by the solver");
        close(&s["check"]["swing_deg"], 60.0, 1e-6, "swing");
    }
    // Problem 188's pivot is among them.
    assert!(sols.iter().any(|s| {
        (s["pivot"][0].as_f64().unwrap() + 0.55).abs() < 1e-3
            && (s["crank"].as_f64().unwrap() - 0.1668).abs() < 2e-4
    }));
}

#[test]
fn offset_slider_crank_189_uses_the_re_derived_offset() {
    let v = run_json("scenarios/synthesis_slider_crank_189.toml");
    let s = &v["slider_crank"];
    close(&s["rod"], 768.5, 0.05, "l");
    close(&s["crank"], 192.1, 0.05, "r");
    close(
        &s["offset"],
        206.3,
        0.05,
        "e (the book's 0.27 m contradicts K)",
    );
    close(&s["max_pressure_angle_deg"], 31.2, 0.05, "α max");
    close(&s["theta_deg"], 8.57, 5e-3, "θ");
    // The linkage solver: stroke 400, K 1.1, and its largest rod angle.
    close(&s["check"]["stroke"], 400.0, 1e-6, "stroke by the solver");
    close(&s["check"]["time_ratio"], 1.1, 1e-7, "K by the solver");
    close(
        &s["check"]["max_pressure_angle_deg"],
        s["max_pressure_angle_deg"].as_f64().unwrap(),
        1e-6,
        "α max by the solver",
    );
    // Closed form written out: H² = (l + r)² + (l − r)² − 2 (l² − r²) cos θ.
    let (r, l) = (s["crank"].as_f64().unwrap(), s["rod"].as_f64().unwrap());
    let th = s["theta_deg"].as_f64().unwrap().to_radians();
    let h2 = (l + r).powi(2) + (l - r).powi(2) - 2.0 * (l * l - r * r) * th.cos();
    close(&Value::from(h2.sqrt()), 400.0, 1e-9, "stroke equation");
    // The other route (given the offset) returns the same mechanism.
    let e = s["offset"].as_f64().unwrap();
    let d = syn::slider_crank_from_offset(400.0, 1.1, e).unwrap();
    assert!(
        (d.crank - r).abs() < 1e-9 && (d.rod - l).abs() < 1e-9,
        "{d:?}"
    );
}

#[test]
fn centred_slider_crank_189_and_offset_slider_crank_194() {
    let v = run_json("scenarios/synthesis_slider_crank_189_centred.toml");
    let s = &v["slider_crank"];
    close(&s["crank"], 200.0, 1e-9, "r");
    close(&s["rod"], 800.0, 1e-9, "l");
    close(&s["offset"], 0.0, 1e-12, "e");
    close(&s["max_pressure_angle_deg"], 14.48, 5e-3, "α max");
    close(&s["check"]["time_ratio"], 1.0, 1e-7, "K");
    let v = run_json("scenarios/synthesis_slider_crank_194.toml");
    let s = &v["slider_crank"];
    close(&s["theta_deg"], 1.782, 5e-4, "θ");
    close(&s["rod"], 0.3746, 5e-5, "l");
    close(&s["crank"], 0.1199, 5e-5, "r");
    close(&s["offset"], 0.0163, 5e-5, "e");
    close(&s["max_pressure_angle_deg"], 21.3, 0.05, "α max");
    close(&s["check"]["stroke"], 0.24, 1e-9, "stroke by the solver");
    close(&s["check"]["time_ratio"], 1.02, 1e-7, "K by the solver");
}

#[test]
fn shaper_190_and_195_match_the_book_and_the_slotted_lever_solver() {
    let v = run_json("scenarios/synthesis_shaper_190.toml");
    let s = &v["shaper"];
    close(&s["swing_deg"], 51.43, 5e-3, "ψ");
    close(&s["lever"], 576.2, 0.05, "L");
    close(&s["crank"], 108.5, 0.05, "r");
    close(&s["sagitta"], 57.06, 5e-3, "sagitta");
    close(&s["max_rod_angle_deg"], 10.3, 0.05, "rod angle");
    close(
        &s["check"]["swing_deg"],
        s["swing_deg"].as_f64().unwrap(),
        1e-6,
        "swing by the solver",
    );
    close(&s["check"]["time_ratio"], 1.8, 1e-7, "K by the solver");
    let v = run_json("scenarios/synthesis_shaper_195.toml");
    let s = &v["shaper"];
    close(&s["crank"], 0.1, 1e-12, "r");
    close(&s["lever"], 0.8, 1e-12, "L");
    close(&s["velocity_ratio"], 1.5, 1e-12, "K_v");
    close(
        &s["check"]["swing_deg"],
        s["swing_deg"].as_f64().unwrap(),
        1e-6,
        "swing by the solver",
    );
}

#[test]
fn three_position_round_trip_returns_the_188_mechanism() {
    let v = run_json("scenarios/synthesis_function_round_trip.toml");
    let f = &v["function"];
    close(&f["coefficients"][0], 3.29736, 5e-5, "K1");
    close(&f["coefficients"][1], 1.375, 5e-5, "K2");
    close(&f["coefficients"][2], 0.41701, 5e-5, "K3");
    close(&f["crank"], 0.1668, 5e-5, "a");
    close(&f["coupler"], 0.6593, 5e-5, "b");
    close(&f["rocker"], 0.4, 5e-5, "c");
    for e in f["precision_check_deg"].as_array().unwrap() {
        close(e, 0.0, 1e-9, "solver at a precision point");
    }
}

#[test]
fn log10_generator_structural_error_agrees_with_the_closed_form_position() {
    let v = run_json("scenarios/synthesis_function_log10.toml");
    let f = &v["function"];
    for e in f["structural_error"]["at_precision_points_deg"]
        .as_array()
        .unwrap()
    {
        close(e, 0.0, 1e-9, "error at a precision point");
    }
    // Chebyshev spacing over [1, 10].
    let xs: Vec<f64> = f["precision_points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["x"].as_f64().unwrap())
        .collect();
    let c = 4.5 * (std::f64::consts::PI / 6.0).cos();
    for (x, want) in xs.iter().zip([5.5 - c, 5.5, 5.5 + c]) {
        assert!((x - want).abs() < 1e-12, "{x} vs {want}");
    }
    // The largest error by circle intersection on a 4× finer grid: the solver's sampled
    // maximum cannot exceed it and lies within what the grid resolves.
    let g = |k: &str| f[k].as_f64().unwrap();
    let (a, b, cc, d) = (g("crank"), g("coupler"), g("rocker"), g("frame"));
    let map = FunctionMap {
        f: Function::Log10,
        x: [1.0, 10.0],
        phi: [30f64.to_radians(), 120f64.to_radians()],
        psi: [60f64.to_radians(), 150f64.to_radians()],
    };
    let mode = {
        let (phi, psi) = (map.phi_of(xs[1]), map.psi_of(xs[1]));
        [1.0, -1.0]
            .into_iter()
            .min_by(|m1, m2| {
                let err = |m: f64| {
                    let (_, pc) = fourbar::position(d, a, b, cc, phi, m).unwrap();
                    (pc.y.atan2(pc.x - d) - psi).abs()
                };
                err(*m1).total_cmp(&err(*m2))
            })
            .unwrap()
    };
    let mut max = 0.0f64;
    for k in 0..=1440 {
        let phi = map.phi[0] + (map.phi[1] - map.phi[0]) * k as f64 / 1440.0;
        let (_, pc) = fourbar::position(d, a, b, cc, phi, mode).unwrap();
        let psi = pc.y.atan2(pc.x - d);
        max = max.max((psi - map.psi_of(map.x_of(phi))).abs().to_degrees());
    }
    let got = f["structural_error"]["max_angle_error_deg"]
        .as_f64()
        .unwrap();
    assert!(got <= max + 1e-9 && got > max - 1e-3, "{got} vs {max}");
    // The library route gives the same numbers as the JSON.
    let e = structural_error((a, b, cc, d), &map, &xs, 360).unwrap();
    assert!((e.max_angle_error_deg - got).abs() < 1e-12);
}

#[test]
fn freudenstein_round_trip_on_random_four_bars() {
    // Any closed four-bar's three positions give back its lengths (a second route: the
    // positions are computed here by circle intersection).
    for (a, b, c, d) in [
        (0.3, 1.1, 0.8, 1.0),
        (1.0, 2.2, 1.9, 2.4),
        (0.2, 0.9, 0.7, 0.75),
    ] {
        let pts = [20.0f64, 75.0, 140.0].map(|deg: f64| {
            let phi = deg.to_radians();
            let (_, pc) = fourbar::position(d, a, b, c, phi, 1.0).unwrap();
            (phi, pc.y.atan2(pc.x - d))
        });
        let k = syn::freudenstein_coefficients(&pts).unwrap();
        let [a2, b2, c2] = syn::four_bar_from_coefficients(k, d).unwrap();
        assert!((a2 - a).abs() < 1e-9 && (b2 - b).abs() < 1e-9 && (c2 - c).abs() < 1e-9);
    }
}

#[test]
fn one_limit_crank_rocker_returns_188_and_every_solution_keeps_the_limit_and_k() {
    let v = run_json("scenarios/synthesis_crank_rocker_188_one_limit.toml");
    let sols = v["crank_rocker"]["solutions"].as_array().unwrap();
    assert!(sols.len() >= 2, "{sols:?}");
    // |AC'| = b + a, with A = (−0.55, 0) and C' = 0.4 (cos 60°, sin 60°).
    let ext = ((0.4 * 0.5f64 + 0.55).powi(2) + (0.4 * 60f64.to_radians().sin()).powi(2)).sqrt();
    for s in sols {
        close(&s["extended"], ext, 1e-12, "AC' = b + a");
        close(&s["limit_angles_deg"][0], 60.0, 1e-9, "given limit");
        close(&s["time_ratio"], 1.2487825, 1e-9, "K");
        close(
            &s["check"]["time_ratio"],
            1.2487825,
            1e-6,
            "K by the solver",
        );
    }
    let s188 = sols
        .iter()
        .find(|s| (s["limit_angles_deg"][1].as_f64().unwrap() - 120.0).abs() < 1e-4)
        .expect("188's second limit at 120°");
    close(&s188["crank"], 0.166846, 2e-6, "a");
    close(&s188["coupler"], 0.659289, 2e-6, "b");
    close(&s188["check"]["swing_deg"], 60.0, 1e-4, "swing");
    // The same mechanism from its folded limit (120°) as the given one.
    let k = syn::time_ratio(19.91337480145036f64.to_radians());
    let pivot = armsim::machines::linkage::Vec2::new(-0.55, 0.0);
    let folded = syn::crank_rockers_from_one_limit(
        0.4,
        120f64.to_radians(),
        Some(syn::RockerLimit::Folded),
        k,
        pivot,
    )
    .unwrap();
    assert!(folded
        .iter()
        .any(|s| (s.crank - 0.166846).abs() < 2e-6 && (s.limit_angles_deg[0] - 60.0).abs() < 1e-4));
}

/// `(φ, ψ)` of the open four-bar `(a, b, c)` on frame `d` at crank angle `deg`.
fn position(d: f64, a: f64, b: f64, c: f64, deg: f64) -> (f64, f64) {
    let phi = deg.to_radians();
    let (_, pc) = fourbar::position(d, a, b, c, phi, 1.0).unwrap();
    (phi, pc.y.atan2(pc.x - d))
}

#[test]
fn two_position_synthesis_recovers_four_bars_from_either_given_link() {
    use armsim::machines::synthesis::two_position::{four_bar_from_two_positions, GivenLink};
    for (a, b, c, d) in [
        (0.166846, 0.659289, 0.4, 0.55),
        (0.3, 1.1, 0.8, 1.0),
        (1.0, 2.2, 1.9, 2.4),
    ] {
        let pts = [position(d, a, b, c, 25.0), position(d, a, b, c, 110.0)];
        let r = four_bar_from_two_positions(pts, d, GivenLink::Rocker(c)).unwrap();
        assert!(
            (r.crank - a).abs() < 1e-9 && (r.coupler - b).abs() < 1e-9,
            "{r:?}"
        );
        let r = four_bar_from_two_positions(pts, d, GivenLink::Crank(a)).unwrap();
        assert!(
            (r.rocker - c).abs() < 1e-9 && (r.coupler - b).abs() < 1e-9,
            "{r:?}"
        );
    }
    let v = run_json("scenarios/synthesis_two_position_function.toml");
    let t = &v["two_position"];
    close(&t["crank"], 0.166846, 1e-5, "a");
    close(&t["coupler"], 0.659289, 1e-5, "b");
    close(&t["coefficients"][1], 0.55 / 0.4, 1e-12, "K2 = d/c");
    close(
        &t["check"]["rocker_error_at_second_deg"],
        0.0,
        1e-6,
        "solver",
    );
}

#[test]
fn coupler_guidance_puts_the_pivots_on_the_bisectors_and_the_line() {
    use armsim::machines::linkage::{rotate, Vec2};
    use armsim::machines::synthesis::two_position::four_bar_from_coupler_positions;
    let (a, b, c, d) = (0.3, 1.1, 0.8, 1.0);
    // The mechanism turned by 25° and moved to (2, −1): the pivot line is its frame line.
    let (turn, o) = (25f64.to_radians(), Vec2::new(2.0, -1.0));
    let place = |p: Vec2| o + rotate(turn, &p);
    let pos = |deg: f64| {
        let (pb, pc) = fourbar::position(d, a, b, c, deg.to_radians(), 1.0).unwrap();
        (place(pb), place(pc))
    };
    let r = four_bar_from_coupler_positions(
        pos(40.0),
        pos(130.0),
        o + Vec2::new(-3.0 * turn.cos(), -3.0 * turn.sin()),
        turn,
    )
    .unwrap();
    let (pa, pd) = (place(Vec2::zeros()), place(Vec2::new(d, 0.0)));
    assert!(
        (Vec2::new(r.crank_pivot[0], r.crank_pivot[1]) - pa).norm() < 1e-12,
        "{r:?}"
    );
    assert!(
        (Vec2::new(r.rocker_pivot[0], r.rocker_pivot[1]) - pd).norm() < 1e-12,
        "{r:?}"
    );
    assert!(
        (r.crank - a).abs() < 1e-12
            && (r.coupler - b).abs() < 1e-12
            && (r.rocker - c).abs() < 1e-12
    );
    assert!((r.crank_turn_deg - 90.0).abs() < 1e-9, "{r:?}");
    assert!((r.positions_deg[0][0] - 40.0).abs() < 1e-9);
    let v = run_json("scenarios/synthesis_two_position_coupler.toml");
    let t = &v["two_position"];
    close(&t["crank_pivot"][0], 0.0, 1e-6, "A x");
    close(&t["rocker_pivot"][0], 0.55, 1e-6, "D x");
    close(&t["crank"], 0.166846, 1e-6, "a");
    close(&t["rocker"], 0.4, 1e-6, "c");
    close(&t["crank_turn_deg"], 60.0, 1e-4, "crank turn");
    close(
        &t["check"]["rocker_error_at_second_deg"],
        0.0,
        1e-3,
        "solver",
    );
}

#[test]
fn shaper_from_its_crank_gives_the_frame_r_over_sin_half_swing() {
    let v = run_json("scenarios/synthesis_shaper_190_from_crank.toml");
    let s = &v["shaper"];
    let half = (90.0f64 * 0.8 / 2.8).to_radians();
    close(&s["frame"], 108.471 / half.sin(), 1e-9, "d = r / sin(ψ/2)");
    close(&s["frame"], 250.0, 2e-3, "190's frame");
    close(&s["lever"], 576.2, 0.05, "L");
    close(&s["check"]["time_ratio"], 1.8, 1e-7, "K by the solver");
    // 195 by its crank: K_v = (d + r)/(d − r) = 1.5 with r = 0.1 gives d = 0.5.
    let s = syn::shaper(0.32, syn::ShaperSize::Crank(0.1), 1.5, true, None).unwrap();
    assert!(
        (s.frame - 0.5).abs() < 1e-12 && (s.lever - 0.8).abs() < 1e-12,
        "{s:?}"
    );
}

const BROKEN: &[(&str, usize, &str, &str)] = &[
    ("synthesis_nothing.toml", 1, "file", "nothing to synthesise"),
    (
        "synthesis_negative_rocker.toml",
        4,
        "crank_rocker.rocker",
        "must be positive",
    ),
    (
        "synthesis_both_pivot_and_ratio.toml",
        8,
        "crank_rocker.time_ratio",
        "not both",
    ),
    (
        "synthesis_crank_rocker_underdetermined.toml",
        3,
        "crank_rocker",
        "missing",
    ),
    ("synthesis_no_crank.toml", 3, "crank_rocker", "no crank"),
    (
        "synthesis_time_ratio_below_one.toml",
        5,
        "slider_crank.time_ratio",
        "at least 1",
    ),
    (
        "synthesis_rod_ratio.toml",
        6,
        "slider_crank.rod_ratio",
        "between 0 and 1",
    ),
    (
        "synthesis_frame_out_of_range.toml",
        8,
        "crank_rocker.frame",
        "1e308 is out of range: a length lies in 1e-100..1e100",
    ),
    (
        "synthesis_time_ratio_out_of_range.toml",
        7,
        "slider_crank.time_ratio",
        "1e308 is out of range: at most 1e6",
    ),
    (
        "synthesis_rod_ratio_tiny.toml",
        8,
        "slider_crank.rod_ratio",
        "1e-300 is out of range: the crank and the rod",
    ),
    (
        "synthesis_rod_too_short.toml",
        3,
        "shaper",
        "shorter than half the sagitta",
    ),
    (
        "synthesis_two_precision_points.toml",
        5,
        "function.precision_deg",
        "exactly three",
    ),
    (
        "synthesis_unknown_function.toml",
        5,
        "function.function",
        "unknown function",
    ),
    (
        "synthesis_missing_rocker_range.toml",
        3,
        "function",
        "rocker_range_deg",
    ),
    (
        "synthesis_unknown_key.toml",
        7,
        "slider_crank.length",
        "unknown field",
    ),
    (
        "synthesis_wrong_type.toml",
        4,
        "shaper.stroke",
        "invalid type",
    ),
    (
        "synthesis_one_limit_without_pivot.toml",
        3,
        "crank_rocker",
        "missing: `pivot_direction_deg`",
    ),
    (
        "synthesis_limit_with_both_limits.toml",
        7,
        "crank_rocker.limit",
        "applies only to one given limit",
    ),
    (
        "synthesis_unknown_limit.toml",
        6,
        "crank_rocker.limit",
        "expected extended or folded",
    ),
    (
        "synthesis_two_position_three_points.toml",
        6,
        "two_position.precision_deg",
        "exactly two",
    ),
    (
        "synthesis_coupler_positions_with_frame.toml",
        5,
        "two_position.frame",
        "does not apply to `coupler_positions`",
    ),
    (
        "synthesis_coupler_not_rigid.toml",
        3,
        "two_position",
        "not one rigid coupler",
    ),
    (
        "synthesis_shaper_frame_and_crank.toml",
        6,
        "shaper.crank",
        "not both",
    ),
    (
        "synthesis_precision_angle_out_of_range.toml",
        7,
        "function.precision_deg[0]",
        "strictly between -3600 and 3600",
    ),
];

#[test]
fn broken_synthesis_scenarios_give_located_errors() {
    common::assert_broken_scenarios(
        "synthesis_",
        BROKEN,
        common::CheckSays::RefusesUnlessRunKey(&["crank_rocker", "shaper", "two_position"]),
    );
}
