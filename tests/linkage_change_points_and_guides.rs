//! Linkage sweeps through change points (the parallelogram against its closed form at every
//! row, the change points' inputs against the collinear positions), kinetostatics at and
//! near them; prismatic guides bearing at two points (two normal forces against hand
//! statics, Coulomb friction `f (|N_a| + |N_b|)` against the closed form, virtual power,
//! jamming); the full-balance counterweight's text.

use armsim::io::report::Report;
use armsim::machines::friction::two_point_guide::friction_force;
use armsim::scenarios::linkage::{parse, report::report, NAME};
use serde_json::Value;
use std::path::PathBuf;

fn run_text(rel: &str, text: &str) -> Report {
    let sc = parse(rel, text).unwrap_or_else(|e| panic!("{e}"));
    report(&sc, NAME)
}

fn run(rel: &str) -> Report {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel);
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{rel}: {e}"));
    run_text(rel, &text)
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b}");
}

/// Angle difference wrapped to (−180°, 180°].
fn ddeg(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

fn no_non_finite(text: &str) {
    for bad in ["NaN", "inf"] {
        assert!(!text.contains(bad), "the text prints {bad}:\n{text}");
    }
}

#[test]
fn change_point_four_bar_continues_on_the_parallelogram_at_every_row() {
    let r = run("scenarios/linkage_change_point_fourbar.toml");
    let v = &r.json;
    assert!(v.get("stopped").is_none(), "{}", v["stopped"]);
    let rows = v["sweep"].as_array().unwrap();
    // 10° to 370° by 1.5°: 241 rows.
    assert_eq!(rows.len(), 241);
    let k = 9.81 * (1.0 * 0.05 + 3.0 * 0.1 + 1.5 * 0.05);
    close(k, 4.16925, 1e-12, "T amplitude by hand");
    for row in rows {
        let phi = f(&row["input_deg"]);
        let links = &row["links"];
        // The parallelogram: θ3 = 0, θ4 = θ2, ω3 = 0, ω4 = ω2.
        close(ddeg(f(&links["BC"]["angle_deg"]), 0.0), 0.0, 1e-7, "θ3");
        close(
            ddeg(f(&links["DC"]["angle_deg"]), phi),
            0.0,
            1e-7,
            "θ4 − θ2",
        );
        close(f(&links["BC"]["omega"]), 0.0, 1e-7, "ω3");
        close(f(&links["DC"]["omega"]), 10.0, 1e-7, "ω4");
        let b = &row["points"]["B"]["p"];
        let c = &row["points"]["C"]["p"];
        close(f(&c[0]) - f(&b[0]), 0.3, 1e-9, "C − B");
        close(f(&c[1]) - f(&b[1]), 0.0, 1e-9, "C − B");
        // The driving torque, T = g cos φ (m1 a/2 + m2 a + m3 c/2), Lagrange multipliers
        // away from the change points, virtual power (the limit) at them.
        let t = k * phi.to_radians().cos();
        close(f(&row["driving"]), t, 1e-7, &format!("T at {phi}°"));
        close(
            f(&row["driving_virtual_power"]),
            t,
            1e-7,
            &format!("T by virtual power at {phi}°"),
        );
    }
    // The change points: all links on one line, at 180° and 360° (the crank along the
    // ground line), against the group's sign flipping on the smooth motion.
    let cps = v["change_points"].as_array().unwrap();
    assert_eq!(cps.len(), 2, "{cps:?}");
    for (cp, at) in cps.iter().zip([180.0, 360.0]) {
        close(f(&cp["input_deg"]), at, 1e-4, "change point");
        assert_eq!(cp["rule"], "smooth");
        assert_eq!(cp["four_bar_branch"], "parallelogram");
        assert_eq!(cp["four_bar_branch_before"], "parallelogram");
        let (b, a) = (
            f(&cp["signs_before"]["BC+DC"]),
            f(&cp["signs_after"]["BC+DC"]),
        );
        assert!(b * a < 0.0, "the sign flips: {cp}");
    }
    // Kinetostatics: finite near the change point, reported as singular at it.
    let kat = v["kinetostatics"]["at"].as_array().unwrap();
    assert_eq!(kat.len(), 3);
    assert_eq!(kat[0]["singular"], false);
    assert_eq!(kat[2]["singular"], true);
    assert!(kat[2]["joint_forces"].is_null());
    close(f(&kat[2]["driving"]), -k, 1e-7, "T at 180°");
    let near = kat[1]["joint_forces"].as_array().unwrap();
    let big = near.iter().map(|j| f(&j["magnitude"])).fold(0.0, f64::max);
    assert!(
        big.is_finite() && big > 10.0 * 3.0 * 9.81,
        "1/sin growth at 179°: {big}"
    );
    no_non_finite(&r.text);
    assert!(
        r.text.contains("change point at input 180.0000°"),
        "{}",
        r.text
    );
    assert!(
        r.text
            .contains("singular position: the joint forces are not determined here"),
        "{}",
        r.text
    );
}

#[test]
fn where_the_tracker_stops_at_a_change_point_the_sweep_is_restarted_on_the_parallelogram() {
    // With each centre of mass at its link's first end the tracker stops at the change
    // points (the sign it keeps belongs to the other branch past them) and the sweep is
    // restarted there on the smooth motion: one crossing each, still the parallelogram.
    let rel = "scenarios/linkage_change_point_fourbar.toml";
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel);
    let text = std::fs::read_to_string(&p)
        .unwrap()
        .replace("\ninertia = ", "\ncom = [0.0, 0.0]\ninertia = ");
    let r = run_text(rel, &text);
    let v = &r.json;
    assert!(v.get("stopped").is_none(), "{}", v["stopped"]);
    let rows = v["sweep"].as_array().unwrap();
    assert_eq!(rows.len(), 241);
    // Only the coupler's centre (at B) moves: T = g m2 a cos φ.
    let k = 9.81 * 3.0 * 0.1;
    for row in rows {
        let phi = f(&row["input_deg"]);
        close(
            ddeg(f(&row["links"]["BC"]["angle_deg"]), 0.0),
            0.0,
            1e-7,
            "θ3",
        );
        close(
            ddeg(f(&row["links"]["DC"]["angle_deg"]), phi),
            0.0,
            1e-7,
            "θ4",
        );
        close(f(&row["links"]["DC"]["omega"]), 10.0, 1e-7, "ω4");
        close(f(&row["driving"]), k * phi.to_radians().cos(), 1e-7, "T");
    }
    let cps = v["change_points"].as_array().unwrap();
    assert_eq!(cps.len(), 2, "{cps:?}");
    for (cp, at) in cps.iter().zip([180.0, 360.0]) {
        close(f(&cp["input_deg"]), at, 1e-4, "change point");
        assert_eq!(cp["restarted"], true, "{cp}");
        assert_eq!(cp["four_bar_branch"], "parallelogram");
    }
    no_non_finite(&r.text);
}

