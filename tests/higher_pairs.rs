//! Cam contacts (higher pairs) in a linkage (issue 29, problem book ch. 1–3), through the
//! bundled scenarios and inline files, against closed forms:
//! - an eccentric disc cam with a roller rocker is the four-bar O–A–B–C (crank e, coupler
//!   R + r): positions, rates and accelerations at every sample; the contact force from
//!   the rocker's moment equation, the driving torque from the cam's and by virtual power;
//! - a disc on a flat-faced translating follower is the Scotch yoke: `s = R + e sin φ`,
//!   and with friction in the contact the driving torque `N e cos φ + f N (e sin φ + R)`;
//! - a disc on a flat-faced rocker: `ψ = δ − asin(R/d)`;
//! - `Φ_q` and `γ` of the contact rows against finite differences (circles outside and
//!   inside, a line on a turning body);
//! - the structure: `p₄`, the replacing link and the groups of the replaced mechanism;
//! - broken files: located errors.

mod common;

use armsim::machines::linkage::constraints::{gamma_vec, jacobian_mat, residual_vec};
use armsim::machines::linkage::sweep::sweep;
use armsim::scenarios::linkage::{parse, report::report, LinkageScenario, NAME};
use nalgebra::{DMatrix, DVector};
use serde_json::Value;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn text(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn scenario_of(name: &str, t: &str) -> LinkageScenario {
    parse(name, t).unwrap_or_else(|e| panic!("{e}"))
}

fn json_of(name: &str, t: &str) -> Value {
    report(&scenario_of(name, t), NAME).json
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn xy(v: &Value) -> [f64; 2] {
    [f(&v[0]), f(&v[1])]
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol * (1.0 + b.abs()), "{what}: {a} vs {b}");
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Solves `x p + y r = w` for `(x, y)` (two columns of a 2×2 system).
fn solve2(p: [f64; 2], r: [f64; 2], w: [f64; 2]) -> (f64, f64) {
    let det = cross(p, r);
    (cross(w, r) / det, cross(p, w) / det)
}

/// The four-bar O–A–B–C closed form at crank angle `phi` (ω₁ constant), on the branch
/// nearest `near` for B: `(B, ψ, ω₃, α₃, v_B, a_B, A)`.
#[allow(clippy::type_complexity)]
fn four_bar(
    phi: f64,
    w1: f64,
    (e, c, l3, cc): (f64, f64, f64, [f64; 2]),
    near: [f64; 2],
) -> ([f64; 2], f64, f64, f64, [f64; 2], [f64; 2], [f64; 2]) {
    let a = [e * phi.cos(), e * phi.sin()];
    let (dx, dy) = (cc[0] - a[0], cc[1] - a[1]);
    let d = dx.hypot(dy);
    let m = (c * c - l3 * l3 + d * d) / (2.0 * d);
    let h = (c * c - m * m).sqrt();
    let mid = [a[0] + m * dx / d, a[1] + m * dy / d];
    let cands = [
        [mid[0] + h * dy / d, mid[1] - h * dx / d],
        [mid[0] - h * dy / d, mid[1] + h * dx / d],
    ];
    let dist = |p: [f64; 2]| (p[0] - near[0]).hypot(p[1] - near[1]);
    let b = if dist(cands[0]) < dist(cands[1]) {
        cands[0]
    } else {
        cands[1]
    };
    let u2 = [(b[0] - a[0]) / c, (b[1] - a[1]) / c];
    let u3 = [(b[0] - cc[0]) / l3, (b[1] - cc[1]) / l3];
    let perp = |u: [f64; 2]| [-u[1], u[0]];
    // v_A + c ω₂ perp(u₂) = L ω₃ perp(u₃).
    let va = [-w1 * a[1], w1 * a[0]];
    let (p2, p3) = (perp(u2), perp(u3));
    let (w2, w3) = solve2(
        [c * p2[0], c * p2[1]],
        [-l3 * p3[0], -l3 * p3[1]],
        [-va[0], -va[1]],
    );
    // a_A + c α₂ perp(u₂) − c ω₂² u₂ = L α₃ perp(u₃) − L ω₃² u₃.
    let aa = [-w1 * w1 * a[0], -w1 * w1 * a[1]];
    let rhs = [
        -aa[0] + c * w2 * w2 * u2[0] - l3 * w3 * w3 * u3[0],
        -aa[1] + c * w2 * w2 * u2[1] - l3 * w3 * w3 * u3[1],
    ];
    let (_, e3) = solve2([c * p2[0], c * p2[1]], [-l3 * p3[0], -l3 * p3[1]], rhs);
    let vb = [l3 * w3 * p3[0], l3 * w3 * p3[1]];
    let ab = [
        l3 * e3 * p3[0] - l3 * w3 * w3 * u3[0],
        l3 * e3 * p3[1] - l3 * w3 * w3 * u3[1],
    ];
    (b, u3[1].atan2(u3[0]), w3, e3, vb, ab, a)
}

#[test]
fn eccentric_cam_with_a_roller_rocker_is_the_four_bar_o_a_b_c() {
    let rel = "scenarios/linkage_eccentric_cam_rocker.toml";
    let v = json_of(rel, &text(rel));
    let dims = (0.02, 0.05 + 0.015, 0.08, [0.1, 0.06]);
    let w1 = 10.0;
    let rows = v["sweep"].as_array().unwrap();
    assert_eq!(rows.len(), 181);
    for r in rows {
        let phi = f(&r["input_deg"]).to_radians();
        let pb = xy(&r["points"]["B"]["p"]);
        let (b, psi, w3, e3, vb, ab, a) = four_bar(phi, w1, dims, pb);
        let what = format!("at {}°", f(&r["input_deg"]));
        for i in 0..2 {
            close(pb[i], b[i], 1e-9, &format!("B {what}"));
            close(
                xy(&r["points"]["B"]["v"])[i],
                vb[i],
                1e-9,
                &format!("v_B {what}"),
            );
            close(
                xy(&r["points"]["B"]["a"])[i],
                ab[i],
                1e-9,
                &format!("a_B {what}"),
            );
        }
        let rocker = &r["links"]["rocker"];
        let ang = f(&rocker["angle_deg"]).to_radians();
        close(
            (ang - psi).sin(),
            0.0,
            1e-9,
            &format!("rocker angle {what}"),
        );
        close(f(&rocker["omega"]), w3, 1e-9, &format!("ω₃ {what}"));
        close(f(&rocker["alpha"]), e3, 1e-9, &format!("α₃ {what}"));
        // The contact point lies on AB at the disc's radius from A.
        let k = &r["contacts"]["K"];
        let p = xy(&k["point"]);
        let ab_len = (b[0] - a[0]).hypot(b[1] - a[1]);
        for i in 0..2 {
            close(
                p[i],
                a[i] + 0.05 * (b[i] - a[i]) / ab_len,
                1e-9,
                "contact point",
            );
        }
    }
    // Kinetostatics by hand: the rocker's moments about C give N, the cam's the torque.
    let (m3, j3) = (2.0, 0.001);
    for at in v["kinetostatics"]["at"].as_array().unwrap() {
        let phi = f(&at["input_deg"]).to_radians();
        let row = rows
            .iter()
            .find(|r| (f(&r["input_deg"]) - f(&at["input_deg"])).abs() < 1e-9)
            .unwrap();
        let (b, _, w3, e3, _, _, a) = four_bar(phi, w1, dims, xy(&row["points"]["B"]["p"]));
        let len = (a[0] - b[0]).hypot(a[1] - b[1]);
        let nu = [(a[0] - b[0]) / len, (a[1] - b[1]) / len];
        // On the rocker: (B − C) × (−N ν) + M₃ − J α₃ = 0.
        let bc = [b[0] - 0.1, b[1] - 0.06];
        let n = (m3 - j3 * e3) / cross(bc, nu);
        let cf = &at["contact_forces"][0];
        assert_eq!(cf["on"], "cam");
        assert_eq!(cf["by"], "rocker");
        assert_eq!(cf["separates"], false);
        close(f(&cf["normal_force"]), n, 1e-9, "N");
        close(f(&cf["magnitude"]), n, 1e-9, "|F|");
        let fv = xy(&cf["force"]);
        close(fv[0], n * nu[0], 1e-9, "F_x");
        close(fv[1], n * nu[1], 1e-9, "F_y");
        // On the cam: T + A × (N ν) = 0; by virtual power T ω₁ + (M₃ − J α₃) ω₃ = 0.
        let t = -n * cross(a, nu);
        close(f(&at["driving"]), t, 1e-9, "driving torque (cam statics)");
        close(
            f(&at["driving"]),
            -(m3 - j3 * e3) * w3 / w1,
            1e-9,
            "driving torque (virtual power)",
        );
    }
    // The numbers of the 30° row (for the docs): N = 24.983 N, T = 0.41622 N m.
    let at30 = &v["kinetostatics"]["at"][0];
    close(
        f(&at30["contact_forces"][0]["normal_force"]),
        24.9834,
        1e-5,
        "N at 30°",
    );
    close(f(&at30["driving"]), 0.416216, 1e-5, "T at 30°");
    // Structure: p₄ = 1, replaced by the link AB of 0.065 between two revolutes: one RRR
    // dyad (rocker + the link), class II; W = 3·2 − 2·2 − 1 = 1.
    let s = &v["structure"];
    assert_eq!(s["p4"], 1);
    let hp = &s["higher_pairs"][0];
    assert_eq!(hp["link"], "contact K");
    close(f(&hp["length"]), 0.065, 1e-15, "replacing link");
    assert_eq!(hp["pairs"][0]["kind"], "R");
    assert_eq!(hp["pairs"][1]["kind"], "R");
    assert_eq!(hp["pairs"][0]["bodies"][0], "cam");
    assert_eq!(hp["pairs"][1]["bodies"][1], "rocker");
    assert_eq!(s["class"], 2);
    let g = s["groups"].as_array().unwrap();
    assert_eq!(g.len(), 1);
    assert_eq!(g[0]["kind"], "RRR");
    let mob = &v["mobility"];
    assert_eq!(mob["higher_pairs"], 1);
    assert_eq!(mob["grubler"], 1);
    assert_eq!(mob["mobility"], 1);
}

#[test]
fn disc_on_a_flat_faced_follower_is_the_scotch_yoke_with_contact_friction() {
    let rel = "scenarios/linkage_cam_flat_follower_kinetostatics.toml";
    let v = json_of(rel, &text(rel));
    let (e, rr, w, m, g, p, fc) = (0.02, 0.05, 20.0, 2.0, 9.81, 300.0, 0.1);
    for r in v["sweep"].as_array().unwrap() {
        let phi = f(&r["input_deg"]).to_radians();
        let fp = &r["points"]["F"];
        close(xy(&fp["p"])[1], rr + e * phi.sin(), 1e-9, "s");
        close(xy(&fp["v"])[1], e * w * phi.cos(), 1e-9, "v");
        close(xy(&fp["a"])[1], -e * w * w * phi.sin(), 1e-9, "a");
        close(xy(&fp["p"])[0], 0.0, 1e-12, "x");
    }
    let ks = &v["kinetostatics"];
    let fr = &ks["friction"]["at"];
    for (k, at) in ks["at"].as_array().unwrap().iter().enumerate() {
        let phi = f(&at["input_deg"]).to_radians();
        let n = p + m * g + m * (-e * w * w * phi.sin());
        close(f(&at["driving"]), n * e * phi.cos(), 1e-9, "T ideal");
        let cf = &at["contact_forces"][0];
        close(f(&cf["normal_force"]), n, 1e-9, "N");
        let pt = xy(&cf["point"]);
        close(pt[0], e * phi.cos(), 1e-12, "contact x");
        close(pt[1], rr + e * phi.sin(), 1e-12, "contact y");
        // With f = 0.1 in the contact: the follower slides to +x on the cam's top.
        let with = &fr[k];
        close(f(&with["input"]), phi, 1e-12, "friction row");
        let t = n * e * phi.cos() + fc * n * (e * phi.sin() + rr);
        close(f(&with["driving"]), t, 1e-9, "T with friction");
        close(
            f(&with["friction_power"]),
            fc * n * w * (e * phi.sin() + rr),
            1e-9,
            "friction power",
        );
        let cf = &with["contact_forces"][0];
        let ff = xy(&cf["friction_force"]);
        close(ff[0], fc * n, 1e-9, "friction force on the cam");
        close(ff[1], 0.0, 1e-12, "friction force along the face");
        // The total leans by the friction angle.
        let tot = xy(&cf["force"]);
        close(tot[0].atan2(-tot[1]), fc.atan(), 1e-9, "friction angle");
    }
    // Structure: the flat face is replaced by a link with R at the disc centre and P
    // along the face: with the follower's guide a dyad R–P–P (5th kind).
    let s = &v["structure"];
    assert_eq!(s["p4"], 1);
    assert_eq!(s["higher_pairs"][0]["pairs"][1]["kind"], "P");
    assert!(s["higher_pairs"][0]["length"].is_null());
    assert_eq!(s["groups"][0]["kind"], "RPP");
    assert_eq!(s["class"], 2);
}

/// A disc (e = 0.02, R = 0.03 about O) against the flat face of a lever pivoted at
/// C = (0.12, 0): the face is the lever's line through C; the disc's centre A stays at R
/// from it, `ψ = δ − asin(R/d)` with `d, δ` the distance and direction of A from C.
const FLAT_LEVER: &str = r#"
kind = "linkage"
[ground]
O = [0.0, 0.0]
C = [0.12, 0.0]
[links.cam]
points = { O = [0.0, 0.0] }
[links.lever]
points = { C = [0.0, 0.0], T = [-0.1, 0.0] }
mass = 0.3
com = [-0.05, 0.0]
inertia = 0.0004
[[contacts]]
links = ["lever", "cam"]
profiles = [ { line = { through = "C", direction = [1.0, 0.0] } },
             { circle = { centre = [0.02, 0.0], radius = 0.03 } } ]
side = "right"
[driver]
link = "cam"
speed = 5.0
[guess]
T = [0.02, 0.03]
[sweep]
step_deg = 5.0
report_at_deg = [40.0]
[kinetostatics]
[[loads]]
link = "lever"
torque = 1.5
"#;

#[test]
fn disc_on_a_flat_faced_lever_follows_the_offset_line_closed_form() {
    let sc = scenario_of("flat_lever.toml", FLAT_LEVER);
    let v = report(&sc, NAME).json;
    let (e, rr, cx) = (0.02, 0.03, 0.12);
    // δ = π + atan2(−d_y, −d_x): A stays left of C, so no jump at ±π.
    let psi_of = |phi: f64| {
        let d = [e * phi.cos() - cx, e * phi.sin()];
        std::f64::consts::PI + (-d[1]).atan2(-d[0]) - (rr / d[0].hypot(d[1])).asin()
    };
    let h = 1e-3;
    for r in v["sweep"].as_array().unwrap() {
        let phi = f(&r["input_deg"]).to_radians();
        let l = &r["links"]["lever"];
        let psi = psi_of(phi);
        close(
            (f(&l["angle_deg"]).to_radians() - psi).sin(),
            0.0,
            1e-9,
            "ψ",
        );
        let dpsi = (psi_of(phi + h) - psi_of(phi - h)) / (2.0 * h);
        let ddpsi = (psi_of(phi + h) - 2.0 * psi + psi_of(phi - h)) / (h * h);
        close(f(&l["omega"]), 5.0 * dpsi, 1e-6, "ω");
        close(f(&l["alpha"]), 25.0 * ddpsi, 1e-5, "α");
        // The driving torque by virtual power agrees with the multipliers.
        close(f(&r["driving"]), f(&r["driving_virtual_power"]), 1e-9, "T");
    }
    // The contact is "on" the lever (the circle is the cam's): a = cam after reordering.
    let s = &v["structure"];
    assert_eq!(s["higher_pairs"][0]["pairs"][0]["bodies"][0], "cam");
    assert_eq!(s["higher_pairs"][0]["pairs"][1]["kind"], "P");
    // The lever's torque presses the face on the disc: N > 0, on the cam by the lever.
    let cf = &v["kinetostatics"]["at"][0]["contact_forces"][0];
    assert_eq!(cf["on"], "cam");
    assert!(f(&cf["normal_force"]) > 0.0, "{cf}");
    assert_eq!(cf["separates"], false);
    // Turned the other way the torque would pull the face off the disc: flagged.
    let off = json_of(
        "off.toml",
        &FLAT_LEVER.replace("torque = 1.5", "torque = -1.5"),
    );
    let cf = &off["kinetostatics"]["at"][0]["contact_forces"][0];
    assert!(f(&cf["normal_force"]) < 0.0, "{cf}");
    assert_eq!(cf["separates"], true);
}

/// `Φ_q` by central differences of `Φ`, and `γ = −(Φ_q q̇)_q q̇` by differences of `Φ_q`
/// along `q̇`, against the closed forms, at several samples of a sweep.
fn check_rows(name: &str, t: &str) {
    let sc = scenario_of(name, t);
    let m = sc.mechanism.as_ref().unwrap();
    let l = &m.linkage;
    let sw = sweep(l, &m.assembly, &m.sweep).unwrap();
    let h = 1e-6;
    for st in sw.samples.iter().step_by(7) {
        let (q, qd) = (&st.q, st.qd(m.speed));
        let jac = jacobian_mat(l, q);
        let mut fd = DMatrix::zeros(l.nrows(), l.ncoords());
        for c in 0..l.ncoords() {
            let mut qp = q.clone();
            let mut qm = q.clone();
            qp[c] += h;
            qm[c] -= h;
            let d = (residual_vec(l, &qp, st.s) - residual_vec(l, &qm, st.s)) / (2.0 * h);
            fd.set_column(c, &d);
        }
        assert!((&jac - &fd).amax() < 1e-7, "{name}: Φ_q at {}", st.s);
        let jd = (jacobian_mat(l, &(q + &qd * h)) - jacobian_mat(l, &(q - &qd * h))) / (2.0 * h);
        let g_fd: DVector<f64> = -(jd * &qd);
        let g = gamma_vec(l, q, &qd, 0.0);
        let n = l.nrows();
        let kin = (g.rows(0, n - 1) - g_fd.rows(0, n - 1)).amax();
        assert!(
            kin < 1e-6 * (1.0 + g.amax()),
            "{name}: γ at {}: {kin}",
            st.s
        );
    }
}

/// A circle inside a ring: a disc of radius 0.01 on a crank OA = 0.02 rolls inside a ring
/// of radius 0.06 on a rocker about C.
const INSIDE: &str = r#"
kind = "linkage"
[ground]
O = [0.0, 0.0]
C = [0.1, 0.0]
[links.crank]
points = { O = [0.0, 0.0], A = [0.02, 0.0] }
[links.ring]
points = { C = [0.0, 0.0], M = [-0.08, 0.0] }
[[contacts]]
links = ["crank", "ring"]
profiles = [ { circle = { centre = "A", radius = 0.01 } },
             { circle = { centre = "M", radius = 0.06 } } ]
side = "inside"
[driver]
link = "crank"
speed = 3.0
[guess]
M = [0.036, 0.047]
[sweep]
step_deg = 5.0
"#;

#[test]
fn contact_rows_match_finite_differences() {
    for rel in [
        "scenarios/linkage_eccentric_cam_rocker.toml",
        "scenarios/linkage_cam_flat_follower_kinetostatics.toml",
    ] {
        check_rows(rel, &text(rel));
    }
    check_rows("flat_lever.toml", FLAT_LEVER);
    check_rows("inside.toml", INSIDE);
    // Inside: the crank-ring pair is the four-bar O–A–M–C with coupler 0.06 − 0.01.
    let v = json_of("inside.toml", INSIDE);
    close(
        f(&v["structure"]["higher_pairs"][0]["length"]),
        0.05,
        1e-15,
        "AM",
    );
    for r in v["sweep"].as_array().unwrap() {
        let phi = f(&r["input_deg"]).to_radians();
        let pm = xy(&r["points"]["M"]["p"]);
        let (b, ..) = four_bar(phi, 3.0, (0.02, 0.05, 0.08, [0.1, 0.0]), pm);
        close(pm[0], b[0], 1e-9, "M x");
        close(pm[1], b[1], 1e-9, "M y");
    }
}

/// `(file, line, key, message fragment)`.
const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "higher_pair_two_lines.toml",
        17,
        "contacts[0].profiles",
        "two lines do not touch at a point",
    ),
    (
        "higher_pair_side_on_circles.toml",
        21,
        "contacts[0].side",
        "two circles touch \"outside\" or \"inside\"",
    ),
    (
        "higher_pair_negative_radius.toml",
        17,
        "contacts[0].profiles",
        "[0]: circle.radius must be in 0 … 1000 m",
    ),
    (
        "higher_pair_unknown_link.toml",
        16,
        "contacts[0].links",
        "no link 'follower'",
    ),
    (
        "higher_pair_friction_without_kinetostatics.toml",
        22,
        "contacts[0].friction_coefficient",
        "needs a [kinetostatics] table",
    ),
];

#[test]
fn broken_contact_files_give_located_errors() {
    let listed: Vec<&str> = BROKEN.iter().map(|b| b.0).collect();
    common::assert_lists_every_broken_scenario("higher_pair_", &listed);
    for &(file, line, key, msg) in BROKEN {
        let rel = format!("tests/broken_scenarios/{file}");
        let e = parse(&rel, &text(&rel)).expect_err(file);
        assert_eq!(e.line, Some(line), "{file}: {e}");
        assert_eq!(e.key, key, "{file}: {e}");
        assert!(e.message.contains(msg), "{file}: {e}");
    }
}
