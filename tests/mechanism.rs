//! Closed-chain planar linkages: the oil pump's published table, the problem book's
//! checkpoints, branch tracking, singular positions, kinetostatics against virtual power,
//! balancing, flywheel, machine motion, the spatial loop closure, and located errors for
//! broken linkage scenarios.
//!
//! References are independent of the solver: published numbers, closed forms written out
//! here, finite differences of the position solution, a second method.

mod common;

use armsim::kinematics::spatial_loop::{self, ClosureKind, LoopClosure};
use armsim::machines::balancing::{self, RotorMass};
use armsim::machines::flywheel;
use armsim::machines::flywheel::machine_motion::{self, Characteristic};
use armsim::machines::linkage::branch::sign;
use armsim::machines::linkage::catalog;
use armsim::machines::linkage::constraints::{gamma_vec, jacobian_mat, residual_vec};
use armsim::machines::linkage::fourbar::{self, GrashofClass};
use armsim::machines::linkage::kinetostatics::{self, Loads};
use armsim::machines::linkage::mobility::{conditioning, mobility};
use armsim::machines::linkage::position::{solve_position, NewtonOptions};
use armsim::machines::linkage::sweep::{sweep, State, Sweep, SweepOptions, Tracker};
use armsim::machines::linkage::velocity::{solve_acceleration, solve_velocity};
use armsim::machines::linkage::virtual_power;
use armsim::machines::linkage::{Driver, Linkage, PlanarLink, Slider, Vec2, GROUND};
use armsim::scenarios::linkage::{parse, LinkageScenario, MechanismScenario};
use nalgebra::DVector;
use serde_json::Value;
use std::f64::consts::PI;
use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scenario(rel: &str) -> LinkageScenario {
    let p = root().join(rel);
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{rel}: {e}"));
    parse(rel, &text).unwrap_or_else(|e| panic!("{e}"))
}

fn mech(rel: &str) -> MechanismScenario {
    scenario(rel).mechanism.expect("a linkage scenario")
}

fn run_sweep(m: &MechanismScenario) -> Sweep {
    sweep(&m.linkage, &m.assembly, &m.sweep).expect("sweep")
}

fn at_deg(sw: &Sweep, deg: f64) -> &State {
    sw.samples
        .iter()
        .find(|s| (s.s.to_degrees() - deg).abs() < 1e-9)
        .unwrap_or_else(|| panic!("no sample at {deg}°"))
}

fn pos(l: &Linkage, st: &State, p: &str) -> Vec2 {
    let (b, lp) = l.find_point(p).expect("point");
    l.point_position(&st.q, b, &lp)
}

fn vel(l: &Linkage, st: &State, sd: f64, p: &str) -> Vec2 {
    let (b, lp) = l.find_point(p).expect("point");
    l.point_velocity(&st.q, &st.qd(sd), b, &lp)
}

fn acc(l: &Linkage, st: &State, sd: f64, sdd: f64, p: &str) -> Vec2 {
    let (b, lp) = l.find_point(p).expect("point");
    l.point_acceleration(&st.q, &st.qd(sd), &st.qdd(sd, sdd), b, &lp)
}