#[test]
fn rod_in_two_bushes_matches_hand_statics_with_and_without_friction() {
    let r = run("scenarios/linkage_guide_two_bushes.toml");
    let v = &r.json;
    let kat = v["kinetostatics"]["at"].as_array().unwrap();
    // Frictionless at s = 0: D = Q = 500 N; N_a + N_b = P, 0.1 (N_b − N_a) = 0.05 D + 0.3 P.
    let g0 = &kat[0]["guide_contacts"][0];
    close(f(&kat[0]["driving"]), 500.0, 1e-9, "D");
    close(f(&g0["normal_forces"][0]), -325.0, 1e-9, "N_a");
    close(f(&g0["normal_forces"][1]), 525.0, 1e-9, "N_b");
    close(f(&g0["points"][0][0]), -0.1, 1e-12, "bush a");
    close(f(&g0["points"][1][0]), 0.1, 1e-12, "bush b");
    // s = 0.05: 0.1 (N_b − N_a) = 25 + 0.35 · 200.
    let g1 = &kat[1]["guide_contacts"][0];
    close(
        f(&g1["normal_forces"][0]),
        (200.0 - 950.0) / 2.0,
        1e-9,
        "N_a(0.05)",
    );
    close(
        f(&g1["normal_forces"][1]),
        (200.0 + 950.0) / 2.0,
        1e-9,
        "N_b(0.05)",
    );
    assert!(f(&v["kinetostatics"]["max_virtual_power_difference"]) < 1e-9);
    // With f = 0.15: D = (500 + 2000 f (s + 0.3)) / (1 − 0.5 f).
    let fr = &v["kinetostatics"]["friction"];
    let fat = fr["at"].as_array().unwrap();
    for (e, s) in fat.iter().zip([0.0, 0.05]) {
        let d = (500.0 + 2000.0 * 0.15 * (s + 0.3)) / (1.0 - 0.5 * 0.15);
        close(f(&e["driving"]), d, 1e-9, &format!("D at s = {s}"));
        let spread = 0.5 * d + 2000.0 * (s + 0.3);
        let g = &e["guide_contacts"][0];
        close(
            f(&g["normal_forces"][0]),
            (200.0 - spread) / 2.0,
            1e-9,
            "N_a",
        );
        close(
            f(&g["normal_forces"][1]),
            (200.0 + spread) / 2.0,
            1e-9,
            "N_b",
        );
        close(f(&g["friction_force"]), 0.15 * spread, 1e-9, "F");
        // The driver's extra power is the friction's: (D − Q) v = F v.
        close(
            f(&e["driving_power"]) - 500.0 * 0.1,
            f(&e["friction_power"]),
            1e-9,
            "power balance",
        );
        assert_eq!(e["jammed"], false);
    }
    close(
        f(&fat[0]["driving"]),
        637.837_837_837_837_8,
        1e-9,
        "D at s = 0",
    );
    no_non_finite(&r.text);
}

