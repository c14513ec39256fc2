//! Linkage analyses of issue 29 (problem book ch. 1, 2, 4) through the bundled scenarios:
//! every relative instant centre `P_ij` (velocities through `P_ij` against the velocity
//! solution, Aronhold–Kennedy's three-centres line), the structure (Assur groups and the
//! class), the reduced moment of inertia and reduced moment of a slider-crank against
//! the closed form, and machine motion through a gear with a position-dependent inertia
//! (closed form, the un-geared equivalent, the energy balance).

use armsim::machines::instant_centres::{all_centres, three_centres_error, RelativeCentre};
use armsim::machines::linkage::sweep::Tracker;
use armsim::machines::linkage::{perp, Vec2, GROUND};
use armsim::scenarios::linkage::{parse, report::report, LinkageScenario, NAME};
use serde_json::Value;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scenario(rel: &str) -> LinkageScenario {
    let text = std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
    parse(rel, &text).unwrap_or_else(|e| panic!("{e}"))
}

fn json(rel: &str) -> Value {
    report(&scenario(rel), NAME).json
}

fn inline(text: &str) -> Value {
    let sc = parse("inline.toml", text).unwrap_or_else(|e| panic!("{e}"));
    report(&sc, NAME).json
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn every_instant_centre_of_the_oil_pump_gives_the_solved_velocities() {
    let sc = scenario("scenarios/linkage_instant_centres_oil_pump.toml");
    let m = sc.mechanism.as_ref().unwrap();
    let l = &m.linkage;
    let t = Tracker::assemble(l, &m.assembly, 150f64.to_radians(), m.sweep.newton).unwrap();
    let st = t.state();
    let qd = st.qd(m.speed);
    let centres = all_centres(l, &st.q, &st.dq);
    assert_eq!(centres.len(), 15, "six bodies, 15 centres");
    // v_i(M) − v_j(M) = (ω_i − ω_j) perp(M − P_ij) for points M of either body, with the
    // velocities of the velocity solution (v_j(M) from a point Q of j: v_Q + ω_j perp(M − Q)).
    let omega = |b: usize| if b == GROUND { 0.0 } else { qd[3 * b + 2] };
    let field = |b: usize, m: Vec2| -> Vec2 {
        if b == GROUND {
            return Vec2::zeros();
        }
        let (n, p) = &l.links[b].points[0];
        let _ = n;
        let q = l.point_position(&st.q, b, p);
        l.point_velocity(&st.q, &qd, b, p) + perp(&(m - q)) * omega(b)
    };
    let (mut checked, mut infinite) = (0, 0);
    for (i, j, c) in &centres {
        let p = match c {
            RelativeCentre::Point(p) => p,
            RelativeCentre::AtInfinity(d) => {
                // Only the slider translates on the frame: a uniform relative velocity,
                // across the direction of the centre.
                assert_eq!((l.body_name(*i), l.body_name(*j)), ("ground", "slider"));
                assert!((omega(*i) - omega(*j)).abs() < 1e-15);
                let e = l.point_position(&st.q, *j, &Vec2::zeros());
                assert!(d.dot(&(field(*i, e) - field(*j, e))).abs() < 1e-15);
                infinite += 1;
                continue;
            }
            RelativeCentre::Undefined => panic!("{c:?}"),
        };
        for b in [*i, *j] {
            for (_, lp) in l.body_points(b) {
                let mpt = if b == GROUND {
                    *lp
                } else {
                    l.point_position(&st.q, b, lp)
                };
                let solved = field(*i, mpt) - field(*j, mpt);
                let through = perp(&(mpt - p)) * (omega(*i) - omega(*j));
                assert!(
                    (solved - through).norm() <= 1e-12 + 1e-9 * solved.norm(),
                    "{}–{} at {mpt:?}: {solved:?} vs {through:?}",
                    l.body_name(*i),
                    l.body_name(*j)
                );
                checked += 1;
            }
        }
        // Velocities at P_ij itself agree.
        assert!((field(*i, *p) - field(*j, *p)).norm() < 1e-12);
    }
    assert!(checked > 40, "{checked}");
    assert_eq!(infinite, 1);
    assert!(three_centres_error(&centres) < 1e-12);
    // The report names them: P(ground,AB) is where the crank line OA meets the rocker line
    // CB (Kennedy), P(OA,AB) the pin A.
    let v = report(&sc, NAME).json;
    let at = &v["instant_centres"]["at"][0];
    assert_eq!(f(&at["input_deg"]), 150.0);
    let cs = at["centres"].as_array().unwrap();
    assert_eq!(cs.len(), 15);
    let get = |a: &str, b: &str| {
        let c = cs
            .iter()
            .find(|c| c["links"][0] == a && c["links"][1] == b)
            .unwrap_or_else(|| panic!("P({a},{b})"));
        Vec2::new(f(&c["point"][0]), f(&c["point"][1]))
    };
    let pt = |n: &str| {
        let p = &v["at"][0]["points"][n]["p"];
        Vec2::new(f(&p[0]), f(&p[1]))
    };
    let (a, b) = (pt("A"), pt("B"));
    let (o, c) = (Vec2::new(0.0, 0.0), Vec2::new(1.16, 0.0));
    let d1 = a - o;
    let d2 = b - c;
    let t = armsim::machines::linkage::cross(&(c - o), &d2)
        / armsim::machines::linkage::cross(&d1, &d2);
    let kennedy = o + d1 * t;
    assert!(
        (get("ground", "AB") - kennedy).norm() < 1e-9,
        "{:?} vs {kennedy:?}",
        get("ground", "AB")
    );
    assert!((get("OA", "AB") - a).norm() < 1e-12);
    assert!(f(&v["instant_centres"]["three_centres_max_error"]) < 1e-12);
    // relative_omega is ω_i − ω_j.
    let c = cs.iter().find(|c| c["label"] == "P(AB,CB)").unwrap();
    let w = |n: &str| f(&v["at"][0]["links"][n]["omega"]);
    assert!((f(&c["relative_omega"]) - (w("AB") - w("CB"))).abs() < 1e-15);
}

#[test]
fn a_translating_pair_has_its_centre_at_infinity() {
    // Scotch yoke: the yoke translates, P(ground, yoke) lies at infinity across the guide.
    let v = inline(
        r#"kind = "linkage"
[ground]
A = [0.0, 0.0]
[links.AB]
ends = ["A", "B"]
length = 0.1
[links.yoke]
points = { Y = [0.0, 0.0] }
[[sliders]]
link = "yoke"
point = "Y"
through = [0.0, 0.0]
direction = [1.0, 0.0]
[[sliders]]
link = "AB"
point = "B"
guide = "yoke"
through = [0.0, 0.0]
direction = [0.0, 1.0]
type = "pin_in_slot"
[driver]
link = "AB"
speed = 10.0
[guess]
B = [0.0866, 0.05]
Y = [0.0866, 0.0]
[sweep]
report_at_deg = [30.0]
[instant_centres]
"#,
    );
    let cs = v["instant_centres"]["at"][0]["centres"]
        .as_array()
        .unwrap()
        .clone();
    let gy = cs.iter().find(|c| c["label"] == "P(ground,yoke)").unwrap();
    assert!(gy["point"].is_null());
    assert!(f(&gy["direction_at_infinity"][0]).abs() < 1e-12);
    assert!((f(&gy["direction_at_infinity"][1]).abs() - 1.0).abs() < 1e-12);
    // P(AB, yoke) = (0, r sin φ): on the vertical through A and the horizontal through B.
    let ay = cs.iter().find(|c| c["label"] == "P(AB,yoke)").unwrap();
    assert!(f(&ay["point"][0]).abs() < 1e-12);
    assert!((f(&ay["point"][1]) - 0.05).abs() < 1e-12);
    // The structure: the yoke and the block replacing the pin in the slot form an RPP
    // dyad (kind 5), the sine mechanism's group.
    let g = &v["structure"]["groups"][0];
    assert_eq!(g["kind"], "RPP");
    assert_eq!(g["kind_number"], 5);
}

#[test]
fn structure_classes_four_bar_pump_and_triad() {
    let v = json("scenarios/four_bar_parallelogram.toml");
    let s = &v["structure"];
    assert_eq!(s["class"], 2);
    assert_eq!(s["groups"].as_array().unwrap().len(), 1);
    assert_eq!(s["groups"][0]["kind"], "RRR");
    assert_eq!(s["groups"][0]["order"], 2);
    // The oil pump: crank OA, dyads AB+CB (RRR) and DE+slider (RRP): class II.
    let v = json("scenarios/oil_pump.toml");
    let s = &v["structure"];
    assert_eq!(s["initial"]["link"], "OA");
    assert_eq!(s["class"], 2);
    let g = s["groups"].as_array().unwrap();
    assert_eq!(g.len(), 2);
    assert_eq!(g[0]["links"], serde_json::json!(["AB", "CB"]));
    assert_eq!(
        (g[0]["kind"].as_str(), g[0]["kind_number"].as_u64()),
        (Some("RRR"), Some(1))
    );
    assert_eq!(g[1]["links"], serde_json::json!(["DE", "slider"]));
    assert_eq!(
        (g[1]["kind"].as_str(), g[1]["kind_number"].as_u64()),
        (Some("RRP"), Some(2))
    );
    assert!(s["unassigned"].as_array().unwrap().is_empty());
    // The shaper: the block in the lever's slot is a third-kind dyad (RPR).
    let v = json("scenarios/shaper_quick_return.toml");
    assert_eq!(v["structure"]["groups"][0]["kind"], "RPR");
    assert_eq!(v["structure"]["groups"][0]["kind_number"], 3);
    // The triad: one group of four links, class III, order 3, base link BCD.
    let v = json("scenarios/linkage_class_iii_triad.toml");
    let s = &v["structure"];
    assert_eq!(s["class"], 3);
    let g = s["groups"].as_array().unwrap();
    assert_eq!(g.len(), 1);
    assert_eq!(g[0]["links"].as_array().unwrap().len(), 4);
    assert_eq!(g[0]["class"], 3);
    assert_eq!(g[0]["order"], 3);
    assert!(g[0]["kind"].is_null());
    let mut internal: Vec<String> = g[0]["internal_pairs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().to_string())
        .collect();
    internal.sort();
    assert_eq!(internal, ["B", "C", "D"]);
    // A class-IV group: two ternary links joined in a four-pair contour (Artobolevsky's
    // example), built in code: structure only, no position needed.
    use armsim::machines::linkage::assur::decompose;
    use armsim::machines::linkage::{Driver, Linkage, PlanarLink};
    let b = |n: &str, a: &str, c: &str| PlanarLink::binary(n, a, c, 1.0);
    let tern = |n: &str, p: [&str; 3]| {
        PlanarLink::new(
            n,
            vec![
                (p[0].into(), Vec2::new(0.0, 0.0)),
                (p[1].into(), Vec2::new(1.0, 0.0)),
                (p[2].into(), Vec2::new(0.0, 1.0)),
            ],
        )
    };
    // Crank OA; ternary L2 (A external, B, G), binary L3 (B–C), ternary L4 (C, D, E
    // external on the frame), binary L5 (D–G): six pairs, the contour B–C–D–G.
    let l = Linkage::with_shared_pins(
        "class IV",
        vec![
            ("O".into(), Vec2::zeros()),
            ("E".into(), Vec2::new(2.0, 0.0)),
        ],
        vec![
            b("OA", "O", "A"),
            tern("L2", ["A", "B", "G"]),
            b("L3", "B", "C"),
            tern("L4", ["C", "D", "E"]),
            b("L5", "D", "G"),
        ],
        vec![],
        Driver::Angle {
            link: 0,
            relative_to: GROUND,
        },
    );
    let s = decompose(&l);
    assert_eq!(s.groups.len(), 1);
    assert_eq!(s.groups[0].links.len(), 4);
    assert_eq!(s.groups[0].class, 4, "{s:?}");
    assert_eq!(s.groups[0].order, 2);
    assert_eq!(s.class, 4);
}

/// Slider-crank closed form: `(J_red, M_red)` at crank angle `phi` for the data of
/// `slider_crank_reduced_inertia.toml`.
fn slider_crank_reduced(phi: f64) -> (f64, f64) {
    let (r, l, a) = (0.074, 0.2, 0.06);
    let (m1, m2, m3, j1, j2, as1) = (10.0, 0.5, 0.4, 0.005, 0.0018, 0.02);
    let s2 = -r * phi.sin() / l;
    let th2 = s2.asin();
    let dth2 = -r * phi.cos() / (l * th2.cos());
    let dxc = -r * phi.sin() - l * th2.sin() * dth2;
    let ds2 =
        Vec2::new(-r * phi.sin(), r * phi.cos()) + Vec2::new(-th2.sin(), th2.cos()) * (a * dth2);
    let j = j1 + m1 * as1 * as1 + m2 * ds2.norm_squared() + j2 * dth2 * dth2 + m3 * dxc * dxc;
    (j, -500.0 * dxc)
}

#[test]
fn reduced_inertia_of_a_slider_crank_matches_the_closed_form() {
    let v = json("scenarios/slider_crank_reduced_inertia.toml");
    let rows = v["sweep"].as_array().unwrap();
    assert_eq!(rows.len(), 361);
    let w = 200.0;
    for (k, row) in rows.iter().enumerate() {
        let phi = f(&row["input_deg"]).to_radians();
        let (j, m) = slider_crank_reduced(phi);
        let (jr, dj, mr) = (
            f(&row["reduced_inertia"]),
            f(&row["reduced_inertia_derivative"]),
            f(&row["reduced_moment"]),
        );
        assert!((jr - j).abs() < 1e-12, "{phi}: J_red {jr} vs {j}");
        assert!((mr - m).abs() < 1e-9, "{phi}: M_red {mr} vs {m}");
        // Lagrange's equation of the reduced model gives the kinetostatic driving torque
        // (constant crank speed): T = ½ J' ω² − M_red.
        let t = f(&row["driving"]);
        assert!(
            (t - (0.5 * dj * w * w - mr)).abs() < 1e-8 * (1.0 + t.abs()),
            "{phi}: {t}"
        );
        // dJ/dφ against the central difference of the closed form.
        let h = 1e-5;
        let fd = (slider_crank_reduced(phi + h).0 - slider_crank_reduced(phi - h).0) / (2.0 * h);
        assert!((dj - fd).abs() < 1e-8, "{k}: dJ/dφ {dj} vs {fd}");
    }
    // At 90° the rod's angular velocity vanishes and v_C = −r ω1 (closed form by hand):
    // J_red = J_S1 + m1 AS1² + (m2 + m3) r².
    let at90 = rows.iter().find(|r| f(&r["input_deg"]) == 90.0).unwrap();
    let hand = 0.005 + 10.0 * 0.02f64.powi(2) + (0.5 + 0.4) * 0.074f64.powi(2);
    assert!((f(&at90["reduced_inertia"]) - hand).abs() < 1e-12);
    // At 45° with no load the driving torque is the book's 84.625 N m (the kinetostatics
    // scenario), so with the 500 N load: 84.625 − M_red.
    let at45 = &v["at"][0];
    assert_eq!(f(&at45["input_deg"]), 45.0);
    let t45 = 0.5 * f(&at45["reduced_inertia_derivative"]) * w * w;
    assert!((t45 - 84.625).abs() < 1e-3, "{t45}");
    let e = &v["extremes"]["reduced_inertia"];
    assert!(f(&e["min"]) <= hand && f(&e["max"]) > hand);
}

#[test]
fn geared_machine_motion_matches_the_closed_form_and_the_ungeared_machine() {
    let v = json("scenarios/machine_motion_geared.toml");
    let mm = &v["machine_motion"];
    // J = 2 + 0.01·10² = 3; M = 10 (100 − 10 ω) − 50 = 950 − 100 ω.
    assert!((f(&mm["steady_speed"]) - 9.5).abs() < 1e-12);
    assert!((f(&mm["time_constant"]) - 0.03).abs() < 1e-15);
    assert!(f(&mm["max_error_vs_closed_form"]) < 1e-9);
    assert!((f(&mm["reduced_inertia"]["min"]) - 3.0).abs() < 1e-15);
    let fin = &mm["final"];
    let closed = 9.5 * (1.0 - (-0.3f64 / 0.03).exp());
    assert!((f(&fin["omega"]) - closed).abs() < 1e-9);
    assert!((f(&fin["omega_motor"]) - 10.0 * f(&fin["omega"])).abs() < 1e-12);
    // The same machine written un-geared on the machine shaft.
    let u = inline(
        "kind = \"linkage\"\n[machine_motion]\ninertia = 3.0\ndrive = [950.0, -100.0]\nload = 0.0\nt_end = 0.3\ndt = 0.0001\n",
    );
    let fu = &u["machine_motion"]["final"];
    assert!((f(&fu["omega"]) - f(&fin["omega"])).abs() < 1e-12);
    assert!((f(&fu["phi"]) - f(&fin["phi"])).abs() < 1e-12);
    let e = &mm["energy_check"];
    assert!(f(&e["difference"]).abs() < 1e-9 * f(&e["work"]));
}

#[test]
fn machine_motion_with_the_linkage_inertia_keeps_the_energy_balance() {
    let v = json("scenarios/slider_crank_reduced_inertia.toml");
    let mm = &v["machine_motion"];
    assert_eq!(mm["reduced_inertia"]["source"], "linkage");
    // J(φ) = 0.002·5² + 0.05 + J_red(φ).
    let jmin = f(&v["extremes"]["reduced_inertia"]["min"]);
    let jmax = f(&v["extremes"]["reduced_inertia"]["max"]);
    assert!((f(&mm["reduced_inertia"]["min"]) - (0.1 + jmin)).abs() < 1e-9);
    assert!((f(&mm["reduced_inertia"]["max"]) - (0.1 + jmax)).abs() < 1e-6);
    let e = &mm["energy_check"];
    let (dk, w) = (f(&e["kinetic_energy_change"]), f(&e["work"]));
    assert!(w > 100.0, "{w}");
    assert!((dk - w).abs() < 1e-8 * w, "{dk} vs {w}");
    // The speed ripples with J(φ) about the constant-inertia run's (no closed form).
    assert!(mm["max_error_vs_closed_form"].is_null());
    // A tabulated J(φ): the energy balance holds too, and a table of equal rows is the
    // constant inertia (closed form).
    let t = inline(
        "kind = \"linkage\"\n[machine_motion]\ninertia = 0.1\ninertia_deg = [[0.0, 0.0], [90.0, 0.2], [180.0, 0.0], [270.0, 0.2]]\ndrive = [100.0, -1.0]\nload = 5.0\nt_end = 0.5\ndt = 0.0001\n",
    );
    let e = &t["machine_motion"]["energy_check"];
    assert!(f(&e["difference"]).abs() < 1e-7 * f(&e["work"]), "{e}");
    let c = inline(
        "kind = \"linkage\"\n[machine_motion]\ninertia = 0.05\ninertia_deg = [[0.0, 0.05], [180.0, 0.05]]\ndrive = [100.0, -1.0]\nload = 5.0\nt_end = 0.5\ndt = 0.001\n",
    );
    let w_end = f(&c["machine_motion"]["final"]["omega"]);
    let closed = 95.0 * (1.0 - (-10.0f64 * 0.5).exp());
    assert!((w_end - closed).abs() < 1e-6, "{w_end} vs {closed}");
}
