//! Gear geometry (docs/reference_data.md §M2): every published checkpoint through `armsim run
//! --json` on its bundled scenario (re-derived values where the sheet says the book is
//! wrong), and independent routes: the zero-backlash condition on the working pitch
//! circles, the rolling-cone condition of bevel pairs, equal normal pitches of crossed
//! helical pairs, the involute of a point, the internal-gear interference root, the
//! pointed-tooth shift as a zero of the tip thickness, and the broken files.

use armsim::machines::gearing::crossed_axes::{bevel, crossed, worm};
use armsim::machines::gearing::involute::{inv, inv_inverse, involute_at, thickness_at};
use armsim::machines::gearing::pair::{pair, PairKind, PairSpec};
use armsim::machines::gearing::pair_design::{design, specific_sliding};
use serde_json::Value;
use std::f64::consts::PI;

mod common;
use common::run_json;

fn f(v: &Value, path: &str) -> f64 {
    let mut x = v;
    for k in path.split('.') {
        x = match k.parse::<usize>() {
            Ok(i) => &x[i],
            Err(_) => &x[k],
        };
    }
    x.as_f64().unwrap_or_else(|| panic!("{path}: {x}"))
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

fn spur(z: [u32; 2], x: [f64; 2]) -> PairSpec {
    PairSpec {
        kind: PairKind::External,
        module: 10.0,
        teeth: z,
        pressure_angle: 20f64.to_radians(),
        addendum: 1.0,
        clearance: 0.25,
        shift: x,
        helix: 0.0,
        face_width: None,
        centre_distance: None,
    }
}

// ---------------------------------------------------------------------------------------
// Published checkpoints.

#[test]
fn gg2_line_of_action_and_largest_tip_radii() {
    let v = run_json("scenarios/gear_pair_gg2_214_line_of_action.toml");
    let p = &v["pairs"][0];
    close(f(p, "line_of_action"), 92.345, 5e-4, "N1N2");
    close(f(p, "arc_of_action"), 98.27, 5e-3, "arc");
    close(f(p, "gears.0.max_tip_radius"), 145.75, 5e-3, "ra1");
    close(f(p, "gears.1.max_tip_radius"), 168.51, 5e-3, "ra2");
}

#[test]
fn gg3_minimum_centre_distances_for_ratio_two() {
    let v = run_json("scenarios/gear_pair_gg3_204_min_centre_distance.toml");
    let a: Vec<f64> = (0..3)
        .map(|i| f(&v["pairs"][i], "centre_distance"))
        .collect();
    close(a[0], 255.0, 1e-9, "standard (the book's 235 is a slip)");
    close(a[1], 180.0, 1e-9, "equal and opposite");
    close(
        a[2],
        152.2,
        0.05,
        "positive shift (the book's 133 is inconsistent)",
    );
    assert!(a[2] < a[1] && a[1] < a[0], "ordering {a:?}");
    let p = &v["pairs"][2];
    close(f(p, "shift.0"), 7.0 / 17.0, 1e-12, "x1");
    close(f(p, "shift.1"), -3.0 / 17.0, 1e-12, "x2");
    close(
        f(p, "working_pressure_angle_deg"),
        22.19,
        0.005,
        "αw = 22°12'",
    );
    let inv_aw = inv(f(p, "working_pressure_angle_deg").to_radians());
    close(inv_aw, 0.0206, 5e-5, "inv αw");
    for i in 0..3 {
        for g in 0..2 {
            assert_eq!(
                v["pairs"][i]["gears"][g]["undercut"], false,
                "pair {i} gear {g}"
            );
        }
    }
}

#[test]
fn gg4_tooth_thickness_and_pointed_tooth_shift() {
    let v = run_json("scenarios/gear_pair_gg4_218_tooth_thickness.toml");
    let g = &v["pairs"][0]["gears"][0];
    close(f(g, "thickness_pitch"), 15.71, 0.005, "s");
    close(f(g, "thickness_tip"), 6.95, 0.005, "s_a");
    close(
        f(g, "pointed_shift_fixed_tip"),
        -0.868,
        0.0015,
        "tip held at 110 mm",
    );
    close(f(g, "pointed_shift_growing_tip"), 1.22, 0.005, "tip grows");
}

#[test]
fn gg5_helical_pair_with_the_inferred_ten_degree_helix() {
    let v = run_json("scenarios/gear_pair_gg5_222_helical.toml");
    let p = &v["pairs"][0];
    close(f(p, "centre_distance"), 103.57, 0.005, "A");
    close(f(p, "transverse_pressure_angle_deg"), 20.28, 0.005, "αt");
    close(f(p, "contact_ratio.transverse"), 1.566, 0.0015, "εα");
    close(f(p, "contact_ratio.overlap"), 0.415, 0.0015, "εβ");
    close(f(p, "contact_ratio.total"), 1.98, 0.005, "ε");
}

#[test]
fn internal_pairs_200_and_213() {
    let v = run_json("scenarios/gear_pair_200_213_internal.toml");
    let p = &v["pairs"][0];
    let g = |k: usize, key: &str| f(&p["gears"][k], key);
    close(g(1, "base_radius"), 187.94, 0.005, "rb2");
    close(g(0, "tip_radius"), 110.0, 1e-9, "ra1");
    close(g(1, "tip_radius"), 190.0, 1e-9, "ra2");
    close(g(0, "root_radius"), 87.5, 1e-9, "rf1");
    close(g(1, "root_radius"), 212.5, 1e-9, "rf2");
    close(f(p, "pitch"), 31.4, 0.05, "p");
    close(f(p, "base_pitch"), 29.5, 0.05, "pb");
    close(f(p, "o2n1"), 191.0, 0.05, "O2N1");
    assert_eq!(p["interference"], true);
    close(
        f(p, "internal_min_pinion_teeth.exact"),
        22.3,
        0.05,
        "exact z1_min",
    );
    assert_eq!(
        v["pairs"][1]["interference"], false,
        "short tooth h_a* = 0.8"
    );
    close(
        f(&v["pairs"][1]["gears"][1], "tip_radius"),
        192.0,
        1e-9,
        "short ra2",
    );
    close(
        f(&v["pairs"][2], "contact_ratio.transverse"),
        1.921,
        0.0015,
        "213 ε",
    );
    close(
        f(&v["pairs"][3], "working_pressure_angle_deg"),
        13.57,
        0.005,
        "213 αw",
    );
    close(
        f(&v["pairs"][3], "contact_ratio.transverse"),
        0.750,
        0.0015,
        "213 ε'",
    );
}

#[test]
fn rack_215_contact_ratio_and_withdrawal() {
    let v = run_json("scenarios/gear_pair_215_rack.toml");
    close(
        f(&v["pairs"][0], "contact_ratio.transverse"),
        1.769,
        0.0015,
        "ε",
    );
    close(
        f(&v["pairs"][0], "withdrawal_for_unit_contact_ratio"),
        10.9,
        0.05,
        "D",
    );
    close(
        f(&v["pairs"][1], "contact_ratio.transverse"),
        1.0,
        0.005,
        "withdrawn",
    );
    // ε' = ε − 2D/(p sin 2α).
    let e = f(&v["pairs"][0], "contact_ratio.transverse")
        - 2.0 * 10.9 / (PI * 14.0 * 40f64.to_radians().sin());
    close(
        f(&v["pairs"][1], "contact_ratio.transverse"),
        e,
        1e-12,
        "formula",
    );
}

#[test]
fn helical_undercut_limits_and_helix_from_centre_distance() {
    let v = run_json("scenarios/gear_pair_205_221_223_helical.toml");
    close(
        f(&v["pairs"][0]["gears"][0], "z_min"),
        14.1,
        0.05,
        "205 β = 20°",
    );
    close(
        f(&v["pairs"][1]["gears"][0], "z_min"),
        11.04,
        0.005,
        "205 β = 30°",
    );
    close(
        f(&v["pairs"][1]["gears"][0], "virtual_teeth"),
        16.94,
        0.005,
        "221 zv",
    );
    // 221: with x = 0.412 the smallest pinion is 17 (1 − 0.412) cos³30° = 6.5 → 7.
    let zmin_shifted = 17.0 * (1.0 - 0.412) * 30f64.to_radians().cos().powi(3);
    close(zmin_shifted, 6.5, 0.05, "221");
    assert_eq!(
        v["pairs"][2]["gears"][0]["undercut"], false,
        "z = 7 with x = 0.412"
    );
    close(
        f(&v["pairs"][3], "helix_angle_deg"),
        10.0 + 51.0 / 60.0,
        0.01,
        "223 β = 10°51'",
    );
    close(f(&v["pairs"][3], "centre_distance"), 140.0, 1e-9, "223 A");
}

#[test]
fn spatial_checkpoints_worm_bevel_crossed() {
    let v = run_json("scenarios/gear_pair_gs2_232_worm.toml");
    let w = &v["pairs"][0];
    close(
        f(w, "lead_angle_deg"),
        14.0 + 2.0 / 60.0,
        0.005,
        "λ = 14°2'",
    );
    close(f(w, "pitch_line_speed"), 7.04, 0.005, "v1");
    close(f(w, "sliding_speed"), 7.25, 0.005, "vs");
    assert_eq!(w["self_locking"], false);
    let v = run_json("scenarios/gear_pair_gs3_gs4_bevel.toml");
    let b = &v["pairs"][0];
    close(f(b, "cone_angles_deg.0"), 26.0 + 34.0 / 60.0, 0.01, "δ1");
    close(f(b, "cone_angles_deg.1"), 63.0 + 26.0 / 60.0, 0.01, "δ2");
    close(f(b, "z_min"), 15.2, 0.01, "z_min");
    close(f(b, "pinion_shift"), 0.41, 0.005, "x1");
    let b = &v["pairs"][1];
    close(f(b, "cone_angles_deg.0"), 23.15, 0.005, "225 δ1");
    close(f(b, "cone_angles_deg.1"), 51.85, 0.005, "225 δ2");
    close(f(b, "virtual_teeth.0"), 21.75, 0.005, "zv1");
    close(
        f(b, "virtual_teeth.1"),
        64.75,
        0.005,
        "zv2 (the book's 63.7 is a misprint)",
    );
    close(f(b, "virtual_ratio"), 2.977, 0.0015, "i'");
    close(
        f(b, "contact_ratio"),
        1.69,
        0.005,
        "ε (the book's 1.77 does not hold)",
    );
    let v = run_json("scenarios/gear_pair_gs5_224_226_crossed.toml");
    close(f(&v["pairs"][0], "centre_distance"), 500.0, 1e-9, "224 A");
    close(f(&v["pairs"][0], "shaft_angle_deg"), 60.0, 1e-9, "224 Σ");
    close(f(&v["pairs"][0], "sliding_speed"), 1.732, 5e-4, "224 vs");
    close(
        f(&v["pairs"][1], "transverse_modules.0"),
        28.555,
        5e-4,
        "226 mt",
    );
    close(f(&v["pairs"][1], "centre_distance"), 128.57, 0.02, "226 A");
    close(
        f(&v["pairs"][2], "centre_distance"),
        133.57,
        0.02,
        "226 ratio 10.5",
    );
}

#[test]
fn design_balances_sliding_within_the_constraints() {
    let v = run_json("scenarios/gear_pair_design.toml");
    let d = &v["pairs"][0];
    assert_eq!(d["teeth"], serde_json::json!([16, 32]));
    assert_eq!(d["constraints_met"], true);
    close(
        f(d, "centre_distance"),
        125.0,
        1e-9,
        "the shifts give back A",
    );
    close(
        f(d, "specific_sliding.0"),
        f(d, "specific_sliding.1"),
        1e-6,
        "balanced",
    );
    close(
        f(d, "shift.0") + f(d, "shift.1"),
        f(d, "total_shift"),
        1e-12,
        "split",
    );
}

// ---------------------------------------------------------------------------------------
// Independent routes.

/// Without backlash, the tooth thicknesses on the working pitch circles fill the working
/// circular pitch: `s_w1 + s_w2 = 2π r_w1 / z1` (a different equation from the
/// `inv α_w` formula the pair uses).
#[test]
fn shifted_pairs_have_no_backlash_on_their_working_circles() {
    for (z, x) in [
        ([10, 20], [7.0 / 17.0, -3.0 / 17.0]),
        ([16, 32], [0.5, 0.6]),
        ([13, 41], [0.3, -0.1]),
    ] {
        let g = pair(&spur(z, x));
        let aw = g.alpha_w;
        let rw: Vec<f64> = g.gears.iter().map(|gg| gg.rb / aw.cos()).collect();
        close(
            rw[0] + rw[1],
            g.centre_distance,
            1e-9,
            "working circles touch",
        );
        let sw: f64 = g
            .gears
            .iter()
            .zip(&rw)
            .map(|(gg, &r)| thickness_at(gg.s, gg.r, gg.rb, r))
            .sum();
        close(sw, 2.0 * PI * rw[0] / z[0] as f64, 1e-9, "no backlash");
    }
    let d = design(125.0, 5.0, 20f64.to_radians(), 2.0, 1.0, 0.25).unwrap();
    let s = specific_sliding(&d.pair);
    close(s[0], s[1], 1e-6, "design balance");
}

#[test]
fn involute_of_a_point_problem_211() {
    // rb = 50, OM = 100: ρ = √(100² − 50²) = 86.6, αM = 60°, inv αM = 0.6849.
    let a = (50f64 / 100.0).acos();
    close(a.to_degrees(), 60.0, 1e-12, "αM");
    close(inv(a), 0.6849, 5e-5, "inv");
    close(inv_inverse(inv(a)), a, 1e-12, "inverse");
    close(100.0 * a.sin(), 86.6, 0.005, "ρ");
}

#[test]
fn root_circle_inside_base_circle_up_to_41_teeth() {
    // z ≤ 2·1.25/(1 − cos 20°) = 41.45 (problem 219).
    let inside = |z: u32| pair(&spur([z, 60], [0.0, 0.0])).gears[0].root_inside_base;
    assert!(inside(41) && !inside(42));
    // Problem 220: an internal gear's base circle equals its tip circle at
    // z = 2/(1 − cos 20°) = 33.2 (book 34).
    close(2.0 / (1.0 - 20f64.to_radians().cos()), 33.2, 0.05, "220");
}

/// An internal gear's tooth is the space of the external involute gear with the same
/// teeth: at its tip radius `ra` (inside the pitch circle) its thickness is the circular
/// pitch at `ra`, `2π ra/z`, less the external tooth's thickness there; by hand for the
/// bundled 40-tooth internal gear of problem 200 (m = 10, ra = 190): 9.668 mm.
#[test]
fn internal_tooth_at_the_tip_is_the_external_space() {
    let g = pair(&PairSpec {
        kind: PairKind::Internal,
        teeth: [20, 40],
        ..spur([20, 40], [0.0, 0.0])
    });
    let ring = &g.gears[1];
    assert!(ring.internal && ring.ra < ring.r, "{ring:?}");
    let z = ring.teeth as f64;
    let space = 2.0 * PI * ring.ra / z - thickness_at(PI * 10.0 - ring.s, ring.r, ring.rb, ring.ra);
    close(ring.s_tip, space, 1e-12, "s_a (internal) = external space");
    let aa = (ring.rb / ring.ra).acos();
    let by_hand = 2.0 * 190.0 * (PI * 10.0 / 2.0 / 400.0 - inv(20f64.to_radians()) + inv(aa));
    close(ring.s_tip, by_hand, 1e-12, "s_a by hand");
    close(ring.s_tip, 9.6685, 5e-4, "s_a rounded");
}

#[test]
fn internal_interference_root_is_exact() {
    // At the exact smallest pinion O2N1 = ra2 (continuous tooth count, m = 1).
    let g = pair(&PairSpec {
        kind: PairKind::Internal,
        teeth: [20, 40],
        module: 1.0,
        ..spur([20, 40], [0.0, 0.0])
    });
    let (z1, _) = g.internal_min_pinion.unwrap();
    let (a, i) = (20f64.to_radians(), 2.0);
    let u = z1 / 2.0;
    let lhs = ((i * u * a.cos()).powi(2) + ((i - 1.0) * u * a.sin()).powi(2)).sqrt();
    close(lhs, i * u - 1.0, 1e-9, "O2N1 = ra2");
}

#[test]
fn pointed_shift_zeroes_the_tip_thickness() {
    let g = pair(&PairSpec {
        kind: PairKind::Rack,
        ..spur([20, 0], [0.0, 0.0])
    });
    let gg = &g.gears[0];
    let x = gg.pointed_shift_growing_tip.unwrap();
    let s = 10.0 * (PI / 2.0 + 2.0 * x * 20f64.to_radians().tan());
    close(
        thickness_at(s, 100.0, gg.rb, 100.0 + (1.0 + x) * 10.0),
        0.0,
        1e-9,
        "growing",
    );
    let x = gg.pointed_shift_fixed_tip.unwrap();
    let s = 10.0 * (PI / 2.0 + 2.0 * x * 20f64.to_radians().tan());
    close(thickness_at(s, 100.0, gg.rb, 110.0), 0.0, 1e-9, "fixed");
}

#[test]
fn spatial_pairs_satisfy_their_rolling_conditions() {
    // Bevel: pitch cones roll: sin δ1 / sin δ2 = z1 / z2, δ1 + δ2 = Σ.
    for (z, s) in [([20, 40], 75.0), ([9, 18], 90.0), ([13, 47], 110.0)] {
        let b = bevel(5.0, z, f64::to_radians(s), 20f64.to_radians(), 1.0, 0.25);
        close(
            b.cone[0].sin() / b.cone[1].sin(),
            z[0] as f64 / z[1] as f64,
            1e-12,
            "cones",
        );
        close((b.cone[0] + b.cone[1]).to_degrees(), s, 1e-9, "Σ");
    }
    // Crossed helical: equal normal pitches, and vs from the velocity triangle.
    let c = crossed(10.0, [20, 40], [0.3, 0.7], Some(10.0));
    close(
        c.mt[0] * 0.3f64.cos(),
        c.mt[1] * 0.7f64.cos(),
        1e-12,
        "normal pitch",
    );
    let v1 = 10.0 * c.r[0] / 1000.0;
    let v2 = v1 * 0.3f64.cos() / 0.7f64.cos();
    close(
        c.sliding_speed.unwrap(),
        v1 * 0.3f64.sin() + v2 * 0.7f64.sin(),
        1e-12,
        "vs",
    );
    // Worm: the screw formula, and self-locking below the friction angle.
    let w = worm(10.0, 1, 20.0, 40, 20f64.to_radians(), None, Some(0.1));
    let phi = (0.1 / 20f64.to_radians().cos()).atan();
    let lam = (1.0f64 / 20.0).atan();
    close(
        w.efficiency.unwrap(),
        lam.tan() / (lam + phi).tan(),
        1e-12,
        "η",
    );
    assert_eq!(w.self_locking(), Some(lam <= phi));
    assert!(w.reverse_efficiency.unwrap() < 0.0);
}

// ---------------------------------------------------------------------------------------
// Broken files.

const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "gear_pair_unknown_key.toml",
        6,
        "pair.tooth",
        "unknown field `tooth`",
    ),
    (
        "gear_pair_query_clearance_not_used.toml",
        6,
        "query[0].clearance",
        "is not used by `find = \"internal_tip_equals_base\"`",
    ),
    (
        "gear_pair_no_pairs.toml",
        2,
        "kind",
        "at least one [[pair]]",
    ),
    (
        "gear_pair_missing_module.toml",
        4,
        "pair[0].module",
        "a module is needed",
    ),
    (
        "gear_pair_bad_type.toml",
        6,
        "pair[0].type",
        "unknown pair type 'hypoid'",
    ),
    (
        "gear_pair_tips_do_not_reach.toml",
        9,
        "pair[0].rack_withdrawal",
        "the tips do not reach each other: the transverse contact ratio would be -0.353472",
    ),
    (
        "gear_pair_crossed_find_helix.toml",
        10,
        "pair[0].find_helix_angle",
        "is not used by pairs of type 'crossed'",
    ),
    (
        "gear_pair_key_not_used.toml",
        7,
        "pair[0].diameter_factor",
        "is not used by pairs of type 'external'",
    ),
    (
        "gear_pair_rack_two_teeth.toml",
        7,
        "pair[0].teeth",
        "takes 1 tooth count",
    ),
    (
        "gear_pair_internal_fewer_teeth.toml",
        7,
        "pair[0].teeth",
        "needs more teeth",
    ),
    (
        "gear_pair_bad_shift.toml",
        7,
        "pair[0].shift",
        "\"no_undercut\"",
    ),
    (
        "gear_pair_helix_without_centre_distance.toml",
        7,
        "pair[0].find_helix_angle",
        "needs a centre_distance",
    ),
    (
        "gear_pair_bad_pressure_angle.toml",
        7,
        "pair[0].pressure_angle_deg",
        "45°",
    ),
    (
        "gear_pair_design_without_ratio.toml",
        4,
        "pair[0].ratio",
        "the speed ratio",
    ),
    (
        "gear_pair_worm_without_q.toml",
        5,
        "pair[0].diameter_factor",
        "q = d1/m",
    ),
    (
        "gear_pair_at_radius_inside_base.toml",
        8,
        "pair[0].at_radii",
        "gear 1: radius 90 mm is outside 93.9693 … 1100.0000 mm (the involute starts on the base circle",
    ),
    (
        "gear_pair_cycloidal_face_too_short.toml",
        8,
        "pair[0].rolling_radii",
        "traces gear 2's face only up to 2ρ = 3 mm above its pitch circle",
    ),
    (
        "gear_pair_pin_too_large.toml",
        8,
        "pair[0].pin_radius",
        "a quarter of the pitch p/4 = 3.1416 mm",
    ),
    (
        "gear_pair_roots_with_teeth.toml",
        8,
        "pair[0].teeth",
        "is not used by pairs of type 'roots'",
    ),
    (
        "gear_pair_lobes_on_involute.toml",
        8,
        "pair[0].lobes",
        "is not used by pairs of type 'external'",
    ),
];