/// The drawer (a block bearing at its two ends, contacts on the link) pushed along a line
/// `h` off the guide: it jams when `f · 2h/L ≥ 1`, else `D = Q / (1 − 2 f h / L)` while
/// the near end lifts (`h D > G L/2`).
fn drawer(h: f64, f_: f64) -> String {
    format!(
        r#"kind = "linkage"
[ground]
O = [0.0, 0.0]
[links.block]
points = {{ X = [0.0, 0.0], H = [0.0, {h}] }}
[[sliders]]
link = "block"
point = "X"
through = [0.0, 0.0]
direction = [1.0, 0.0]
contacts = [-0.1, 0.1]
contacts_on = "link"
[driver]
link = "block"
type = "slide"
point = "H"
through = [0.0, {h}]
direction = [1.0, 0.0]
speed = 0.2
[guess]
X = [0.0, 0.0]
[sweep]
from = 0.0
to = 0.1
step = 0.05
report_at = [0.05]
[kinetostatics]
gravity = [0.0, 0.0]
friction_coefficient = {f_}
[[loads]]
link = "block"
point = "X"
force = [-500.0, -100.0]
"#
    )
}

#[test]
fn a_drawer_bearing_at_its_ends_follows_the_hand_solution_and_jams() {
    let (l, q, g) = (0.2, 500.0, 100.0);
    for (h, fc) in [(0.05, 0.3), (0.15, 0.3)] {
        let r = run_text("drawer.toml", &drawer(h, fc));
        let e = &r.json["kinetostatics"]["friction"]["at"][0];
        let d = q / (1.0 - 2.0 * fc * h / l);
        assert!(h * d > g * l / 2.0, "the near end lifts");
        close(f(&e["driving"]), d, 1e-9, &format!("D at h = {h}"));
        let nb = g / 2.0 + h * d / l;
        close(
            f(&e["guide_contacts"][0]["normal_forces"][1]),
            nb,
            1e-9,
            "N_b",
        );
        close(
            f(&e["guide_contacts"][0]["normal_forces"][0]),
            g - nb,
            1e-9,
            "N_a",
        );
        // The block's ends move with it: at s = 0.05 they are at 0.05 ∓ 0.1.
        close(
            f(&e["guide_contacts"][0]["points"][0][0]),
            -0.05,
            1e-12,
            "end a",
        );
    }
    // f · 2h/L = 0.5 · 2 · 0.25 / 0.2 = 1.25 ≥ 1: self-locking.
    let r = run_text("drawer.toml", &drawer(0.25, 0.5));
    let fr = &r.json["kinetostatics"]["friction"];
    assert_eq!(fr["at"][0]["jammed"], true);
    assert!(fr["at"][0]["driving"].is_null());
    assert_eq!(fr["jammed_at"].as_array().unwrap().len(), 3);
    assert!(r.text.contains("jams (self-locking"), "{}", r.text);
    no_non_finite(&r.text);
}

#[test]
fn coulomb_friction_of_two_contacts_by_sign_cases() {
    // Both forces positive and independent of F: F = f (α_a + α_b).
    close(
        friction_force(0.2, [30.0, 70.0], [0.0, 0.0]).unwrap(),
        20.0,
        1e-12,
        "plain",
    );
    // N_a = 50 − 2F changes sign at F = 25: below, F = 0.3 (50 − 2F + 10 + F) has the root
    // F = 18/1.3 < 25.
    close(
        friction_force(0.3, [50.0, 10.0], [-2.0, 1.0]).unwrap(),
        18.0 / 1.3,
        1e-12,
        "first segment",
    );
    // Growth f (|β_a| + |β_b|) ≥ 1 with the loads pushing on: no root, it jams.
    assert!(friction_force(0.5, [10.0, 10.0], [1.0, 1.0]).is_none());
}