fn link(l: &Linkage, name: &str) -> usize {
    l.link_id(name).expect("link")
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

fn cli(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_armsim"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("run armsim")
}

// ---------------------------------------------------------------------------------------
// Oil pump (docs/reference_data.md §S2a).

#[test]
fn oil_pump_reproduces_the_published_table_at_150_degrees() {
    let m = mech("scenarios/oil_pump.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    let st = at_deg(&sw, 150.0);
    let w = m.speed;
    assert_eq!(w, 0.5);
    let om = |n: &str| st.dq[3 * link(l, n) + 2] * w;
    let al = |n: &str| st.ddq[3 * link(l, n) + 2] * w * w;
    let tol = 0.0006;
    // Published (3 decimals), angles from the frame line, counter-clockwise positive.
    close(om("AB"), 0.059, tol, "w2");
    close(al("AB"), 0.063, tol, "e2");
    close(om("CB"), 0.235, tol, "w3");
    close(al("CB"), -0.074, tol, "e3");
    close(om("DE"), 0.093, tol, "w4");
    close(al("DE"), -0.011, tol, "e4");
    close(vel(l, st, w, "E").x, -0.066, tol, "v_E");
    close(acc(l, st, w, 0.0, "E").x, 0.045, tol, "a_E");
    // E stays on the slide line y = 0.
    assert!(pos(l, st, "E").y.abs() < 1e-12);
    // Transmission angle at B between the coupler and the rocker: about 117°.
    let mu = fourbar::transmission_angle(&pos(l, st, "A"), &pos(l, st, "B"), &Vec2::new(1.16, 0.0));
    close(mu.to_degrees(), 117.0, 0.5, "transmission angle");
}

/// The pump by hand: circle intersection for B (B left of A→C, i.e. above the line for
/// this assembly), D on CB, E to the right of D on y = 0.
fn pump_closed_form(q: f64) -> (Vec2, Vec2, Vec2) {
    let a = Vec2::new(0.42 * q.cos(), 0.42 * q.sin());
    let c = Vec2::new(1.16, 0.0);
    let d = c - a;
    let dist = d.norm();
    let x = (1.05 * 1.05 - 0.74 * 0.74 + dist * dist) / (2.0 * dist);
    let h = (1.05 * 1.05 - x * x).sqrt();
    let u = d / dist;
    let b = a + u * x + Vec2::new(-u.y, u.x) * h;
    let dd = c + (b - c) * (0.65 / 0.74);
    let e = Vec2::new(dd.x + (1.25f64.powi(2) - dd.y * dd.y).sqrt(), 0.0);
    (b, dd, e)
}

#[test]
fn oil_pump_full_turn_keeps_its_branch_closes_the_loop_and_matches_the_closed_form() {
    let m = mech("scenarios/oil_pump.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    assert!(sw.stopped.is_none());
    assert!(sw.samples.len() >= 361, "1° steps over a full turn");
    assert_eq!(sw.groups.len(), 2, "two loops: {:?}", sw.groups);
    let first: Vec<i8> = sw.samples[0].indicators.iter().map(|x| sign(*x)).collect();
    assert!(first.iter().all(|&s| s != 0));
    for st in &sw.samples {
        let signs: Vec<i8> = st.indicators.iter().map(|x| sign(*x)).collect();
        assert_eq!(signs, first, "branch jumped at {}°", st.s.to_degrees());
        assert!(!st.singular);
        let r = residual_vec(l, &st.q, st.s).amax();
        assert!(r <= 1e-12, "loop residual {r} at {}°", st.s.to_degrees());
        let (b, d, e) = pump_closed_form(st.s);
        for (n, p) in [("B", b), ("D", d), ("E", e)] {
            assert!(
                (pos(l, st, n) - p).norm() < 1e-12,
                "{n} at {}°",
                st.s.to_degrees()
            );
        }
    }
    // After a turn every link is back (the crank one turn on).
    let (q0, q1) = (&sw.samples[0].q, &sw.samples.last().unwrap().q);
    for i in 0..l.links.len() {
        let turn = if i == link(l, "OA") { 2.0 * PI } else { 0.0 };
        assert!((q1[3 * i + 2] - q0[3 * i + 2] - turn).abs() < 1e-9);
        assert!((q1[3 * i] - q0[3 * i]).abs() < 1e-12);
    }
}

#[test]
fn the_other_assembly_mode_has_the_other_indicator_sign() {
    let m = mech("scenarios/oil_pump.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    let ours = at_deg(&sw, 150.0);
    // Guess B below the line AC (the other intersection): a different solution, and the
    // indicator of the coupler-rocker group flips.
    let mut g = std::collections::HashMap::new();
    g.insert("B".to_string(), Vec2::new(0.52, -0.36));
    g.insert("D".to_string(), Vec2::new(0.59, -0.32));
    g.insert("E".to_string(), Vec2::new(1.80, 0.0));
    let q0 = l.coordinates_from_points(&g, &[]).unwrap();
    let t = Tracker::assemble(l, &q0, 150f64.to_radians(), NewtonOptions::default()).unwrap();
    let other = t.state();
    assert!((pos(l, other, "B") - pos(l, ours, "B")).norm() > 0.5);
    assert_eq!(sign(other.indicators[0]), -sign(ours.indicators[0]));
    assert_eq!(sign(other.indicators[1]), sign(ours.indicators[1]));
}

#[test]
fn a_huge_step_is_refused_rather_than_jumping_branch() {
    let m = mech("scenarios/oil_pump.toml");
    let l = &m.linkage;
    let reference = run_sweep(&m);
    let mut t = Tracker::assemble(
        l,
        &m.assembly,
        150f64.to_radians(),
        NewtonOptions::default(),
    )
    .unwrap();
    // Let the tracker try the whole way in one predictor step: Newton from such a poor
    // prediction may close on either branch; the tracker must halve until it holds.
    t.max_step = 4.0;
    let signs0: Vec<i8> = t.state().indicators.iter().map(|x| sign(*x)).collect();
    for target in [330.0, 20.0, 200.0, 150.0 + 360.0] {
        let st = t.advance(f64::to_radians(target)).unwrap();
        let signs: Vec<i8> = st.indicators.iter().map(|x| sign(*x)).collect();
        assert_eq!(signs, signs0, "jumped at {target}°");
        let r = at_deg(&reference, target % 360.0);
        assert!(
            (pos(l, &st, "E") - pos(l, r, "E")).norm() < 1e-10,
            "{target}°"
        );
    }
}

#[test]
fn oil_pump_velocities_and_accelerations_match_central_differences_of_the_positions() {
    let m = mech("scenarios/oil_pump.toml");
    let l = &m.linkage;
    // A fine sweep: h = 0.1°.
    let mut opts = m.sweep;
    opts.step = 0.1f64.to_radians();
    let sw = sweep(l, &m.assembly, &opts).unwrap();
    let h = opts.step;
    let scale_v = sw.samples.iter().map(|s| s.dq.amax()).fold(0.0, f64::max);
    let scale_a = sw.samples.iter().map(|s| s.ddq.amax()).fold(0.0, f64::max);
    let mut worst_v: f64 = 0.0;
    let mut worst_a: f64 = 0.0;
    for k in 1..sw.samples.len() - 1 {
        let (a, b, c) = (&sw.samples[k - 1], &sw.samples[k], &sw.samples[k + 1]);
        let dv = (&c.q - &a.q) / (2.0 * h) - &b.dq;
        let da = (&c.q - &b.q * 2.0 + &a.q) / (h * h) - &b.ddq;
        worst_v = worst_v.max(dv.amax() / scale_v);
        worst_a = worst_a.max(da.amax() / scale_a);
    }
    // Truncation h²/6 q''' and h²/12 q'''' with h = 1.7e-3: ~1e-6 relative.
    assert!(worst_v < 2e-6, "velocity vs central differences: {worst_v}");
    assert!(
        worst_a < 2e-6,
        "acceleration vs central differences: {worst_a}"
    );
}

#[test]
fn oil_pump_grashof_transmission_extremes_and_dead_centres_agree_with_closed_forms() {
    let c = fourbar::classify(1.16, 0.42, 1.05, 0.74);
    assert_eq!(c.class, GrashofClass::Grashof);
    assert_eq!(c.kind, "crank-rocker");
    assert!(c.input_rotates && !c.output_rotates);
    let v = report_json("scenarios/oil_pump.toml");
    let (mu0, mu180) = fourbar::transmission_extremes(1.16, 0.42, 1.05, 0.74);
    let ext = &v["extremes"]["transmission_angle_deg"];
    // The sweep's extremes (sampled at 1°, but they fall on 0° and 180°).
    close(
        ext["min"].as_f64().unwrap(),
        mu0.unwrap().to_degrees(),
        1e-9,
        "μ min",
    );
    close(
        ext["max"].as_f64().unwrap(),
        mu180.unwrap().to_degrees(),
        1e-9,
        "μ max",
    );
    // The rocker's dead centres: crank and coupler in line, |OB| = b ± a.
    let dcs = v["dead_centres"].as_array().unwrap();
    let rocker: Vec<f64> = dcs
        .iter()
        .filter(|d| d["follower"] == "CB")
        .map(|d| d["input_deg"].as_f64().unwrap().to_radians())
        .collect();
    assert_eq!(rocker.len(), 2);
    for phi in rocker {
        let a = Vec2::new(0.42 * phi.cos(), 0.42 * phi.sin());
        let (b, _, _) = pump_closed_form(phi);
        let ob = b.norm();
        let collinear = (ob - (1.05 + 0.42)).abs().min((ob - (1.05 - 0.42)).abs());
        assert!(
            collinear < 1e-9,
            "crank and coupler not in line: |OB| = {ob}"
        );
        assert!(armsim::machines::linkage::cross(&a, &(b - a)).abs() < 1e-9);
    }
    // The stroke of E: between the two dead centres.
    let stroke = v["followers"]["slider"]["stroke"].as_f64().unwrap();
    let xs: Vec<f64> = dcs
        .iter()
        .filter(|d| d["follower"] == "slider")
        .map(|d| {
            pump_closed_form(d["input_deg"].as_f64().unwrap().to_radians())
                .2
                .x
        })
        .collect();
    close(stroke, (xs[0] - xs[1]).abs(), 1e-9, "stroke");
}

fn report_json(rel: &str) -> Value {
    let o = cli(&["run", rel, "--json"]);
    assert!(
        o.status.success(),
        "{rel}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).expect("JSON")
}

#[test]
fn oil_pump_json_has_the_sweep_contract() {
    let v = report_json("scenarios/oil_pump.toml");
    let sweep = v["sweep"].as_array().unwrap();
    assert!(sweep.len() >= 360);
    let s150 = sweep.iter().find(|s| s["input_deg"] == 150.0).unwrap();
    for p in ["A", "B", "D", "E"] {
        for k in ["p", "v", "a"] {
            assert_eq!(
                s150["points"][p][k].as_array().map(Vec::len),
                Some(2),
                "{p}.{k}"
            );
        }
    }
    for l in ["OA", "AB", "CB", "DE"] {
        for k in ["angle_deg", "omega", "alpha"] {
            assert!(s150["links"][l][k].is_number(), "{l}.{k}");
        }
    }
    close(
        s150["points"]["E"]["v"][0].as_f64().unwrap(),
        -0.066,
        6e-4,
        "v_E in JSON",
    );
    close(
        s150["links"]["CB"]["omega"].as_f64().unwrap(),
        0.235,
        6e-4,
        "w3 in JSON",
    );
    close(
        s150["transmission_angle_deg"].as_f64().unwrap(),
        117.4,
        0.1,
        "μ in JSON",
    );
    assert!(v["extremes"]["points"]["E"]["x"]["max"].is_number());
    assert_eq!(v["branches"]["constant"], true);
    assert_eq!(v["four_bar"]["grashof"]["kind"], "crank-rocker");
    assert_eq!(v["mobility"]["grubler"], 1);
    assert_eq!(v["mobility"]["mobility"], 1);
    let text = cli(&["run", "scenarios/oil_pump.toml"]);
    let t = String::from_utf8_lossy(&text.stdout);
    assert!(t.contains("crank-rocker") && t.contains("0.235464"), "{t}");
}

// ---------------------------------------------------------------------------------------
// Problem-book slider-cranks (docs/reference_data.md §S2b), against the closed form x_C(φ).

/// `(x_C, dx/dφ, d²x/dφ², rod angle β, dβ/dφ, d²β/dφ²)` of a slider-crank with crank
/// `r`, rod `l`, offset `e`, slider to the right.
fn slider_crank_closed_form(r: f64, l: f64, e: f64, phi: f64) -> [f64; 6] {
    let (s, c) = phi.sin_cos();
    let u = r * s - e;
    let (u1, u2) = (r * c, -r * s);
    let w = (l * l - u * u).sqrt();
    let x = r * c + w;
    let x1 = -r * s - u * u1 / w;
    let x2 = -r * c - (u1 * u1 + u * u2) / w - u * u * u1 * u1 / (w * w * w);
    // sin β = −u / l.
    let beta = (-u / l).asin();
    let cb = w / l;
    let b1 = -u1 / (l * cb);
    let b2 = (-u2 / l + beta.sin() * b1 * b1) / cb;
    [x, x1, x2, beta, b1, b2]
}

#[test]
fn centric_slider_crank_at_90_degrees() {
    let m = mech("scenarios/slider_crank_centric.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    let w = m.speed;
    let st = at_deg(&sw, 90.0);
    // Published: v_C = 4 m/s, |a_C| = w² AB tan 30° = 92.4 m/s².
    close(vel(l, st, w, "C").norm(), 4.0, 1e-12, "|v_C|");
    close(
        acc(l, st, w, 0.0, "C").norm(),
        w * w * 0.1 * 30f64.to_radians().tan(),
        1e-9,
        "|a_C|",
    );
    close(
        acc(l, st, w, 0.0, "C").norm(),
        92.4,
        0.05,
        "|a_C| published",
    );
    // The whole turn against the closed form.
    for st in &sw.samples {
        let [x, x1, x2, beta, b1, b2] = slider_crank_closed_form(0.1, 0.2, 0.0, st.s);
        close(pos(l, st, "C").x, x, 1e-12, "x_C");
        close(vel(l, st, w, "C").x, x1 * w, 1e-9, "v_C");
        close(acc(l, st, w, 0.0, "C").x, x2 * w * w, 1e-7, "a_C");
        let k = link(l, "BC");
        close(
            armsim::machines::linkage::wrap_angle(st.q[3 * k + 2] - beta),
            0.0,
            1e-12,
            "rod angle",
        );
        close(st.dq[3 * k + 2], b1, 1e-10, "rod rate");
        close(st.ddq[3 * k + 2], b2, 1e-9, "rod acceleration");
    }
}

#[test]
fn isosceles_slider_crank_at_30_degrees_and_through_its_change_points() {
    let m = mech("scenarios/slider_crank_isosceles.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    let w = m.speed;
    let st = at_deg(&sw, 30.0);
    let rod = link(l, "BC");
    close(vel(l, st, w, "C").norm(), 1.0, 1e-12, "|v_C|");
    close(acc(l, st, w, 0.0, "C").norm(), 17.32, 0.005, "|a_C|");
    close(st.dq[3 * rod + 2] * w, -w, 1e-12, "w2 = -w1");
    close(st.ddq[3 * rod + 2], 0.0, 1e-12, "e2");
    // x_C = 2 r cos φ on the whole turn, through the change points 90° and 270° where the
    // rod stands perpendicular to the slide (the other branch keeps C at A).
    let sing: Vec<f64> = sw
        .singular_positions
        .iter()
        .map(|s| s.to_degrees())
        .collect();
    assert!(
        sing.iter().any(|s| (s - 90.0).abs() < 1e-6)
            && sing.iter().any(|s| (s - 270.0).abs() < 1e-6),
        "{sing:?}"
    );
    for st in &sw.samples {
        let phi = st.s;
        // At the change points the velocity and acceleration are limits along the branch
        // (see src/mechanism/sweep.rs), good to ~1e-11 and ~1e-7.
        close(pos(l, st, "C").x, 0.2 * phi.cos(), 1e-12, "x_C");
        close(vel(l, st, w, "C").x, -0.2 * w * phi.sin(), 1e-9, "v_C");
        close(
            acc(l, st, w, 0.0, "C").x,
            -0.2 * w * w * phi.cos(),
            1e-6,
            "a_C",
        );
        close(st.dq[3 * rod + 2], -1.0, 1e-8, "rod rate");
    }
    let s90 = at_deg(&sw, 90.0);
    assert!(s90.singular && s90.limit && !s90.locked);
}

#[test]
fn slider_crank_dead_centre_is_solved_and_reported() {
    let m = mech("scenarios/slider_crank_dead_centre.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    let w = m.speed;
    let odc = at_deg(&sw, 0.0);
    let idc = at_deg(&sw, 180.0);
    // Crank and rod collinear: v_C = 0, |a_C| = w² r (1 ± r/l).
    assert!(vel(l, odc, w, "C").norm() < 1e-12);
    close(
        acc(l, odc, w, 0.0, "C").norm(),
        60.0,
        1e-9,
        "outer dead centre",
    );
    close(
        acc(l, odc, w, 0.0, "C").norm(),
        w * w * 0.1 * (1.0 + 0.5),
        1e-9,
        "w² r (1 + r/l)",
    );
    assert!(vel(l, idc, w, "C").norm() < 1e-12);
    close(
        acc(l, idc, w, 0.0, "C").norm(),
        w * w * 0.1 * (1.0 - 0.5),
        1e-9,
        "inner dead centre",
    );
    // The crank-driven problem is regular there; driving from the slider would not be.
    assert!(!odc.singular);
    let mut from_slider = l.clone();
    from_slider.driver = Driver::Slide {
        link: link(l, "slider"),
        p: Vec2::zeros(),
        through: Vec2::zeros(),
        dir: Vec2::new(1.0, 0.0),
    };
    assert!(conditioning(&from_slider, &odc.q).singular);
    assert!(!conditioning(&from_slider, &at_deg(&sw, 90.0).q).singular);
    // ...yet the slider-driven velocity problem at rest is consistent and still solved.
    let v = solve_velocity(&from_slider, &odc.q, 0.0, None);
    assert!(v.residual < 1e-14 && v.rank < from_slider.ncoords());
    // Reported: in the sweep and in the list of dead centres.
    let j = report_json("scenarios/slider_crank_dead_centre.toml");
    let s0 = &j["sweep"][0];
    assert_eq!(s0["input_deg"], 0.0);
    assert!(s0["dead_centre"]
        .as_array()
        .unwrap()
        .iter()
        .any(|x| x == "slider"));
    assert_eq!(s0["singular"], false);
    let dcs: Vec<f64> = j["dead_centres"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["input_deg"].as_f64().unwrap())
        .collect();
    assert_eq!(dcs.len(), 2, "{dcs:?}");
    assert!(
        dcs[0].abs() < 1e-9 && (dcs[1] - 180.0).abs() < 1e-9,
        "{dcs:?}"
    );
    close(
        j["followers"]["slider"]["stroke"].as_f64().unwrap(),
        0.2,
        1e-12,
        "stroke 2r",
    );
}

#[test]
fn offset_slider_crank_stroke_and_time_ratio() {
    let v = report_json("scenarios/slider_crank_offset.toml");
    let (r, l, e) = (0.1f64, 0.3f64, 0.05f64);
    let stroke = ((l + r).powi(2) - e * e).sqrt() - ((l - r).powi(2) - e * e).sqrt();
    close(
        v["followers"]["slider"]["stroke"].as_f64().unwrap(),
        stroke,
        1e-12,
        "stroke",
    );
    let outer = (e / (l + r)).asin();
    let inner = PI + (e / (l - r)).asin();
    let fwd = inner - outer;
    let ratio = fwd.max(2.0 * PI - fwd) / fwd.min(2.0 * PI - fwd);
    close(
        v["followers"]["slider"]["time_ratio"].as_f64().unwrap(),
        ratio,
        1e-10,
        "time ratio",
    );
    let m = mech("scenarios/slider_crank_offset.toml");
    let sw = run_sweep(&m);
    for st in &sw.samples {
        let [x, x1, x2, ..] = slider_crank_closed_form(r, l, e, st.s);
        close(pos(&m.linkage, st, "C").x, x, 1e-12, "x_C");
        close(vel(&m.linkage, st, 10.0, "C").x, x1 * 10.0, 1e-9, "v_C");
        close(
            acc(&m.linkage, st, 10.0, 0.0, "C").x,
            x2 * 100.0,
            1e-7,
            "a_C",
        );
    }
}

#[test]
fn shaper_quick_return_time_ratio() {
    let v = report_json("scenarios/shaper_quick_return.toml");
    let a = (0.1f64 / 0.3).asin();
    let ratio = (PI + 2.0 * a) / (PI - 2.0 * a);
    close(
        v["followers"]["ram"]["time_ratio"].as_f64().unwrap(),
        ratio,
        1e-10,
        "time ratio",
    );
    // At the dead centres the crank is perpendicular to the lever.
    let m = mech("scenarios/shaper_quick_return.toml");
    let l = &m.linkage;
    for d in v["dead_centres"].as_array().unwrap() {
        let phi = d["input_deg"].as_f64().unwrap().to_radians();
        let a = Vec2::new(0.1 * phi.cos(), 0.3 + 0.1 * phi.sin());
        let crank = a - Vec2::new(0.0, 0.3);
        assert!(crank.dot(&a).abs() < 1e-9, "crank ⟂ lever at {phi}");
    }
    assert_eq!(mobility(l, &m.assembly).grubler, 1);
    assert_eq!(mobility(l, &m.assembly).half_joints, 1);
}

#[test]
fn scotch_yoke_velocity_and_acceleration() {
    let m = mech("scenarios/scotch_yoke.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    let w = m.speed;
    for st in &sw.samples {
        let phi = st.s;
        // World x of the yoke: x = r cos φ. The book's displacement from the outer dead
        // centre s = r (1 − cos φ) = r − x has v = sin φ, a = 10 cos φ (r w = 1, r w² = 10).
        let (x, v, a) = (
            pos(l, st, "Y").x,
            vel(l, st, w, "Y").x,
            acc(l, st, w, 0.0, "Y").x,
        );
        close(x, 0.1 * phi.cos(), 1e-12, "x");
        close(-v, phi.sin(), 1e-12, "book v = sin φ");
        close(-a, 10.0 * phi.cos(), 1e-10, "book a = 10 cos φ");
    }
}

#[test]
fn parallelogram_keeps_its_branch_through_the_change_points() {
    let m = mech("scenarios/four_bar_parallelogram.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    let w = m.speed;
    assert!(sw.stopped.is_none());
    let coupler = link(l, "BC");
    for st in &sw.samples {
        let (vb, vc) = (vel(l, st, w, "B"), vel(l, st, w, "C"));
        close(vb.norm(), 1.0, 1e-12, "|v_B|");
        assert!(
            (vc - vb).norm() < 1e-9,
            "v_C ≠ v_B at {}°",
            st.s.to_degrees()
        );
        // The coupler translates: it stays parallel to the ground (a parallelogram).
        close(
            armsim::machines::linkage::wrap_angle(st.q[3 * coupler + 2]),
            0.0,
            1e-7,
            "coupler angle",
        );
        assert!((pos(l, st, "C") - pos(l, st, "B") - Vec2::new(0.2, 0.0)).norm() < 1e-7);
    }
    // 0° and 180° are change points: singular, passed on the same branch.
    for deg in [0.0, 180.0, 360.0] {
        let st = at_deg(&sw, deg);
        assert!(st.singular && st.limit && !st.locked, "{deg}°");
        assert!(
            (acc(l, st, w, 0.0, "C") - acc(l, st, w, 0.0, "B")).norm() < 2e-6,
            "a_C at {deg}°"
        );
    }
    // A coupler point of a parallelogram traces a circle of the crank's radius.
    let v = report_json("scenarios/four_bar_parallelogram.toml");
    for p in v["coupler_curves"]["P"].as_array().unwrap() {
        let (x, y) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
        close(
            ((x - 0.1).powi(2) + (y - 0.05).powi(2)).sqrt(),
            0.1,
            1e-7,
            "coupler circle",
        );
    }
    assert_eq!(v["four_bar"]["grashof"]["kind"], "parallelogram");
    assert_eq!(v["four_bar"]["grashof"]["class"], "change-point");
}

#[test]
fn antiparallelogram_branch_exists_at_the_same_lengths_and_stays_crossed() {
    let m = mech("scenarios/four_bar_antiparallelogram.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    assert!(sw.stopped.is_none());
    let st = at_deg(&sw, 45.0);
    // The closed form's other intersection.
    let (_, c_anti) = fourbar::position(0.2, 0.1, 0.2, 0.1, PI / 4.0, -1.0).unwrap();
    let (_, c_para) = fourbar::position(0.2, 0.1, 0.2, 0.1, PI / 4.0, 1.0).unwrap();
    assert!(
        (c_para - Vec2::new(0.2 + 0.1 * (PI / 4.0).cos(), 0.1 * (PI / 4.0).sin())).norm() < 1e-12
    );
    assert!((pos(l, st, "C") - c_anti).norm() < 1e-12);
    // Crossed over the whole turn: C never sits at B + (0.2, 0) except at the change points.
    for st in &sw.samples {
        let off = (pos(l, st, "C") - pos(l, st, "B") - Vec2::new(0.2, 0.0)).norm();
        let at_change = (st.s.sin()).abs() < 1e-9;
        assert!(
            at_change || off > 1e-3,
            "became a parallelogram at {}°",
            st.s.to_degrees()
        );
        // An antiparallelogram's diagonals AC and BD are parallel (its vertices form an
        // isosceles trapezoid).
        let (a, b, c, d) = (
            Vec2::zeros(),
            pos(l, st, "B"),
            pos(l, st, "C"),
            Vec2::new(0.2, 0.0),
        );
        close(
            armsim::machines::linkage::cross(&(c - a), &(d - b)),
            0.0,
            1e-7,
            "AC ∥ BD",
        );
    }
    // Here v_C ≠ v_B.
    assert!((vel(l, st, 10.0, "C") - vel(l, st, 10.0, "B")).norm() > 0.1);
}

#[test]
fn redundant_constraints_are_found_by_rank_where_grubler_fails() {
    // A parallelogram with a third crank EF parallel to AB and DC (locomotive coupling
    // rods): Grübler counts 3·4 − 2·6 = 0, but it moves, with one redundant equation.
    let l = Linkage::with_shared_pins(
        "double parallelogram",
        vec![
            ("A".into(), Vec2::zeros()),
            ("E".into(), Vec2::new(0.1, 0.0)),
            ("D".into(), Vec2::new(0.2, 0.0)),
        ],
        vec![
            PlanarLink::binary("AB", "A", "B", 0.1),
            PlanarLink::new(
                "BC",
                vec![
                    ("B".into(), Vec2::zeros()),
                    ("F".into(), Vec2::new(0.1, 0.0)),
                    ("C".into(), Vec2::new(0.2, 0.0)),
                ],
            ),
            PlanarLink::binary("DC", "D", "C", 0.1),
            PlanarLink::binary("EF", "E", "F", 0.1),
        ],
        Vec::new(),
        Driver::Angle {
            link: 0,
            relative_to: GROUND,
        },
    );
    let phi = 0.7f64;
    let b = Vec2::new(0.1 * phi.cos(), 0.1 * phi.sin());
    let mut g = std::collections::HashMap::new();
    g.insert("B".to_string(), b);
    g.insert("C".to_string(), b + Vec2::new(0.2, 0.0));
    g.insert("F".to_string(), b + Vec2::new(0.1, 0.0));
    let q0 = l.coordinates_from_points(&g, &[]).unwrap();
    let sol = solve_position(
        &l,
        &(q0.clone() + DVector::from_element(q0.len(), 1e-3)),
        phi,
        &NewtonOptions::default(),
    )
    .unwrap();
    let mob = mobility(&l, &sol.q);
    assert_eq!(mob.grubler, 0);
    assert_eq!(mob.mobility, 1);
    assert_eq!(mob.redundant, 1);
    // The minimum-norm solve still gives the motion: every coupler point at 1 m/s.
    let v = solve_velocity(&l, &sol.q, 10.0, None);
    assert!(v.residual < 1e-12);
    for p in ["B", "F", "C"] {
        let (bd, lp) = l.find_point(p).unwrap();
        close(
            l.point_velocity(&sol.q, &v.x, bd, &lp).norm(),
            1.0,
            1e-12,
            p,
        );
    }
    // The plain four-bar has no redundancy.
    let fb = catalog::four_bar(0.2, 0.1, 0.2, 0.1);
    let q = catalog::four_bar_guess(&fb, (0.2, 0.1, 0.2, 0.1), 0.7, 1.0).unwrap();
    let m4 = mobility(&fb, &q);
    assert_eq!((m4.grubler, m4.mobility, m4.redundant), (1, 1, 0));
}

// ---------------------------------------------------------------------------------------
// Constraint derivatives against finite differences.

fn test_linkages() -> Vec<(Linkage, DVector<f64>)> {
    let mut v = Vec::new();
    for rel in [
        "scenarios/oil_pump.toml",
        "scenarios/shaper_quick_return.toml",
        "scenarios/scotch_yoke.toml",
    ] {
        let m = mech(rel);
        v.push((m.linkage.clone(), m.assembly.clone()));
    }
    // A slide driver and a moving guide with a prismatic joint on it.
    let mut sc = catalog::slider_crank(0.1, 0.3, 0.02);
    sc.links[0].com = Vec2::new(0.03, 0.01);
    sc.joints
        .push(armsim::machines::linkage::PlanarJoint::Slider(Slider {
            name: "extra".into(),
            link: 2,
            p: Vec2::new(0.01, 0.02),
            guide: 1,
            through: Vec2::new(0.05, 0.0),
            dir: Vec2::new(0.6, 0.8),
            prismatic: Some(0.3),
        }));
    sc.driver = Driver::Slide {
        link: 1,
        p: Vec2::new(0.1, 0.0),
        through: Vec2::new(0.1, 0.2),
        dir: Vec2::new(0.8, -0.6),
    };
    let q = DVector::from_fn(9, |i, _| 0.1 + 0.37 * i as f64);
    v.push((sc, q));
    v
}

#[test]
fn constraint_jacobian_and_gamma_match_finite_differences() {
    for (l, q0) in test_linkages() {
        let n = l.ncoords();
        // Arbitrary (off-manifold) configuration and velocity: the formulas hold anywhere.
        let q = DVector::from_fn(n, |i, _| q0[i] + 0.05 * ((i as f64) * 1.3).sin());
        let qd = DVector::from_fn(n, |i, _| 0.3 * ((i as f64) * 0.7 + 0.2).cos());
        let jac = jacobian_mat(&l, &q);
        let h = 1e-6;
        for c in 0..n {
            let mut qp = q.clone();
            let mut qm = q.clone();
            qp[c] += h;
            qm[c] -= h;
            let fd = (residual_vec(&l, &qp, 0.3) - residual_vec(&l, &qm, 0.3)) / (2.0 * h);
            assert!(
                (fd - jac.column(c)).amax() < 1e-8,
                "{}: Φ_q column {c}",
                l.name
            );
        }
        // γ = −(Φ_q q̇)_q q̇ (scleronomic rows; the driver adds s̈).
        let jq = |x: &DVector<f64>| jacobian_mat(&l, x) * &qd;
        let fd = (jq(&(&q + &qd * h)) - jq(&(&q - &qd * h))) / (2.0 * h);
        let g = gamma_vec(&l, &q, &qd, 0.0);
        assert!((&g + &fd).amax() < 1e-7, "{}: γ", l.name);
        let g2 = gamma_vec(&l, &q, &qd, 2.5);
        assert!((g2[l.nrows() - 1] - g[l.nrows() - 1] - 2.5).abs() < 1e-14);
    }
}

#[test]
fn slide_driven_slider_crank_inverts_the_crank_driven_ratio() {
    let sc = catalog::slider_crank(0.1, 0.25, 0.0);
    let mut by_slider = sc.clone();
    by_slider.driver = Driver::Slide {
        link: 2,
        p: Vec2::zeros(),
        through: Vec2::zeros(),
        dir: Vec2::new(1.0, 0.0),
    };
    let phi = 1.1;
    let q = catalog::slider_crank_guess(&sc, 0.1, 0.25, 0.0, phi, 1.0);
    let q = solve_position(&sc, &q, phi, &NewtonOptions::default())
        .unwrap()
        .q;
    let x = by_slider.input_value(&q);
    let q2 = solve_position(&by_slider, &q, x, &NewtonOptions::default())
        .unwrap()
        .q;
    assert!((&q2 - &q).amax() < 1e-12);
    let vc = solve_velocity(&sc, &q, 1.0, None).x; // per unit crank rate
    let vs = solve_velocity(&by_slider, &q, 1.0, None).x; // per unit slider rate
    let dx_dphi = vc[6];
    close(vs[2] * dx_dphi, 1.0, 1e-12, "dφ/dx · dx/dφ");
    let [_, x1, x2, ..] = slider_crank_closed_form(0.1, 0.25, 0.0, phi);
    close(dx_dphi, x1, 1e-12, "dx/dφ");
    // d²φ/dx² = −x'' / x'³.
    let a = solve_acceleration(&by_slider, &q, &vs, 0.0, None).x;
    close(a[2], -x2 / x1.powi(3), 1e-9, "d²φ/dx²");
}

// ---------------------------------------------------------------------------------------
// Kinetostatics (docs/reference_data.md §S2b): joint forces vs virtual power, against dT/dt
// by hand.

#[test]
fn slider_crank_kinetostatics_matches_virtual_power_and_the_book() {
    let sc = scenario("scenarios/slider_crank_kinetostatics.toml");
    let m = sc.mechanism.as_ref().unwrap();
    let l = &m.linkage;
    let loads = &m.kinetostatics.as_ref().unwrap().loads;
    assert_eq!(loads.gravity, Vec2::zeros());
    let sw = run_sweep(m);
    let w = m.speed;
    for st in &sw.samples {
        let (qd, qdd) = (st.qd(w), st.qdd(w, 0.0));
        let k = kinetostatics::solve(l, &st.q, &qdd, loads);
        let vp = virtual_power::driving_effort(l, &st.q, &qd, &qdd, loads, w).unwrap();
        assert!(
            (k.driving - vp).abs() <= 1e-9 * k.driving.abs().max(1.0),
            "{} vs {vp}",
            k.driving
        );
        assert!(k.residual < 1e-9);
        // Shaking force two ways: from the ground reactions, and −Σ m a_G.
        let mut sum = Vec2::zeros();
        for (i, link) in l.links.iter().enumerate() {
            sum -= Vec2::new(qdd[3 * i], qdd[3 * i + 1]) * link.mass;
        }
        assert!((k.shaking_force - sum).norm() < 1e-8 * sum.norm().max(1.0));
    }
    let st = at_deg(&sw, 45.0);
    let qdd = st.qdd(w, 0.0);
    let k = kinetostatics::solve(l, &st.q, &qdd, loads);
    // Crank inertia force m1 w1² AS1 = 8000 N.
    close(
        k.inertia[link(l, "AB")].0.norm(),
        10.0 * w * w * 0.02,
        1e-9,
        "crank inertia force",
    );
    // Balancing torque: the book's graphical ~85 N m within 5 %.
    assert!(
        (k.driving - 85.0).abs() <= 0.05 * 85.0,
        "driving torque {}",
        k.driving
    );
    // Independently: at constant w the driving torque is dT/dt / w = ½ w² dI/dφ with the
    // reduced inertia I(φ) = m2 |dS2/dφ|² + J2 β'² + m3 x'² (the crank's is constant).
    let inertia = |phi: f64| {
        let [_, x1, _, beta, b1, _] = slider_crank_closed_form(0.074, 0.2, 0.0, phi);
        let ds2 = Vec2::new(
            -0.074 * phi.sin() - 0.06 * beta.sin() * b1,
            0.074 * phi.cos() + 0.06 * beta.cos() * b1,
        );
        0.5 * ds2.norm_squared() + 0.0018 * b1 * b1 + 0.4 * x1 * x1
    };
    let (phi, h) = (PI / 4.0, 1e-5);
    let torque = 0.5 * w * w * (inertia(phi + h) - inertia(phi - h)) / (2.0 * h);
    close(k.driving, torque, 1e-6 * torque, "driving torque vs dT/dt");
    // Over a turn the inertia torque does no net work.
    let drive: Vec<f64> = sw
        .samples
        .iter()
        .map(|s| kinetostatics::solve(l, &s.q, &s.qdd(w, 0.0), loads).driving)
        .collect();
    let phis: Vec<f64> = sw.samples.iter().map(|s| s.s).collect();
    let e = flywheel::energy_curve(&phis, &drive);
    assert!(e.last().unwrap().abs() < 1e-6 * drive.iter().fold(0.0f64, |a, b| a.max(b.abs())));
}

#[test]
fn slider_crank_kinetostatics_report_prints_both_methods() {
    let v = report_json("scenarios/slider_crank_kinetostatics.toml");
    let at = &v["kinetostatics"]["at"][0];
    close(at["input_deg"].as_f64().unwrap(), 45.0, 1e-12, "at 45°");
    let (d, vp) = (
        at["driving"].as_f64().unwrap(),
        at["driving_virtual_power"].as_f64().unwrap(),
    );
    assert!(
        (d - vp).abs() < 1e-9 && (d - 84.625).abs() < 1e-3,
        "{d} {vp}"
    );
    close(
        at["inertia_forces"]["AB"]["magnitude"].as_f64().unwrap(),
        8000.0,
        1e-7,
        "8000 N",
    );
    assert!(
        v["kinetostatics"]["max_virtual_power_difference"]
            .as_f64()
            .unwrap()
            < 1e-9
    );
    // Counterweight: rotating masses fully and half the reciprocating mass.
    let cw = &v["counterweight"];
    let m_rot = 10.0 * 0.02 / 0.074 + 0.5 * 0.14 / 0.2;
    let m_rec = 0.4 + 0.5 * 0.06 / 0.2;
    close(
        cw["counterweight"]["rotating_mass"].as_f64().unwrap(),
        m_rot,
        1e-12,
        "m_rot",
    );
    close(
        cw["counterweight"]["reciprocating_mass"].as_f64().unwrap(),
        m_rec,
        1e-12,
        "m_rec",
    );
    close(
        cw["counterweight"]["mass"].as_f64().unwrap(),
        (m_rot + 0.5 * m_rec) * 0.074 / 0.05,
        1e-12,
        "m_cw",
    );
    // The balanced linkage's shaking force (from its joint forces) is the two-mass formula.
    assert!(cw["deviation_from_two_mass_formula"].as_f64().unwrap() < 1e-6);
    let (before, after) = (
        cw["max_shaking_force_before"].as_f64().unwrap(),
        cw["max_shaking_force_after"].as_f64().unwrap(),
    );
    assert!(after < 0.2 * before, "{before} → {after}");
    // Flywheel: J = ΔE / (δ w²).
    let fw = &v["flywheel"];
    close(
        fw["inertia"].as_f64().unwrap(),
        fw["energy_fluctuation"].as_f64().unwrap() / (0.02 * 200.0 * 200.0),
        1e-15,
        "J",
    );
    assert!(fw["mean_torque"].as_f64().unwrap().abs() < 1e-6);
}

#[test]
fn slider_crank_fully_balanced_by_rod_and_crank_counterweights() {
    let v = report_json("scenarios/slider_crank_full_balance.toml");
    let fb = &v["counterweight"]["full_balance"];
    let (r, l, c1, c2) = (0.074_f64, 0.2_f64, 0.02, 0.06);
    let (m1, m2, m3, e, rho) = (10.0, 0.5, 0.4, 0.05, 0.05);
    let mr = (m2 * c2 + m3 * l) / e;
    let mc = (m1 * c1 + (m2 + m3 + mr) * r) / rho;
    close(fb["rod_mass"].as_f64().unwrap(), mr, 1e-12, "m_r");
    close(mr, 2.2, 1e-12, "m_r by hand");
    close(fb["crank_mass"].as_f64().unwrap(), mc, 1e-12, "m_c");
    close(mc, 8.588, 1e-12, "m_c by hand");
    close(
        fb["rod_position"][0].as_f64().unwrap(),
        -e,
        1e-12,
        "beyond B",
    );
    close(
        fb["crank_position"][0].as_f64().unwrap(),
        -rho,
        1e-12,
        "beyond A",
    );
    // The total centre of mass over a turn, by hand: B = r(cos φ, sin φ), C on the x axis,
    // the rod's points along B→C, the crank's along A→B.
    let mut first: Option<(f64, f64)> = None;
    for k in 0..72 {
        let phi = (k as f64 * 5.0).to_radians();
        let b = (r * phi.cos(), r * phi.sin());
        let c = (b.0 + (l * l - b.1 * b.1).sqrt(), 0.0);
        let (ux, uy) = ((c.0 - b.0) / l, (c.1 - b.1) / l);
        let pts = [
            (m1, c1 / r * b.0, c1 / r * b.1),
            (mc, -rho / r * b.0, -rho / r * b.1),
            (m2, b.0 + c2 * ux, b.1 + c2 * uy),
            (mr, b.0 - e * ux, b.1 - e * uy),
            (m3, c.0, c.1),
        ];
        let mx: f64 = pts.iter().map(|p| p.0 * p.1).sum();
        let my: f64 = pts.iter().map(|p| p.0 * p.2).sum();
        let f = *first.get_or_insert((mx, my));
        assert!(
            (mx - f.0).abs() < 1e-12 && (my - f.1).abs() < 1e-12,
            "φ = {k}·5°"
        );
    }
    // The linkage solver's shaking force (from its joint forces) vanishes too.
    let cw = &v["counterweight"];
    let before = cw["max_shaking_force_before"].as_f64().unwrap();
    let after = cw["max_shaking_force_after"].as_f64().unwrap();
    assert!(
        before > 1000.0 && after < 1e-6 * before,
        "{before} → {after}"
    );
}

#[test]
fn gear_balancers_cancel_the_primary_and_secondary_reciprocating_force() {
    let v = report_json("scenarios/slider_crank_gear_balancer.toml");
    let gb = &v["counterweight"]["gear_balancers"];
    let (r, l, w) = (0.074_f64, 0.2_f64, 200.0_f64);
    let m_rec = 0.4 + 0.5 * 0.06 / 0.2;
    let lam = r / l;
    let get = |k: &str| gb[k].as_f64().unwrap();
    close(
        get("primary_mass_radius_per_gear"),
        m_rec * r / 2.0,
        1e-15,
        "primary m r",
    );
    close(
        get("secondary_mass_radius_per_gear"),
        m_rec * r * lam / 8.0,
        1e-15,
        "secondary m r",
    );
    close(
        get("primary_amplitude_N"),
        m_rec * r * w * w,
        1e-9,
        "m_rec r ω²",
    );
    close(
        get("secondary_amplitude_N"),
        m_rec * r * w * w * lam,
        1e-9,
        "m_rec r ω² λ",
    );
    // The force left, by hand: the exact piston acceleration ω² x''(φ) of
    // x = r cos φ + √(l² − r² sin² φ), against the balancers' −m_rec r ω² (cos φ + λ cos 2φ).
    let x2 = |p: f64| {
        let d = l * l - r * r * p.sin().powi(2);
        -r * p.cos()
            - (r * r * (2.0 * p).cos() * d + r.powi(4) * (2.0 * p).sin().powi(2) / 4.0)
                / d.powf(1.5)
    };
    let (mut prim, mut both) = (0.0_f64, 0.0_f64);
    for k in 0..36000 {
        let p = (k as f64 * 0.01).to_radians();
        let shaking = -m_rec * w * w * x2(p);
        prim = prim.max((shaking - m_rec * r * w * w * p.cos()).abs());
        both = both.max((shaking - m_rec * r * w * w * (p.cos() + lam * (2.0 * p).cos())).abs());
    }
    close(
        get("max_force_left_primary"),
        prim,
        1e-3 * prim,
        "primary pair only",
    );
    close(get("max_force_left_both"), both, 1e-3 * both, "both pairs");
    assert!(
        both < 0.1 * prim && prim < 0.5 * m_rec * r * w * w,
        "{prim} {both}"
    );
}

#[test]
fn kinetostatic_joint_forces_balance_each_link() {
    // Each link: Σ joint forces + loads + d'Alembert = 0, and so are the moments — checked
    // from the reported forces, not the multipliers.
    let m = mech("scenarios/oil_pump.toml");
    let l = &m.linkage;
    let mut loads = Loads {
        gravity: Vec2::new(0.0, -9.81),
        ..Default::default()
    };
    let mut heavy = l.clone();
    for (i, k) in heavy.links.iter_mut().enumerate() {
        k.mass = 10.0 + i as f64;
        k.inertia = 0.5 + 0.1 * i as f64;
        k.com = k.points.iter().map(|(_, p)| *p).sum::<Vec2>() / k.points.len() as f64
            + Vec2::new(0.01, -0.02);
    }
    loads.forces.push(kinetostatics::PointForce {
        link: link(l, "slider"),
        p: Vec2::zeros(),
        force: Vec2::new(-2000.0, 0.0),
    });
    let sw = run_sweep(&m);
    let st = at_deg(&sw, 150.0);
    let (q, qd, qdd) = l.transfer_motion(&heavy, &st.q, &st.qd(0.5), &st.qdd(0.5, 0.0));
    let k = kinetostatics::solve(&heavy, &q, &qdd, &loads);
    let vp = virtual_power::driving_effort(&heavy, &q, &qd, &qdd, &loads, 0.5).unwrap();
    close(
        k.driving,
        vp,
        1e-9 * vp.abs(),
        "driving torque: multipliers vs virtual power",
    );
    for (i, link_i) in heavy.links.iter().enumerate() {
        let (rg, _) = heavy.pose(&q, i);
        let mut f = loads.gravity * link_i.mass + k.inertia[i].0;
        let mut mo = k.inertia[i].1;
        for pf in loads.forces.iter().filter(|p| p.link == i) {
            f += pf.force;
            mo += armsim::machines::linkage::cross(
                &(heavy.point_position(&q, i, &pf.p) - rg),
                &pf.force,
            );
        }
        for jf in &k.joint_forces {
            let at = match &heavy.joints[jf.joint] {
                armsim::machines::linkage::PlanarJoint::Revolute { a, pa, .. } => {
                    heavy.point_position(&q, *a, pa)
                }
                armsim::machines::linkage::PlanarJoint::Slider(s) => {
                    heavy.point_position(&q, s.link, &s.p)
                }
                armsim::machines::linkage::PlanarJoint::Contact(c) => {
                    armsim::machines::linkage::contact_rows::geometry(&heavy, &q, c).point
                }
            };
            let sgn = if jf.on == i {
                1.0
            } else if jf.by == i {
                -1.0
            } else {
                continue;
            };
            f += jf.force * sgn;
            mo += sgn * (armsim::machines::linkage::cross(&(at - rg), &jf.force) + jf.couple);
        }
        if i == heavy.driven_link() {
            mo += k.driving;
        }
        assert!(
            f.norm() < 1e-8 * 2000.0,
            "force balance of {}: {f:?}",
            link_i.name
        );
        assert!(
            mo.abs() < 1e-8 * 2000.0,
            "moment balance of {}: {mo}",
            link_i.name
        );
    }
}

// ---------------------------------------------------------------------------------------
// Balancing, flywheel, machine motion.

#[test]
fn two_plane_rotor_balancing_matches_the_book() {
    let masses: Vec<RotorMass> = [
        (0.2, 0.010, 0.0, 0.0),
        (0.3, 0.015, PI, 0.1),
        (0.2, 0.012, PI, 0.2),
        (0.4, 0.020, 0.0, 0.3),
    ]
    .iter()
    .map(|&(mass, radius, angle, position)| RotorMass {
        mass,
        radius,
        angle,
        position,
    })
    .collect();
    let [cl, cr] = balancing::two_plane(&masses, (0.0, 0.05), (0.3, 0.04));
    close(cl.mass, 0.036, 1e-12, "left correction");
    close(cr.mass, 0.1225, 1e-12, "right correction");
    // Balanced: no resultant force and no moment about any plane.
    let mut all = masses.clone();
    all.push(cl.as_mass());
    all.push(cr.as_mass());
    for z in [0.0, 0.17, 0.3] {
        let (f, m) = balancing::resultant(&all, z);
        assert!(f.norm() < 1e-15 && m.norm() < 1e-15);
    }
    // Single plane: the force vanishes, a moment is left.
    let c = balancing::single_plane(&masses, 0.15, 0.05);
    let mut one = masses.clone();
    one.push(c.as_mass());
    let (f, m) = balancing::resultant(&one, 0.0);
    assert!(f.norm() < 1e-15 && m.norm() > 1e-4);
    close(c.mass, 0.0031 / 0.05, 1e-12, "static correction");
    let v = report_json("scenarios/rotor_two_plane_balancing.toml");
    close(
        v["rotor_balance"]["corrections"][0]["mass"]
            .as_f64()
            .unwrap(),
        0.036,
        1e-12,
        "JSON left",
    );
    close(
        v["rotor_balance"]["corrections"][1]["mass"]
            .as_f64()
            .unwrap(),
        0.1225,
        1e-12,
        "JSON right",
    );
}

#[test]
fn rotor_bearing_loads_at_speed_by_moments_about_a_bearing() {
    // Unbalances m r along x: 0.002, −0.0045, −0.0024, 0.008 kg m at z = 0, 0.1, 0.2,
    // 0.3; bearings at z_A = −0.05, z_B = 0.35; ω = 3000 rpm = 100π rad/s.
    let v = report_json("scenarios/rotor_two_plane_balancing_bearings.toml");
    let b = &v["rotor_balance"]["bearings"];
    let w2 = (100.0 * PI).powi(2);
    let sum_u = 0.002 - 0.0045 - 0.0024 + 0.008;
    let moment_a = 0.002 * 0.05 - 0.0045 * 0.15 - 0.0024 * 0.25 + 0.008 * 0.35;
    let fb = w2 * moment_a / 0.4;
    let fa = w2 * sum_u - fb;
    let at = |k: &str, i: usize| b[k]["force_N"][i].as_f64().unwrap();
    close(at("before", 0), fa.abs(), 1e-9, "F_A");
    close(at("before", 1), fb.abs(), 1e-9, "F_B");
    close(at("before", 0), 94.995, 1e-3, "F_A by hand");
    close(at("before", 1), 400.95, 5e-3, "F_B by hand");
    // F_A points against the masses' direction (0°), F_B along it.
    close(
        b["before"]["angle_deg"][0].as_f64().unwrap().abs(),
        180.0,
        1e-9,
        "A's angle",
    );
    close(
        b["before"]["angle_deg"][1].as_f64().unwrap(),
        0.0,
        1e-9,
        "B's angle",
    );
    close(
        b["centrifugal_force_N"].as_f64().unwrap(),
        w2 * sum_u,
        1e-9,
        "ω² Σ m r",
    );
    // Balanced in two planes: no load left on either bearing.
    assert!(at("after", 0) < 1e-9 && at("after", 1) < 1e-9);
}

#[test]
fn machine_motion_from_rest_matches_the_closed_form() {
    let h = machine_motion::integrate(
        0.1,
        &Characteristic(vec![100.0, -1.0]),
        &Characteristic(vec![5.0]),
        0.0,
        0.5,
        1e-3,
    );
    let mut worst: f64 = 0.0;
    for (t, w) in h.t.iter().zip(&h.omega) {
        worst = worst.max((w - 95.0 * (1.0 - (-10.0 * t).exp())).abs());
    }
    assert!(worst < 1e-7, "RK4 vs 95 (1 − e^(−10 t)): {worst}");
    let phi_exact = machine_motion::linear_angle(0.1, 100.0, 1.0, 5.0, 0.0, 0.5);
    close(*h.phi.last().unwrap(), phi_exact, 1e-7, "angle");
    close(
        phi_exact,
        95.0 * 0.5 - 9.5 * (1.0 - (-5.0f64).exp()),
        1e-12,
        "angle closed form",
    );
    // A coarse step is visibly worse: the comparison can fail.
    let coarse = machine_motion::integrate(
        0.1,
        &Characteristic(vec![100.0, -1.0]),
        &Characteristic(vec![5.0]),
        0.0,
        0.5,
        0.1,
    );
    assert!((coarse.omega[1] - 95.0 * (1.0 - (-1.0f64).exp())).abs() > 1e-3);
    let v = report_json("scenarios/machine_motion.toml");
    assert!(
        v["machine_motion"]["max_error_vs_closed_form"]
            .as_f64()
            .unwrap()
            < 1e-7
    );
    close(
        v["machine_motion"]["steady_speed"].as_f64().unwrap(),
        95.0,
        1e-12,
        "steady speed",
    );
    close(
        v["machine_motion"]["time_constant"].as_f64().unwrap(),
        0.1,
        1e-12,
        "time constant",
    );
}

#[test]
fn flywheel_energy_fluctuation_and_the_speed_it_allows() {
    // M_d = 100 + 40 sin 2φ against a constant load 100: E(φ) = 20 (1 − cos 2φ), ΔE = 40.
    let n = 3600;
    let phi: Vec<f64> = (0..=n).map(|k| 2.0 * PI * k as f64 / n as f64).collect();
    let drive: Vec<f64> = phi.iter().map(|p| 100.0 + 40.0 * (2.0 * p).sin()).collect();
    let fw = flywheel::size(&phi, &drive, None, 50.0, 0.01);
    close(fw.mean_torque, 100.0, 1e-9, "mean");
    close(fw.energy_fluctuation, 40.0, 1e-4, "ΔE");
    close(fw.inertia, 40.0 / (0.01 * 2500.0), 1e-4, "J");
    // Run the machine with that flywheel: J ω dω/dφ = M_d(φ) − M_load, by Simpson's rule
    // in φ on ½ω², starting at the energy minimum (φ = 0) with the speed that makes the
    // mean of the extremes 50 rad/s; the speed then swings by δ ω_mean.
    let j = fw.inertia;
    let (mut e, h) = (0.5 * 49.75f64 * 49.75, 2.0 * PI / 20000.0);
    let f = |p: f64| 40.0 * (2.0 * p).sin() / j;
    let (mut wmax, mut wmin) = (0.0f64, f64::INFINITY);
    for k in 0..20000 {
        let p = k as f64 * h;
        e += h / 6.0 * (f(p) + 4.0 * f(p + 0.5 * h) + f(p + h));
        let w = (2.0 * e).sqrt();
        wmax = wmax.max(w);
        wmin = wmin.min(w);
    }
    close(0.5 * (wmax + wmin), 50.0, 1e-6, "mean speed");
    close((wmax - wmin) / (0.5 * (wmax + wmin)), 0.01, 1e-6, "δ");
}

#[test]
fn grashof_classes() {
    let k = |g, a, b, c| fourbar::classify(g, a, b, c).kind;
    assert_eq!(k(1.16, 0.42, 1.05, 0.74), "crank-rocker");
    assert_eq!(k(2.5, 3.0, 1.0, 2.2), "double-rocker");
    assert_eq!(k(0.4, 1.0, 1.2, 1.1), "double-crank");
    assert_eq!(k(1.0, 1.2, 0.8, 0.4), "rocker-crank");
    assert_eq!(k(1.0, 0.5, 0.6, 0.7), "triple-rocker");
    assert_eq!(
        fourbar::classify(1.0, 0.5, 0.6, 0.7).class,
        GrashofClass::NonGrashof
    );
    assert_eq!(
        fourbar::classify(1.0, 0.9, 0.8, 0.7).class,
        GrashofClass::ChangePoint
    );
    assert_eq!(k(0.2, 0.1, 0.2, 0.1), "parallelogram");
    assert_eq!(k(0.2, 0.2, 0.1, 0.1), "deltoid");
}

// ---------------------------------------------------------------------------------------
// Spatial loop closure on the tree model.

fn four_bar_tree() -> armsim::model::Model {
    use armsim::core::spatial::{Se3, Vec3};
    use armsim::model::{JointSpec, JointType, LinkSpec, ModelSpec};
    let names = ["base", "crank", "coupler", "rocker", "tip", "ground_c"];
    let links = names.iter().map(|n| LinkSpec::new(*n)).collect();
    let mut joints = Vec::new();
    for (name, parent, child, x, ty) in [
        ("j1", "base", "crank", 0.0, JointType::Continuous),
        ("j2", "crank", "coupler", 0.42, JointType::Continuous),
        ("j3", "coupler", "rocker", 1.05, JointType::Continuous),
        ("tip_fix", "rocker", "tip", 0.74, JointType::Fixed),
        ("c_fix", "base", "ground_c", 1.16, JointType::Fixed),
    ] {
        let mut j = JointSpec::new(name, ty, parent, child);
        j.origin = Se3::from_translation(Vec3::new(x, 0.0, 0.0));
        j.axis = Vec3::z();
        joints.push(j);
    }
    let spec = ModelSpec {
        name: "four-bar tree".into(),
        source: "<test>".into(),
        root_offset: Se3::identity(),
        links,
        joints,
        urdf_text: None,
        gravity: None,
        warnings: Vec::new(),
    };
    armsim::model::Model::build(spec).unwrap().0
}

#[test]
fn spatial_point_closure_of_a_four_bar_tree_matches_the_planar_solver() {
    let model = four_bar_tree();
    let mut data = armsim::model::data::Data::new(&model);
    let closure = LoopClosure {
        link_a: model.link_id("tip").unwrap(),
        link_b: model.link_id("ground_c").unwrap(),
        kind: ClosureKind::Position,
    };
    let m = mech("scenarios/oil_pump.toml");
    let l = &m.linkage;
    let sw = run_sweep(&m);
    for deg in [0.0, 60.0, 150.0, 250.0] {
        let st = at_deg(&sw, deg);
        let th = |n: &str| st.q[3 * link(l, n) + 2];
        // Tree coordinates: crank angle, then relative angles; the rocker link runs B → C.
        let q_planar = [th("OA"), th("AB") - th("OA"), th("CB") + PI - th("AB")];
        let guess = [q_planar[0], q_planar[1] + 0.08, q_planar[2] - 0.05];
        let p =
            spatial_loop::project(&model, &mut data, &[closure], &guess, &[0], 1e-13, 50).unwrap();
        assert_eq!(p.q[0], q_planar[0], "the input is held");
        assert_eq!(
            (p.rank, p.redundant),
            (2, 1),
            "the z row is identically zero"
        );
        for (k, qk) in q_planar.iter().enumerate().skip(1) {
            close(
                armsim::machines::linkage::wrap_angle(p.q[k] - qk),
                0.0,
                1e-10,
                "joint angle",
            );
        }
        // Velocities: J_free q̇_free = −J_fixed q̇_fixed.
        let mut qd = [0.5, 0.0, 0.0];
        spatial_loop::constrained_velocity(&model, &mut data, &[closure], &p.q, &[0], &mut qd);
        let w = |n: &str| st.dq[3 * link(l, n) + 2] * 0.5;
        close(qd[1], w("AB") - w("OA"), 1e-10, "coupler rate");
        close(qd[2], w("CB") - w("AB"), 1e-10, "rocker rate");
    }
}

#[test]
fn spatial_pose_closure_jacobian_matches_finite_differences_and_projects() {
    let p = root().join("robots/ur5.urdf");
    let mut spec = armsim::model::Model::read_spec(&p).unwrap();
    let (model0, _) = armsim::model::Model::build(spec.clone()).unwrap();
    let mut data0 = armsim::model::data::Data::new(&model0);
    let q_target = [0.3, -1.1, 1.4, -0.6, 0.9, 0.4];
    armsim::kinematics::forward_kinematics(&model0, &mut data0, &q_target);
    let target =
        armsim::kinematics::frame_placement(&model0, &data0, model0.link_id("tool0").unwrap());
    // A frame fixed in the world at the target pose.
    spec.links.push(armsim::model::LinkSpec::new("target"));
    let mut j = armsim::model::JointSpec::new(
        "target_fix",
        armsim::model::JointType::Fixed,
        spec.links[0].name.clone(),
        "target",
    );
    j.origin = target;
    spec.joints.push(j);
    let (model, _) = armsim::model::Model::build(spec).unwrap();
    let mut data = armsim::model::data::Data::new(&model);
    let c = LoopClosure {
        link_a: model.link_id("tool0").unwrap(),
        link_b: model.link_id("target").unwrap(),
        kind: ClosureKind::Pose,
    };
    // Jacobian against central differences of the residual (log map included).
    let q = [0.1, -0.7, 1.9, -1.2, 0.5, 2.2];
    let jac = spatial_loop::jacobian(&model, &mut data, &[c], &q);
    let h = 1e-6;
    for k in 0..6 {
        let mut qp = q;
        let mut qm = q;
        qp[k] += h;
        qm[k] -= h;
        let fd = (spatial_loop::residual(&model, &mut data, &[c], &qp)
            - spatial_loop::residual(&model, &mut data, &[c], &qm))
            / (2.0 * h);
        assert!(
            (&fd - jac.column(k)).amax() < 1e-8,
            "column {k}: {fd} vs {}",
            jac.column(k)
        );
    }
    // Projection from a perturbed configuration, holding the first joint.
    let start: Vec<f64> = q_target
        .iter()
        .enumerate()
        .map(|(i, x)| if i == 0 { *x } else { x + 0.05 })
        .collect();
    let pr = spatial_loop::project(&model, &mut data, &[c], &start, &[0], 1e-12, 50).unwrap();
    assert!(pr.residual <= 1e-12);
    assert_eq!(pr.q[0], q_target[0]);
    for (got, want) in pr.q.iter().zip(&q_target) {
        close(*got, *want, 1e-9, "projected joint");
    }
}

#[test]
fn log3_handles_small_and_near_pi_rotations() {
    use armsim::core::spatial::{axis_angle, Vec3};
    let axis = Vec3::new(0.48, -0.6, 0.64);
    for angle in [0.0, 1e-9, 1e-4, 0.7, 3.0, PI - 1e-7, PI] {
        let r = axis_angle(&axis, angle);
        let e = spatial_loop::log3(&r);
        let back = axis_angle(
            &(if e.norm() > 0.0 { e / e.norm() } else { axis }),
            e.norm(),
        );
        assert!((back - r).amax() < 1e-9, "angle {angle}");
        close(e.norm(), angle, 1e-8, "angle");
    }
}

// ---------------------------------------------------------------------------------------
// Broken scenarios: located errors, no panic.

/// `(file, line, key, message fragment)`.
const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "linkage_unknown_key.toml",
        9,
        "links.AB.lenght",
        "unknown field `lenght`",
    ),
    (
        "linkage_missing_length.toml",
        11,
        "links.BC.length",
        "needs its `length`",
    ),
    (
        "linkage_cannot_assemble.toml",
        17,
        "links.DC",
        "cannot be assembled",
    ),
    (
        "linkage_unknown_driver_link.toml",
        22,
        "driver.link",
        "no link 'crank'",
    ),
    (
        "linkage_singular_assembly.toml",
        31,
        "sweep.assemble_at_deg",
        "singular position",
    ),
    (
        "linkage_bad_slider_type.toml",
        23,
        "sliders[0].type",
        "unknown slider type 'rotary'",
    ),
    (
        "linkage_rotor_mismatch.toml",
        6,
        "rotor_balance.radii",
        "has 3 values",
    ),
    (
        "linkage_counterweight_fraction_and_rod.toml",
        54,
        "counterweight.fraction",
        "one of the two",
    ),
    (
        "linkage_rotor_speed_without_bearings.toml",
        11,
        "rotor_balance.speed_rpm",
        "together",
    ),
    (
        "linkage_friction_coefficient.toml",
        37,
        "kinetostatics.friction_coefficient",
        "must be in [0, 1], got 1.5",
    ),
    (
        "linkage_pin_radius_without_friction.toml",
        37,
        "kinetostatics.pin_radius",
        "needs friction_coefficient",
    ),
    (
        "linkage_report_point_far_away.toml",
        36,
        "sweep.report_at_deg[1]",
        "-1e308° lies 1e308° outside the sweep (0° to 360°): reporting there would track more than 100000 steps",
    ),
    (
        "linkage_link_length_out_of_range.toml",
        17,
        "links.BC.length",
        "1e-300 is out of range: a length lies in 1e-100..1e100",
    ),
    (
        "linkage_link_length_out_of_scale.toml",
        18,
        "links.BC.length",
        "1e-12 is 5e-12 times the mechanism's size (0.2, its largest length or coordinate)",
    ),
    (
        "linkage_negative_pin_radius.toml",
        38,
        "kinetostatics.pin_radius",
        "must be a radius in 0 … 1000 m, got -0.01",
    ),
    (
        "linkage_machine_negative_ratio.toml",
        6,
        "machine_motion.ratio",
        "must be a positive number between 1e-6 and 1e6",
    ),
    (
        "linkage_machine_inertia_without_linkage.toml",
        6,
        "machine_motion.inertia_from_linkage",
        "needs a linkage in the file driven by an angle over a full turn",
    ),
    (
        "linkage_machine_inertia_table_order.toml",
        6,
        "machine_motion.inertia_deg[2]",
        "the angles must increase",
    ),
    (
        "linkage_instant_centres_nowhere.toml",
        37,
        "instant_centres",
        "no input to report at",
    ),
    (
        "linkage_pin_radii_unknown_joint.toml",
        39,
        "kinetostatics.pin_radii.E",
        "no joint of the linkage is named 'E' (its pins: A, D, B, C)",
    ),
];

#[test]
fn broken_linkage_scenarios_give_located_errors() {
    let listed: Vec<&str> = BROKEN.iter().map(|b| b.0).collect();
    common::assert_lists_every_broken_scenario("linkage_", &listed);
    for &(file, line, key, msg) in BROKEN {
        let rel = format!("tests/broken_scenarios/{file}");
        let text = std::fs::read_to_string(root().join(&rel)).unwrap();
        let e = parse(&rel, &text).expect_err(file);
        assert_eq!(e.line, Some(line), "{file}: {e}");
        assert_eq!(e.key, key, "{file}: {e}");
        assert!(e.message.contains(msg), "{file}: {e}");
        let o = cli(&["run", &rel]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && o.stdout.is_empty(), "{file}");
        assert!(
            err.contains(&format!("{rel}:{line}: {key}: ")),
            "{file}: {err}"
        );
        assert!(!err.contains("panicked"), "{file}: {err}");
    }
}

#[test]
fn every_linkage_scenario_runs() {
    let dir = root().join("scenarios");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        let text = std::fs::read_to_string(&p).unwrap();
        if !text.lines().any(|l| l.trim() == "kind = \"linkage\"") {
            continue;
        }
        let rel = format!("scenarios/{}", p.file_name().unwrap().to_string_lossy());
        let sc = parse(&rel, &text).unwrap_or_else(|e| panic!("{e}"));
        let r = armsim::scenarios::linkage::report::report(&sc, armsim::scenarios::linkage::NAME);
        assert!(r.json.get("error").is_none(), "{rel}: {}", r.json["error"]);
        assert!(
            r.json.get("stopped").is_none(),
            "{rel}: {}",
            r.json["stopped"]
        );
        n += 1;
    }
    assert!(n >= 12, "{n} linkage scenarios");
}

#[test]
fn sweep_options_in_the_other_direction_track_backwards() {
    let m = mech("scenarios/oil_pump.toml");
    let fwd = run_sweep(&m);
    let opts = SweepOptions {
        from: 2.0 * PI,
        to: 0.0,
        ..m.sweep
    };
    let back = sweep(&m.linkage, &m.assembly, &opts).unwrap();
    assert_eq!(back.samples.len(), fwd.samples.len());
    for (a, b) in back.samples.iter().rev().zip(&fwd.samples) {
        assert!((a.s - b.s).abs() < 1e-12);
        // Same positions up to the crank's full turn.
        for i in 0..m.linkage.links.len() {
            assert!((a.q[3 * i] - b.q[3 * i]).abs() < 1e-10);
            assert!((a.dq[3 * i + 2] - b.dq[3 * i + 2]).abs() < 1e-10);
        }
    }
}

#[test]
fn a_triple_rocker_driven_past_its_limit_stops_there_and_says_so() {
    // g = 1, input 0.5, coupler 0.6, output 0.7: s + l = 1.5 > 1.3, the input rocks between
    // the angles where coupler and output line up, |AC| = b + c: cos φ = (a² + g² − 1.69) / (2ag).
    let dims = (1.0, 0.5, 0.6, 0.7);
    assert_eq!(
        fourbar::classify(dims.0, dims.1, dims.2, dims.3).kind,
        "triple-rocker"
    );
    let l = catalog::four_bar(dims.0, dims.1, dims.2, dims.3);
    let q = catalog::four_bar_guess(&l, dims, 0.3, 1.0).unwrap();
    let opts = SweepOptions {
        from: 0.0,
        to: 2.0 * PI,
        step: 1f64.to_radians(),
        assemble_at: 0.3,
        newton: NewtonOptions::default(),
    };
    let sw = sweep(&l, &q, &opts).unwrap();
    let limit = ((0.25 + 1.0 - 1.69) / 1.0f64).acos();
    let last = sw.samples.last().unwrap().s;
    assert!(
        last <= limit && limit - last < 1f64.to_radians(),
        "last sample {last}"
    );
    match &sw.stopped {
        Some(armsim::machines::linkage::sweep::TrackError::Stuck { at, .. }) => {
            assert!((at - limit).abs() < 1e-4, "stopped at {at}, limit {limit}")
        }
        other => panic!("expected a stop at the limit, got {other:?}"),
    }
}

#[test]
fn a_slide_driven_sweep_follows_the_inverse_closed_form_and_stops_at_the_dead_centre() {
    let sc = catalog::slider_crank(0.1, 0.25, 0.0);
    let mut by_slider = sc.clone();
    by_slider.driver = Driver::Slide {
        link: 2,
        p: Vec2::zeros(),
        through: Vec2::zeros(),
        dir: Vec2::new(1.0, 0.0),
    };
    let q = catalog::slider_crank_guess(&sc, 0.1, 0.25, 0.0, 1.0, 1.0);
    let x0 = by_slider.input_value(
        &solve_position(&sc, &q, 1.0, &NewtonOptions::default())
            .unwrap()
            .q,
    );
    let opts = SweepOptions {
        from: 0.2,
        to: 0.4,
        step: 0.002,
        assemble_at: x0,
        newton: NewtonOptions::default(),
    };
    let sw = sweep(&by_slider, &q, &opts).unwrap();
    // The slider cannot go past the outer dead centre x = r + l = 0.35.
    assert!(sw.stopped.is_some());
    let last = sw.samples.last().unwrap().s;
    assert!(last <= 0.35 && last > 0.348, "{last}");
    for st in &sw.samples {
        // Crank angle from the law of cosines, on the upper branch (0 < φ < π).
        let x = st.s;
        let phi = ((x * x + 0.01 - 0.0625) / (0.2 * x)).acos();
        close(st.q[2], phi, 1e-9, "crank angle");
        let [_, x1, ..] = slider_crank_closed_form(0.1, 0.25, 0.0, phi);
        if !st.singular {
            close(
                st.dq[2],
                1.0 / x1,
                1e-6 * (1.0 / x1).abs().max(1.0),
                "dφ/dx",
            );
        }
    }
}