#[test]
fn broken_gear_pair_scenarios_give_located_errors() {
    common::assert_broken_scenarios("gear_pair_", BROKEN, common::CheckSays::Refuses);
}

/// Issue 28: a contact ratio below 1 (the drive is not continuous) is a warning in the
/// text and the JSON; at or above 1 there is none.
#[test]
fn contact_ratio_below_one_is_warned() {
    let dir = std::env::temp_dir().join(format!("armsim_eps_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("rack.toml");
    let text = "kind = \"gear_pair\"\nmodule = 14\n\n[[pair]]\ntype = \"rack\"\nteeth = [20]\n\n[[pair]]\ntype = \"rack\"\nteeth = [20]\nrack_withdrawal = 12\n";
    std::fs::write(&p, text).unwrap();
    let r = armsim::scenarios::run_file(&p).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert!(r.json["pairs"][0].get("warnings").is_none(), "{}", r.json);
    let w = &r.json["pairs"][1]["warnings"][0];
    assert!(
        w.as_str().unwrap().contains("contact ratio is below 1"),
        "{w}"
    );
    assert!(
        r.text.contains("warning: the contact ratio is below 1"),
        "{}",
        r.text
    );
}

/// The design rule's tooth count: `2A/(m(1 + i)) = 120/(2 · 3.158) = 18.9994` with the
/// ratio given to three decimals is 19, not 18; then `z₂ = round(19 · 2.158) = 41` and the
/// standard pair fits `A = m(z₁ + z₂)/2 = 60` exactly: no shift is needed (truncating gave
/// 18/39 with a total shift of 1.76).
#[test]
fn design_takes_the_standard_pair_when_the_quotient_is_a_hair_below_an_integer() {
    let d = design(60.0, 2.0, 20f64.to_radians(), 2.158, 1.0, 0.25).unwrap();
    assert_eq!(d.teeth, [19, 41]);
    close(d.total_shift, 0.0, 1e-9, "x_t");
    close(d.centre_factor, 0.0, 1e-12, "λ");
    // A quotient well inside an interval still truncates: 2·61/(2·3.158) = 19.32 → 19.
    assert_eq!(
        design(61.0, 2.0, 20f64.to_radians(), 2.158, 1.0, 0.25)
            .unwrap()
            .teeth[0],
        19
    );
}

/// The involute's quantities at a radius: `ρ_y` is the length of the generating line
/// (the distance from the flank point to the base circle's tangent point, measured on the
/// flank's points), the polar angle of the flank point is `inv α_y`, and the listed
/// thickness at the pitch and tip radii is the pair's `thickness_pitch` and `thickness_tip`.
#[test]
fn involute_at_a_radius_matches_its_flank_points_and_the_gears_thicknesses() {
    let rb = 93.969_262_078_590_84_f64;
    for ry in [rb, 95.0, 100.0, 110.0, 150.0] {
        let i = involute_at(rb, ry).unwrap();
        // The involute point of roll angle t: rb (cos t + t sin t, sin t − t cos t).
        let t = i.roll_angle;
        let (px, py) = (rb * (t.cos() + t * t.sin()), rb * (t.sin() - t * t.cos()));
        close(px.hypot(py), ry, 1e-9, "radius of the point");
        close(py.atan2(px), i.involute, 1e-12, "polar angle = inv α_y");
        let (tx, ty) = (rb * t.cos(), rb * t.sin());
        close((px - tx).hypot(py - ty), i.curvature_radius, 1e-9, "ρ_y");
        close(i.involute, inv(i.pressure_angle), 0.0, "inv");
    }
    assert!(involute_at(rb, 90.0).is_none(), "inside the base circle");
    let v = run_json("scenarios/gear_pair_involute_at_radius.toml");
    let rows = &v["pairs"][0]["gears"][0]["at_radii"];
    close(
        f(&rows[1], "pressure_angle_deg"),
        20.0,
        1e-12,
        "α at the pitch",
    );
    close(f(&rows[1], "involute"), 0.014_904_383_867, 1e-12, "inv 20°");
    close(
        f(&rows[1], "thickness"),
        f(&v, "pairs.0.gears.0.thickness_pitch"),
        1e-12,
        "s",
    );
    close(
        f(&rows[3], "thickness"),
        f(&v, "pairs.0.gears.0.thickness_tip"),
        1e-12,
        "s_a",
    );
    close(f(&rows[3], "thickness"), 6.95, 0.005, "GG-4 s_a");
    close(
        f(&rows[3], "curvature_radius"),
        57.182,
        1e-3,
        "ρ at the tip",
    );
    close(
        f(&rows[0], "curvature_radius"),
        0.0,
        1e-6,
        "ρ on the base circle",
    );
    let internal = &v["pairs"][1]["gears"][1]["at_radii"];
    close(
        f(&internal[1], "thickness"),
        f(&v, "pairs.1.gears.1.thickness_tip"),
        1e-12,
        "internal s_a",
    );
    close(
        f(&internal[2], "thickness"),
        PI * 10.0 / 2.0,
        1e-9,
        "internal s at the pitch",
    );
}

/// Problems 219–220: the tooth count where two circles meet. Closed forms
/// `2(h_a* + c*)/(1 − cos α)`, `2h_a*/(1 − cos α)`, `2h_a*/sin²α`, and the answer checked
/// on the radii themselves (`r_f = r − 1.25 m` against `r_b = r cos α`, the internal tip
/// `r − m` against `r_b`).
#[test]
fn problems_219_220_which_tooth_count_puts_the_root_or_tip_on_the_base_circle() {
    let v = run_json("scenarios/gear_pair_219_220_tooth_count_queries.toml");
    let q = &v["queries"];
    let c20 = 20f64.to_radians().cos();
    close(
        f(q, "0.teeth_exact"),
        2.5 / (1.0 - c20),
        1e-9,
        "219 closed form",
    );
    close(f(q, "0.teeth_exact"), 41.45, 0.005, "219 book 41.45");
    assert_eq!(q[0]["teeth"], 42);
    assert_eq!(q[0]["largest_below"], 41);
    let (m, a) = (10.0, 20f64.to_radians());
    let root_minus_base = |z: f64| m * z / 2.0 - 1.25 * m - m * z / 2.0 * a.cos();
    assert!(root_minus_base(41.0) < 0.0 && root_minus_base(42.0) > 0.0);
    close(
        f(q, "1.teeth_exact"),
        2.0 / (1.0 - c20),
        1e-9,
        "220 closed form",
    );
    assert_eq!(q[1]["teeth"], 34, "220: book 34");
    let tip_minus_base = |z: f64| m * z / 2.0 - m - m * z / 2.0 * a.cos();
    assert!(tip_minus_base(33.0) < 0.0 && tip_minus_base(34.0) > 0.0);
    close(
        f(q, "2.teeth_exact"),
        2.0 / a.sin().powi(2),
        1e-9,
        "undercut",
    );
    assert_eq!(q[2]["teeth"], 18);
    // A helical gear (β = 15°) with a shift: z = 2(h_a* + c* − x) cos β/(1 − cos α_t),
    // checked on its radii r = m_n z/(2 cos β), r_f = r − (1.25 − x) m_n, r_b = r cos α_t.
    let text = "kind = \"gear_pair\"\n[[query]]\nfind = \"root_equals_base\"\nhelix_angle_deg = 15\nshift = 0.3\n";
    let sc = armsim::scenarios::gear_pair::parse("helical.toml", text).unwrap();
    let ans = sc.queries[0].answer;
    let b = 15f64.to_radians();
    let at = (a.tan() / b.cos()).atan();
    close(
        ans.exact,
        2.0 * 0.95 * b.cos() / (1.0 - at.cos()),
        1e-9,
        "helical",
    );
    let gap = |z: f64| {
        let r = m * z / (2.0 * b.cos());
        r - 0.95 * m - r * at.cos()
    };
    assert!(gap(ans.answer as f64) >= 0.0 && gap(ans.largest_below as f64) < 0.0);
}

/// Ch. 9, a helical gear on a crossed rack: the closed forms of the scenario's header, and
/// an independent route in the pitch plane — gear velocity `v1 x̂`, rack velocity
/// `v2 (cos Σ, −sin Σ)`, gear tooth line `(sin β1, cos β1)`: the relative velocity has no
/// component across the tooth line and its length is the sliding speed.
#[test]
fn crossed_rack_speeds_and_modules() {
    let v = run_json("scenarios/gear_pair_crossed_rack.toml");
    let p = &v["pairs"][0];
    let (b1, b2) = (15f64.to_radians(), 30f64.to_radians());
    let sig = b1 + b2;
    close(f(p, "shaft_angle_deg"), 45.0, 1e-12, "Σ");
    close(f(p, "pitch_radius"), 51.764, 1e-3, "r1");
    close(f(p, "transverse_module"), 5.0 / b1.cos(), 1e-12, "m_t1");
    close(f(p, "rack_module"), 5.7735, 1e-4, "rack module");
    close(f(p, "travel_per_revolution"), 362.76, 0.01, "travel");
    let (v1, v2, vs) = (
        f(p, "pitch_line_speed"),
        f(p, "rack_speed"),
        f(p, "sliding_speed"),
    );
    close(v1, 0.51764, 1e-5, "v1");
    close(v2, 0.57735, 1e-5, "v2");
    close(vs, 0.42265, 1e-5, "v_s");
    let rel = [v1 - v2 * sig.cos(), v2 * sig.sin()];
    let across = rel[0] * b1.cos() - rel[1] * b1.sin();
    close(across, 0.0, 1e-12, "no velocity across the teeth");
    close(rel[0].hypot(rel[1]), vs, 1e-12, "sliding = relative speed");
    // The travel per revolution is the rack speed over the gear's angular speed.
    close(
        v2 * 1000.0 * 2.0 * PI / 10.0,
        f(p, "travel_per_revolution"),
        1e-9,
        "v2 = ω travel/2π",
    );
    // β2 = 0: a straight rack moving at Σ = β1: v2 = v1 cos β1, v_s = v1 sin β1.
    let text =
        std::fs::read_to_string(common::root().join("scenarios/gear_pair_crossed_rack.toml"))
            .unwrap()
            .replace("[15, 30]", "[15, 0]");
    let r = armsim::scenarios::gear_pair_report::report(
        &armsim::scenarios::gear_pair::parse("r.toml", &text).unwrap(),
        "gear_pair",
    );
    let p = &r.json["pairs"][0];
    close(f(p, "rack_speed"), v1 * b1.cos(), 1e-12, "straight rack v2");
    close(
        f(p, "sliding_speed"),
        v1 * b1.sin(),
        1e-12,
        "straight rack v_s",
    );
}