#[test]
fn slider_crank_with_two_bushes_balances_virtual_power_and_splits_the_couple() {
    // The kinetostatics slider-crank's piston in bushes 0.05 m either side of the pin's
    // line position at 0.25 m (guide frame): N_a + N_b = N, moments = the couple.
    let text = r#"kind = "linkage"
[ground]
A = [0.0, 0.0]
[links.AB]
ends = ["A", "B"]
length = 0.074
mass = 10.0
[links.BC]
ends = ["B", "C"]
length = 0.2
mass = 0.5
inertia = 0.002
[links.piston]
points = { C = [0.0, 0.0] }
mass = 0.4
[[sliders]]
link = "piston"
point = "C"
through = [0.0, 0.0]
direction = [1.0, 0.0]
contacts = [0.2, 0.3]
[driver]
link = "AB"
speed = 150.0
[guess]
B = [0.052, 0.052]
C = [0.245, 0.0]
[sweep]
step_deg = 5.0
assemble_at_deg = 45.0
report_at_deg = [45.0, 120.0]
[kinetostatics]
[[loads]]
link = "piston"
point = "C"
force = [-2000.0, 0.0]
"#;
    let r = run_text("bushes.toml", text);
    let v = &r.json;
    assert!(f(&v["kinetostatics"]["max_virtual_power_difference"]) < 1e-8);
    for (i, e) in v["kinetostatics"]["at"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        let jf = e["joint_forces"]
            .as_array()
            .unwrap()
            .iter()
            .find(|j| j["joint"] == "C" && j["by"] == "ground")
            .expect("the guide's reaction");
        let (n, c) = (f(&jf["force"][1]), f(&jf["couple"]));
        let g = &e["guide_contacts"][0];
        let (na, nb) = (f(&g["normal_forces"][0]), f(&g["normal_forces"][1]));
        close(na + nb, n, 1e-9 * n.abs().max(1.0), "N_a + N_b = N");
        close(f(&g["points"][0][0]), 0.2, 1e-12, "bush a fixed");
        // Moments about the piston pin C at x_C: (0.2 − x_C) N_a + (0.3 − x_C) N_b = C.
        assert_eq!(v["at"][i]["input_deg"], e["input_deg"]);
        let xc = f(&v["at"][i]["points"]["C"]["p"][0]);
        close(
            (0.2 - xc) * na + (0.3 - xc) * nb,
            c,
            1e-9 * (na.abs() + nb.abs()).max(1.0),
            "moment = couple",
        );
    }
}

#[test]
fn full_balance_text_names_the_rod_and_crank_counterweights() {
    let r = run("scenarios/slider_crank_full_balance.toml");
    let t = &r.text;
    // m_r = (m2 c2 + m3 l)/e = 2.2 kg, m_c = (m1 c1 + (m2 + m3 + m_r) r)/ρ = 8.588 kg.
    assert!(
        t.contains("full static balancing: on the rod 2.200000 kg at 0.05 m beyond the crank pin"),
        "{t}"
    );
    assert!(
        t.contains("on the crank 8.588000 kg at 0.05 m beyond the pivot"),
        "{t}"
    );
    assert!(!t.contains("with 0% of the reciprocating mass"), "{t}");
}

#[test]
fn contacts_keys_that_do_not_apply_are_refused_with_their_line() {
    let base = drawer(0.05, 0.3);
    let cases = [
        (
            base.replace("contacts = [-0.1, 0.1]\n", "contacts = [0.1, 0.1]\n"),
            "sliders[0].contacts",
            "must differ",
        ),
        (
            base.replace("contacts = [-0.1, 0.1]\n", ""),
            "sliders[0].contacts_on",
            "applies only with",
        ),
        (
            base.replace("contacts_on = \"link\"", "contacts_on = \"frame\""),
            "sliders[0].contacts_on",
            "unknown 'frame'",
        ),
        (
            base.replace(
                "contacts = [-0.1, 0.1]\n",
                "contacts = [-0.1, 0.1]\ntype = \"pin_in_slot\"\n",
            ),
            "sliders[0].contacts",
            "prismatic",
        ),
        (
            base.split("[kinetostatics]").next().unwrap().to_string(),
            "sliders[0].contacts",
            "[kinetostatics]",
        ),
    ];
    for (text, key, what) in cases {
        let e = parse("drawer.toml", &text).expect_err(key).to_string();
        assert!(e.contains(key) && e.contains(what), "{e}");
        let line = text
            .lines()
            .position(|l| l.starts_with(key.rsplit('.').next().unwrap()))
            .unwrap()
            + 1;
        assert!(e.starts_with(&format!("drawer.toml:{line}:")), "{e}");
    }
}
