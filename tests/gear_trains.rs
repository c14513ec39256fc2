//! Gear trains (docs/reference_data.md §M1): every published checkpoint through `armsim run
//! --json` on its bundled scenario, and independent routes — the pitch-point velocity
//! check of the graphical method, closed-form planetary efficiencies, the mobility count
//! against the null-space dimension — plus the broken files.

use armsim::machines::gearing::rational::Ratio;
use armsim::machines::gearing::torques::solve_torques;
use armsim::machines::gearing::willis::relative_ratio;
use armsim::scenarios::gear_train::parse;
use serde_json::Value;
use std::f64::consts::PI;

mod common;
use common::{root, run_json};

fn member<'a>(v: &'a Value, name: &str) -> &'a Value {
    v["members"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["name"] == name)
        .unwrap_or_else(|| panic!("no member {name}"))
}

fn speed(v: &Value, name: &str) -> f64 {
    member(v, name)["speed"].as_f64().unwrap()
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

fn scenario(rel: &str) -> armsim::scenarios::gear_train_report::TrainScenario {
    let text = std::fs::read_to_string(root().join(rel)).unwrap();
    parse(rel, &text).unwrap_or_else(|e| panic!("{e}"))
}

fn with(rel: &str, from: &str, to: &str) -> armsim::scenarios::gear_train_report::TrainScenario {
    let text = std::fs::read_to_string(root().join(rel)).unwrap();
    assert!(text.contains(from), "{rel} has no '{from}'");
    let text = text.replacen(from, to, 1);
    parse(rel, &text).unwrap_or_else(|e| panic!("{e}"))
}

// ---------------------------------------------------------------------------------------
// Published checkpoints.

#[test]
fn gt1_coaxiality_gives_z5_100_and_n5_minus_10_rpm() {
    let v = run_json("scenarios/gear_train_gt1_compound_internal.toml");
    assert_eq!(v["derived_teeth"][0]["gear"], "5");
    assert_eq!(v["derived_teeth"][0]["teeth"], 100);
    assert_eq!(v["transmission"]["gear_ratio"]["exact"], "-33");
    close(speed(&v, "5"), -10.0, 1e-12, "n5");
    assert_eq!(v["classification"], "ordinary");
    // The book's graphical check: v1 = ω1 r1 = 330·π/30·0.08 = 2.76 m/s ("2.7").
    close(330.0 * std::f64::consts::PI / 30.0 * 0.08, 2.76, 0.01, "v1");
}

#[test]
fn gt3_differential_carrier_turns_at_51_8_per_second() {
    let v = run_json("scenarios/gear_train_gt3_differential.toml");
    assert_eq!(v["mobility"]["structural"], 2);
    assert_eq!(v["mobility"]["kinematic"], 2);
    assert_eq!(v["classification"], "differential");
    assert_eq!(v["willis"][0]["ratio"]["exact"], "-62/99");
    close(
        v["willis"][0]["ratio"]["value"].as_f64().unwrap(),
        -0.6263,
        5e-5,
        "i13C",
    );
    let wc = speed(&v, "C");
    assert!((wc - 51.8).abs() <= 0.02 * 51.8, "wC = {wc}");
    close(
        wc,
        (150.0 - 62.0 / 99.0 * 105.0) / (1.0 + 62.0 / 99.0),
        1e-9,
        "closed form",
    );
}

#[test]
fn gt4_high_ratio_differential_is_exactly_9112() {
    let v = run_json("scenarios/gear_train_gt4_high_ratio_differential.toml");
    assert_eq!(v["transmission"]["gear_ratio"]["exact"], "9112");
    assert_eq!(member(&v, "C")["ratio_from_input"]["exact"], "9112");
    close(speed(&v, "C"), 1.0, 1e-9, "carrier");
    // The bevel side gears average: wC = (w2 + w4)/2.
    close(
        speed(&v, "C"),
        (speed(&v, "2") + speed(&v, "4")) / 2.0,
        1e-9,
        "average",
    );
    // Such a differential locks itself: the carrier cannot drive gear 1 back.
    assert_eq!(v["transmission"]["self_locking"], true);
}

#[test]
fn gt5_planetary_torques_and_pin_loads() {
    let v = run_json("scenarios/gear_train_gt5_planetary_torques_112.toml");
    close(
        member(&v, "1")["torque_Nm"].as_f64().unwrap(),
        -40.0,
        1e-9,
        "112 M1",
    );
    close(
        v["load"]["planet_bearings"][0]["load_N"].as_f64().unwrap(),
        500.0,
        1e-9,
        "112 R_B",
    );
    let v = run_json("scenarios/gear_train_gt5_planetary_torques_122.toml");
    close(
        member(&v, "C")["torque_Nm"].as_f64().unwrap().abs(),
        80.0,
        1e-9,
        "122 M_C",
    );
    close(
        v["load"]["planet_bearings"][0]["load_N"].as_f64().unwrap(),
        200.0,
        1e-9,
        "122 R_B",
    );
    let v = run_json("scenarios/gear_train_gt5_planetary_torques_123.toml");
    close(
        member(&v, "1")["torque_Nm"].as_f64().unwrap().abs(),
        8.6,
        0.05,
        "123 |M1|",
    );
    close(
        v["load"]["planet_bearings"][0]["load_N"].as_f64().unwrap(),
        200.0,
        1e-9,
        "123 R_B",
    );
    assert_eq!(v["transmission"]["gear_ratio"]["exact"], "-13/2");
}

#[test]
fn problem_148_and_147_reduced_torques() {
    // 148: M_C = 40 N m reduced to gear 1 of the 122 train is 10 N m.
    let sc = scenario("scenarios/gear_train_gt5_planetary_torques_122.toml");
    let om = sc.omega();
    let c = sc.train.body("C").unwrap();
    let one = sc.train.body("1").unwrap();
    let t = solve_torques(&sc.train, &om, &[(c, 40.0)], &[one]).unwrap();
    close(t.body[one].abs(), 10.0, 1e-9, "148");
    let v = run_json("scenarios/gear_train_147_worm.toml");
    close(
        member(&v, "1")["torque_Nm"].as_f64().unwrap().abs(),
        2.0,
        1e-12,
        "147",
    );
    assert_eq!(member(&v, "2")["sense_defined"], false);
}

#[test]
fn answer_section_trains_match_the_book() {
    let v = run_json("scenarios/gear_train_235_worm_bevel.toml");
    assert_eq!(
        v["transmission"]["gear_ratio"]["value"]
            .as_f64()
            .unwrap()
            .abs(),
        720.0
    );
    close(speed(&v, "5").abs(), 2.0, 1e-12, "235 n5");
    let z: Vec<u64> = v["derived_teeth"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["teeth"].as_u64().unwrap())
        .collect();
    assert_eq!(z, [48, 48]);

    let v = run_json("scenarios/gear_train_238_bevel_planetary.toml");
    assert_eq!(v["transmission"]["gear_ratio"]["exact"], "7/3");
    let other = with(
        "scenarios/gear_train_238_bevel_planetary.toml",
        "kind = \"bevel\"\nsign = 1",
        "kind = \"bevel\"\nsign = -1",
    );
    let c = other.train.body("C").unwrap();
    let r = Ratio::ONE.over(other.speeds.map[c][0]).unwrap().unwrap();
    assert_eq!(
        r,
        Ratio::new(-1, 3).unwrap(),
        "238, planet on the other side"
    );

    let v = run_json("scenarios/gear_train_240_triple_planet.toml");
    close(speed(&v, "C"), -195.0, 1e-9, "240 nC");
    close(speed(&v, "4"), -60.0, 1e-9, "240 n4");
    assert_eq!(v["willis"][0]["ratio"]["exact"], "13");

    let v = run_json("scenarios/gear_train_282_carrier_speed.toml");
    close(speed(&v, "C"), -10.0, 1e-12, "282");

    let v = run_json("scenarios/gear_train_247_fan.toml");
    assert_eq!(v["derived_teeth"][0]["teeth"], 30);
    close(speed(&v, "C"), 1856.25, 1e-9, "247 nC");
    close(speed(&v, "2"), 4950.0, 1e-9, "247 n2");

    let v = run_json("scenarios/gear_train_248_planetary.toml");
    close(speed(&v, "C"), 40.0, 1e-12, "248 nC");
    let v = run_json("scenarios/gear_train_248_stop_carrier.toml");
    close(speed(&v, "3"), -60.0, 1e-12, "248 n3 stops C");

    let v = run_json("scenarios/gear_train_250_compound_planet.toml");
    close(speed(&v, "C"), 100.0, 1e-12, "250 nC");
    close(speed(&v, "2"), -300.0, 1e-12, "250 n2");
    let kinds: Vec<&str> = v["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["kind"].as_str().unwrap())
        .collect();
    assert!(
        kinds.contains(&"assembly") && kinds.contains(&"neighbours"),
        "{kinds:?}"
    );
}

/// A gear rigid with a carrier (ch. 10 mixed train): pair 1–2 drives the carrier H that
/// gear 2 is part of; sun 3 out, planet 4, fixed ring 5. Willis by hand:
/// `ω_H = −(z1/z2) ω1`, `ω3 = (1 + z5/z3) ω_H`, `ω4 = ω_H (1 − z5/z4)`.
#[test]
fn a_gear_rigid_with_a_carrier_drives_the_planetary() {
    let rel = "scenarios/gear_train_mixed_gear_on_carrier.toml";
    let v = run_json(rel);
    assert_eq!(v["classification"], "mixed");
    assert_eq!(member(&v, "H")["kind"], "carrier");
    assert_eq!(member(&v, "H")["gears"][0]["name"], "2");
    close(speed(&v, "H"), -400.0, 1e-9, "ω_H");
    close(speed(&v, "3"), -1600.0, 1e-9, "ω3");
    close(speed(&v, "4"), 800.0, 1e-9, "ω4");
    assert_eq!(v["transmission"]["gear_ratio"]["exact"], "-3/4");
    assert_eq!(v["willis"][0]["ratio"]["exact"], "-3");
    // Other tooth counts, same closed form: z1 = 30, z3 = 30, z4 = 15 (ring 60 = 30 + 2·15).
    let text = std::fs::read_to_string(root().join(rel))
        .unwrap()
        .replacen("name = \"1\"\nteeth = 20", "name = \"1\"\nteeth = 30", 1)
        .replacen("name = \"3\"\nteeth = 20", "name = \"3\"\nteeth = 30", 1)
        .replacen("name = \"4\"\nteeth = 20", "name = \"4\"\nteeth = 15", 1)
        .replace("planets = 4", "planets = 3");
    let sc = parse(rel, &text).unwrap_or_else(|e| panic!("{e}"));
    let (z1, z2, z3, z4, z5) = (30.0, 60.0, 30.0, 15.0, 60.0);
    let wh = -z1 / z2 * 1200.0;
    let b = |n: &str| sc.train.body(n).unwrap();
    close(sc.speeds.values[b("H")], wh, 1e-9, "ω_H (30/60)");
    close(
        sc.speeds.values[b("3")],
        (1.0 + z5 / z3) * wh,
        1e-9,
        "ω3 (30/60)",
    );
    close(
        sc.speeds.values[b("4")],
        wh * (1.0 - z5 / z4),
        1e-9,
        "ω4 (30/60)",
    );
}

fn selection(text: &str) -> Value {
    let sc = armsim::scenarios::gear_train::selection_file("sel.toml", text)
        .unwrap_or_else(|e| panic!("{e}"))
        .expect("a [selection] file");
    armsim::scenarios::gear_train_selection::report(&sc, "gear_train").json["selection"].clone()
}

fn teeth_of(entry: &Value) -> Vec<u64> {
    entry["teeth"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["teeth"].as_u64().unwrap())
        .collect()
}

/// 2K-H planetary conditions by hand: coaxial, assembly, neighbours, z ≥ 17.
fn planetary_ok(z: &[u64], k: u64) -> bool {
    let (z1, z2, z3) = (z[0], z[1], z[2]);
    z.iter().all(|&x| x >= 17)
        && z3 == z1 + 2 * z2
        && (z1 + z3) % k == 0
        && (z2 as f64 + 2.0) < (z1 + z2) as f64 * (PI / k as f64).sin()
}

/// Choosing tooth counts (ch. 10): the classic 2K-H selection `u = 1 + z3/z1` with k
/// planets, against the closed-form conditions and an independent smallest-ring search.
#[test]
fn planetary_tooth_selection_meets_every_condition_and_is_the_smallest() {
    let v = run_json("scenarios/gear_train_selection_planetary.toml");
    let s = &v["selection"];
    assert_eq!(teeth_of(&s["best"]), [18, 18, 54], "u = 4, k = 3");
    close(s["best"]["ratio"].as_f64().unwrap(), 4.0, 1e-12, "u'");
    for c in s["candidates"].as_array().unwrap() {
        let z = teeth_of(c);
        assert!(planetary_ok(&z, 3), "{z:?}");
        close(1.0 + z[2] as f64 / z[0] as f64, 4.0, 1e-12, "exact ratio");
    }
    // u = 5, k = 3: the proportion 1 : 3/2 : 4 : 5/3 needs z1 even and a multiple of 3.
    let text =
        std::fs::read_to_string(root().join("scenarios/gear_train_selection_planetary.toml"))
            .unwrap();
    let s = selection(&text.replace("ratio = 4", "ratio = 5"));
    assert_eq!(teeth_of(&s["best"]), [18, 27, 72]);
    // With 2 % tolerance the ring shrinks; an independent search finds the same ring.
    let s = selection(
        &text
            .replace("ratio = 4", "ratio = 5")
            .replace("tolerance = 0", "tolerance = 0.02"),
    );
    let best = teeth_of(&s["best"]);
    let u = 1.0 + best[2] as f64 / best[0] as f64;
    assert!(
        planetary_ok(&best, 3) && (u - 5.0).abs() / 5.0 <= 0.02,
        "{best:?}"
    );
    let mut smallest_ring = u64::MAX;
    for z1 in 17..=120u64 {
        for z2 in 17..=120u64 {
            let z = [z1, z2, z1 + 2 * z2];
            let u = 1.0 + z[2] as f64 / z1 as f64;
            if z[2] <= 120 && planetary_ok(&z, 3) && (u - 5.0).abs() / 5.0 <= 0.02 {
                smallest_ring = smallest_ring.min(z[2]);
            }
        }
    }
    assert_eq!(best[2], smallest_ring);
    assert!(best[2] < 72, "the tolerance buys a smaller ring: {best:?}");
}

/// Reverted two-stage and compound planetary selections meet their conditions.
#[test]
fn two_stage_and_compound_planetary_selections_meet_their_conditions() {
    let v = run_json("scenarios/gear_train_selection_two_stage.toml");
    let s = &v["selection"];
    let mut smallest = u64::MAX;
    for z1 in 17..=120u64 {
        for z2 in 17..=120u64 {
            for z3 in 17..=120u64 {
                let Some(z4) = (z1 + z2).checked_sub(z3) else {
                    continue;
                };
                let u = (z2 * z4) as f64 / (z1 * z3) as f64;
                if (17..=120).contains(&z4) && (u - 12.0).abs() / 12.0 <= 0.01 {
                    smallest = smallest.min(z2.max(z4));
                }
            }
        }
    }
    for c in s["candidates"].as_array().unwrap() {
        let z = teeth_of(c);
        let u = (z[1] * z[3]) as f64 / (z[0] * z[2]) as f64;
        assert_eq!(z[0] + z[1], z[2] + z[3], "coaxial {z:?}");
        assert!((u - 12.0).abs() / 12.0 <= 0.01 && z.iter().all(|&x| x >= 17));
        close(c["ratio"].as_f64().unwrap(), u, 1e-12, "u'");
    }
    assert_eq!(*teeth_of(&s["best"]).iter().max().unwrap(), smallest);
    // Compound planet 2/2' with u = 1 + z2 z3/(z1 z2') = 16, 3 planets, within 1 %.
    let s = selection(
        "kind = \"gear_train\"\n[selection]\nscheme = \"compound_planetary\"\nratio = 16\ntolerance = 0.01\nplanets = 3\nmax_teeth = 100\n",
    );
    for c in s["candidates"].as_array().unwrap() {
        let z = teeth_of(c);
        let (z1, z2, z2b, z3) = (z[0], z[1], z[2], z[3]);
        let u = 1.0 + (z2 * z3) as f64 / (z1 * z2b) as f64;
        assert!((u - 16.0).abs() / 16.0 <= 0.01, "{z:?}");
        assert_eq!(z1 + z2, z3 - z2b, "coaxial {z:?}");
        let g = (1..=z2.min(z2b))
            .rev()
            .find(|d| z2 % d == 0 && z2b % d == 0)
            .unwrap();
        assert_eq!((z1 * z2b + z3 * z2) % (3 * g), 0, "assembly {z:?}");
        assert!((z2.max(z2b) as f64 + 2.0) < (z1 + z2) as f64 * (PI / 3.0).sin());
    }
}

// ---------------------------------------------------------------------------------------
// Independent routes.

/// The graphical method: with every axis placed (central gears on the main axis, each
/// planet at its arm on the carrier), the two gears of every mesh have the same velocity
/// at their pitch point.
#[test]
fn pitch_points_have_equal_velocities_in_every_planetary_mesh() {
    for rel in [
        "scenarios/gear_train_gt3_differential.toml",
        "scenarios/gear_train_gt5_planetary_torques_112.toml",
        "scenarios/gear_train_gt5_planetary_torques_123.toml",
        "scenarios/gear_train_240_triple_planet.toml",
        "scenarios/gear_train_247_fan.toml",
        "scenarios/gear_train_250_compound_planet.toml",
    ] {
        let sc = scenario(rel);
        let t = &sc.train;
        let w = &sc.speeds.values;
        // Axis positions (mm): the main axis at the origin, planets at (arm, 0).
        let arm = |b: usize| armsim::machines::gearing::assembly::planet_arm(t, b).unwrap();
        let centre = |b: usize| {
            if t.bodies[b].carrier.is_some() {
                (arm(b), 0.0)
            } else {
                (0.0, 0.0)
            }
        };
        let vel = |b: usize, p: (f64, f64)| {
            let o = centre(b);
            let (mut vx, mut vy) = (-w[b] * (p.1 - o.1), w[b] * (p.0 - o.0));
            if let Some(c) = t.bodies[b].carrier {
                vx += -w[c] * o.1;
                vy += w[c] * o.0;
            }
            (vx, vy)
        };
        for m in &t.meshes {
            let [a, b] = m.gears;
            let (ba, bb) = (t.gears[a].body, t.gears[b].body);
            // Pitch point on the line of centres.
            let (planet_gear, other) = if t.bodies[ba].carrier.is_some() {
                (a, b)
            } else {
                (b, a)
            };
            let pb = t.gears[planet_gear].body;
            let rp = t.radius(planet_gear).unwrap();
            let x = if t.gears[other].internal {
                arm(pb) + rp
            } else {
                arm(pb) - rp
            };
            let p = (x, 0.0);
            let (va, vb) = (vel(ba, p), vel(bb, p));
            let scale = w.iter().fold(1.0_f64, |s, v| s.max(v.abs())) * 1000.0;
            assert!(
                (va.0 - vb.0).abs() + (va.1 - vb.1).abs() <= 1e-12 * scale,
                "{rel}: mesh {}–{}: {va:?} vs {vb:?}",
                t.gears[a].name,
                t.gears[b].name
            );
        }
    }
}

#[test]
fn simple_planetary_efficiency_matches_the_relative_power_formula() {
    // Sun 1 drives, ring 3 fixed, carrier out; eta per mesh, eta0 = eta² through both.
    let eta: f64 = 0.97;
    let sc = with(
        "scenarios/gear_train_gt5_planetary_torques_112.toml",
        "output = \"C\"",
        "output = \"C\"\nmesh_efficiency = 0.97",
    );
    let t = &sc.train;
    let om = sc.omega();
    let (one, c) = (t.body("1").unwrap(), t.body("C").unwrap());
    let three = t.body("3").unwrap();
    let i13 = relative_ratio(t, one, three, c).unwrap().unwrap().to_f64();
    close(i13, -56.0 / 16.0, 1e-12, "i13C");
    let eta0 = eta * eta;
    let expected = (1.0 - i13 * eta0) / (1.0 - i13);
    let fwd = solve_torques(t, &om, &[(c, -1.0)], &[one]).unwrap();
    let got = -fwd.body[c] * om[c] / (fwd.body[one] * om[one]);
    close(got, expected, 1e-12, "forward");
    assert!(fwd.converged);
    // Reverse (carrier drives the sun): the relative power flows the other way.
    let k = 56.0 / 16.0;
    let rev = solve_torques(t, &om, &[(one, -1.0)], &[c]).unwrap();
    let got = -rev.body[one] * om[one] / (rev.body[c] * om[c]);
    close(got, (1.0 + k) / (1.0 + k / eta0), 1e-12, "reverse");
}

#[test]
fn ordinary_train_efficiency_is_the_product_of_its_meshes() {
    let sc = with(
        "scenarios/gear_train_gt1_compound_internal.toml",
        "output = \"5\"",
        "output = \"5\"\nmesh_efficiency = 0.98",
    );
    let t = &sc.train;
    let om = sc.omega();
    let (one, five) = (t.body("1").unwrap(), t.body("5").unwrap());
    let fwd = solve_torques(t, &om, &[(five, 1.0)], &[one]).unwrap();
    let eta = -fwd.body[five] * om[five] / (fwd.body[one] * om[one]);
    close(eta, 0.98_f64.powi(4), 1e-12, "series");
    // Ideal torques follow the ratio: M1 = −M5/i15.
    let ideal = solve_torques(
        &scenario("scenarios/gear_train_gt1_compound_internal.toml").train,
        &om,
        &[(five, 1.0)],
        &[one],
    )
    .unwrap();
    close(ideal.body[one], 1.0 / 33.0, 1e-12, "ideal M1");
}

#[test]
fn mobility_count_equals_the_null_space_dimension() {
    for entry in std::fs::read_dir(root().join("scenarios")).unwrap() {
        let p = entry.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if !name.starts_with("gear_train_") || name.starts_with("gear_train_selection_") {
            continue; // the selection files describe no train (their own tests above)
        }
        let sc = scenario(&format!("scenarios/{name}"));
        let (w, ..) = sc.train.structural_mobility();
        assert_eq!(w, sc.kin.dof() as i64, "{name}");
        // Willis' relation holds for every mesh with the solved speeds.
        for e in 0..sc.train.meshes.len() {
            let f = sc.train.mesh_frame(e).unwrap();
            let [ga, gb] = sc.train.meshes[e].gears;
            let wh = f.carrier.map_or(0.0, |h| sc.speeds.values[h]);
            let s = f.sign.unwrap_or(1) as f64;
            let lhs = sc.train.z(ga) as f64 * (sc.speeds.values[f.bodies[0]] - wh);
            let rhs = s * sc.train.z(gb) as f64 * (sc.speeds.values[f.bodies[1]] - wh);
            assert!(
                (lhs - rhs).abs() <= 1e-9 * (1.0 + lhs.abs()),
                "{name} mesh {e}"
            );
        }
    }
}

#[test]
fn reflected_inertia_is_the_kinetic_energy_referred_to_the_input() {
    // Planetary 112 with inertias: sun 0.01, planet 0.02 (3 kg), carrier 0.5 kg m².
    let text =
        std::fs::read_to_string(root().join("scenarios/gear_train_gt5_planetary_torques_112.toml"))
            .unwrap();
    let text = text
        .replacen(
            "name = \"1\"\nteeth = 16",
            "name = \"1\"\nteeth = 16\ninertia = 0.01",
            1,
        )
        .replacen(
            "teeth = 20\ncarrier = \"C\"",
            "teeth = 20\ncarrier = \"C\"\ninertia = 0.02\nmass = 3.0",
            1,
        )
        .replacen(
            "[[carrier]]\nname = \"C\"",
            "[[carrier]]\nname = \"C\"\ninertia = 0.5",
            1,
        );
    let dir = std::env::temp_dir().join(format!("armsim_gt_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("inertia.toml");
    std::fs::write(&f, text).unwrap();
    let v = run_json(f.to_str().unwrap());
    // ω2/ω1 = −2.5/4.5, ωC/ω1 = 1/4.5; planet orbit radius 0.36 m.
    let (r2, rc) = (-180.0 / 450.0, 1.0 / 4.5);
    let expected = 0.01 + 0.02 * r2 * r2 + 3.0 * 0.36 * 0.36 * rc * rc + 0.5 * rc * rc;
    close(
        v["transmission"]["inertia_input_side"].as_f64().unwrap(),
        expected,
        1e-12,
        "J_in",
    );
    close(
        v["transmission"]["inertia_output_side"].as_f64().unwrap(),
        expected * 4.5 * 4.5,
        1e-10,
        "J_out",
    );
    let _ = std::fs::remove_dir_all(dir);
}

// ---------------------------------------------------------------------------------------
// Broken files.

#[test]
fn a_planetary_train_is_an_arm_joints_transmission() {
    // Closed forms (scenarios/gear_train_joint_planetary.toml): N = 1 + 80/20 = 5,
    // η = (1 + 4 · 0.98 · 0.99)/5, J = J1 + JC/N² + 4 (J2 (1/3)² + m2 a²/N²).
    let n = 5.0;
    let eta = (1.0 + 4.0 * 0.98 * 0.99) / 5.0;
    let j = 2e-5 + 4e-4 / 25.0 + 4.0 * (3e-5 / 9.0 + 0.05 * 0.025f64.powi(2) / 25.0);
    let v = run_json("scenarios/planar_2r_geared_shoulder.toml");
    let t = &v["transmissions"][0];
    assert_eq!(t["joint"], "joint1");
    assert_eq!(
        (t["input"].as_str(), t["output"].as_str()),
        (Some("1"), Some("C"))
    );
    close(t["gear_ratio"].as_f64().unwrap(), n, 1e-12, "N");
    close(t["efficiency_forward"].as_f64().unwrap(), eta, 1e-12, "η");
    close(t["inertia_input_side"].as_f64().unwrap(), j, 1e-15, "J");
    assert_eq!(t["self_locking"], false);
    // The arm's dynamics use them: the rotor effect's armature (I_m + J) N² on the mass
    // matrix diagonal, and the motor torque τ/(N η) when driving.
    let path = common::root().join("scenarios/planar_2r_geared_shoulder.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let scene = armsim::scenarios::arm::load(&path, &text).unwrap();
    let r = scene.effects.rotor.as_ref().unwrap();
    assert_eq!(r.gear_ratio, vec![n, 20.0]);
    close(r.efficiency[0], eta, 1e-12, "rotor η");
    close(r.inertia[0], 1e-4 + j, 1e-15, "rotor I_m + J");
    let mut d = armsim::model::data::Data::new(&scene.model);
    let q = [0.3, -0.7];
    let with = armsim::dynamics::mass_matrix(&scene.model, &mut d, &scene.effects, &q).clone();
    let without = armsim::dynamics::mass_matrix(
        &scene.model,
        &mut d,
        &armsim::dynamics::Effects::default(),
        &q,
    )
    .clone();
    close(
        with[(0, 0)] - without[(0, 0)],
        (1e-4 + j) * n * n,
        1e-12,
        "armature",
    );
    close(
        with[(1, 1)] - without[(1, 1)],
        5e-5 * 400.0,
        1e-12,
        "elbow armature",
    );
    close(
        r.motor_torque(0, 10.0, 1.0),
        10.0 / (n * eta),
        1e-12,
        "motor torque",
    );
}

const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "gear_train_unknown_key.toml",
        6,
        "gear.teth",
        "unknown field `teth`",
    ),
    (
        "gear_train_not_coaxial.toml",
        39,
        "mesh[1].gears",
        "(A = 24 mm and 23.5 mm): violated",
    ),
    (
        "gear_train_assembly.toml",
        33,
        "carrier[0].planets",
        "cannot be equally spaced",
    ),
    (
        "gear_train_neighbours.toml",
        33,
        "carrier[0].planets",
        "neighbouring planets collide",
    ),
    (
        "gear_train_too_few_inputs.toml",
        42,
        "input[0].member",
        "give 2 input speeds, not 1",
    ),
    (
        "gear_train_bevel_without_sign.toml",
        38,
        "mesh[1].sign",
        "needs `sign = 1` or `-1`",
    ),
    (
        "gear_train_unknown_gear.toml",
        13,
        "mesh[0].gears",
        "'9' is not a [[gear]]",
    ),
    (
        "gear_train_missing_teeth.toml",
        8,
        "gear[1].teeth",
        "tooth count of '2' is missing",
    ),
    (
        "gear_train_two_internal.toml",
        15,
        "mesh[0].gears",
        "two internal gears",
    ),
    (
        "gear_train_bad_sign.toml",
        15,
        "mesh[0].sign",
        "must be 1 or -1",
    ),
    (
        "gear_train_unknown_carrier.toml",
        11,
        "gear[1].carrier",
        "'X' is not a [[carrier]]",
    ),
    (
        "gear_train_fixed_input.toml",
        29,
        "input[0].member",
        "'1' is fixed",
    ),
    (
        "gear_train_modules_differ.toml",
        15,
        "mesh[0].gears",
        "modules differ",
    ),
    (
        "gear_train_bad_speed_unit.toml",
        3,
        "speed_unit",
        "expected \"rpm\" or \"rad/s\"",
    ),
    (
        "gear_train_carrier_named_like_gear.toml",
        14,
        "carrier[0].name",
        "a gear rigid with this carrier says `body = \"H\"`",
    ),
    (
        "gear_train_selection_with_gears.toml",
        4,
        "gear",
        "describes no train: remove `gear`",
    ),
    (
        "gear_train_selection_impossible.toml",
        4,
        "selection.ratio",
        "no planetary tooth counts in 17 … 20",
    ),
    (
        "gear_train_nested_carrier.toml",
        16,
        "carrier[0].name",
        "nested carriers are not supported",
    ),
];

#[test]
fn broken_gear_train_scenarios_give_located_errors() {
    common::assert_broken_scenarios("gear_train_", BROKEN, common::CheckSays::Refuses);
}
