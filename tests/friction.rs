//! Friction and efficiency (docs/reference_data.md §M4): the published checkpoints through
//! `armsim run --json` on the bundled scenarios, independent routes (Euler's belt law by
//! integrating `dS/dθ = f S`, band brakes by that integration and lever moments, the screw as an incline of angle λ, the collar torques by
//! integrating the pressure over the annulus), and the broken files.

use armsim::machines::friction::elements::{
    band_brake, collar_torque, incline, parallel, screw, series, shoe_coefficient,
    shoe_normal_force, BrakeGiven,
};
use serde_json::Value;
use std::f64::consts::FRAC_PI_2;

mod common;
use common::run_json;

fn g(v: &Value, i: usize, k: &str) -> f64 {
    v["elements"][i][k]
        .as_f64()
        .unwrap_or_else(|| panic!("{k}"))
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

#[test]
fn fr2_square_thread_jack_lifts_18640_newtons_and_locks() {
    let v = run_json("scenarios/friction_fr2_square_thread_jack.toml");
    close(g(&v, 0, "load_N"), 18640.0, 5.0, "Q");
    close(g(&v, 0, "lead_angle_deg"), 2.43, 0.005, "λ");
    close(g(&v, 0, "friction_angle_deg"), 5.71, 0.005, "φ");
    assert_eq!(v["elements"][0]["self_locking"], true);
}

#[test]
fn fr3_sliding_and_rolling_forces() {
    let v = run_json("scenarios/friction_fr3_sliding_rolling.toml");
    close(g(&v, 0, "force_N"), 1000.0, 1e-9, "a");
    close(g(&v, 1, "force_N"), 1414.2, 0.05, "b");
    close(g(&v, 2, "force_N"), 420.0, 1e-9, "c");
    close(g(&v, 3, "force_N"), 20.0, 1e-9, "d");
}

#[test]
fn fr5_trapezoid_jack_torque_and_efficiency() {
    let v = run_json("scenarios/friction_fr5_trapezoid_jack.toml");
    close(g(&v, 0, "lead_angle_deg"), 3.17, 0.005, "λ");
    close(g(&v, 0, "friction_angle_deg"), 7.08, 0.005, "φ'");
    close(g(&v, 0, "thread_torque_Nm"), 41.6, 0.05, "thread");
    close(g(&v, 0, "collar_torque_Nm"), 54.0, 1e-9, "collar");
    close(g(&v, 0, "torque_Nm"), 95.6, 0.05, "M");
    close(g(&v, 0, "efficiency"), 0.133, 0.0005, "η");
    close(g(&v, 0, "handle_length_m"), 0.48, 0.005, "l");
}

#[test]
fn crane_165_friction_torque_and_power() {
    let v = run_json("scenarios/friction_165_crane.toml");
    close(g(&v, 0, "torque_Nm"), 392.7, 0.05, "journal");
    close(g(&v, 1, "torque_Nm"), 133.3, 0.05, "pivot");
    close(v["total_torque_Nm"].as_f64().unwrap(), 918.7, 0.05, "total");
    close(v["friction_power_W"].as_f64().unwrap(), 289.0, 0.5, "power");
}

#[test]
fn wedge_173_and_belt_176() {
    let v = run_json("scenarios/friction_173_176_wedge_belt.toml");
    close(g(&v, 0, "pull_out_N"), 84100.0, 50.0, "wedge");
    assert_eq!(v["elements"][0]["self_locking"], true);
    close(g(&v, 1, "initial_tension_N"), 2250.0, 1e-9, "S0");
    close(g(&v, 1, "shaft_load_N"), 4500.0, 1e-9, "shaft");
    close(g(&v, 1, "tight_N"), 3000.0, 1e-9, "S1");
}

#[test]
fn fr4_band_brakes_hold_570_and_11333_newtons_with_the_books_euler_factor() {
    let v = run_json("scenarios/friction_fr4_band_brakes.toml");
    // Book, e^(fβ) = 1.85: S2 = 250 / 5000 N, F = 213 / 4250 N, Q = 570 / 11 333 N.
    close(g(&v, 0, "slack_N"), 250.0, 1e-9, "simple S2");
    close(g(&v, 0, "braking_force_N"), 212.5, 1e-9, "simple F");
    close(g(&v, 0, "load_held_N"), 566.67, 0.01, "simple Q (book 570)");
    close(g(&v, 1, "slack_N"), 5000.0, 1e-6, "differential S2");
    close(g(&v, 1, "braking_force_N"), 4250.0, 1e-6, "differential F");
    close(g(&v, 1, "load_held_N"), 11333.33, 0.01, "differential Q");
    assert_eq!(v["elements"][0]["brake"], "simple");
    assert_eq!(v["elements"][1]["brake"], "differential");
    assert_eq!(v["elements"][1]["self_locking"], false);
    // Exact e^(0.2π): 583 N and 13 931 N (re-derived in the sheet).
    close(
        g(&v, 2, "euler_factor"),
        (0.2 * std::f64::consts::PI).exp(),
        1e-12,
        "e",
    );
    close(g(&v, 2, "load_held_N"), 583.0, 0.5, "simple Q exact");
    close(
        g(&v, 3, "load_held_N"),
        13931.0,
        5.0,
        "differential Q exact",
    );
    // The differential brake is close to locking (b/a = 2 vs e = 1.85): ~9 % per % of f.
    close(g(&v, 1, "friction_sensitivity"), 8.93, 0.01, "sensitivity");
    close(
        g(&v, 0, "friction_sensitivity"),
        1.338,
        0.001,
        "simple sensitivity",
    );
    for i in 0..4 {
        close(g(&v, i, "lever_load_N"), 200.0, 1e-9, "G l / l");
    }
}

#[test]
fn band_brake_matches_band_integration_and_lever_moments() {
    // Integrate dS/dθ = f S over the wrap (RK4) for S1/S2, take moments about the lever
    // pivot by hand, and compare with the library; then the sensitivity by differences.
    let (f, wrap, a, b, gl) = (0.25_f64, 3.5_f64, 0.1_f64, 0.45_f64, 120.0_f64);
    let n = 2000;
    let h = wrap / n as f64;
    let mut s = 1.0_f64;
    for _ in 0..n {
        let k1 = f * s;
        let k2 = f * (s + h * k1 / 2.0);
        let k3 = f * (s + h * k2 / 2.0);
        let k4 = f * (s + h * k3);
        s += h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0;
    }
    // Moments: S2 b − S1 a = G l with S1 = s S2.
    let s2 = gl / (b - a * s);
    let bb = band_brake((f * wrap).exp(), a, b, BrakeGiven::LeverMoment(gl)).unwrap();
    close(bb.s2, s2, 1e-8 * s2, "S2");
    close(bb.s1, s * s2, 1e-8 * s2, "S1");
    close(bb.s2 * b - bb.s1 * a, gl, 1e-9, "lever moment balance");
    let force = |f: f64| {
        band_brake((f * wrap).exp(), a, b, BrakeGiven::LeverMoment(gl))
            .unwrap()
            .force
    };
    let d = 1e-6;
    let fd =
        (force(f * (1.0 + d)).ln() - force(f * (1.0 - d)).ln()) / ((1.0 + d).ln() - (1.0 - d).ln());
    close(bb.friction_sensitivity, fd, 1e-6, "d ln F / d ln f");
    // Given the braking force instead, the same state comes back.
    let back = band_brake((f * wrap).exp(), a, b, BrakeGiven::BrakingForce(bb.force)).unwrap();
    close(back.lever_moment, gl, 1e-9, "lever moment from the force");
    // Past the limit e ≥ b/a the brake locks: no lever load fixes the tensions.
    assert!(band_brake(5.0, a, b, BrakeGiven::LeverMoment(gl)).is_none());
    assert!(
        band_brake(5.0, a, b, BrakeGiven::BrakingForce(100.0))
            .unwrap()
            .self_locking
    );
}

#[test]
fn euler_belt_law_matches_integrating_the_band_equilibrium() {
    // dS/dθ = f S along the wrap (RK4), from the slack to the tight side.
    let (f, wrap) = (0.3_f64, 2.5_f64);
    let n = 1000;
    let h = wrap / n as f64;
    let mut s = 1.0_f64;
    for _ in 0..n {
        let k1 = f * s;
        let k2 = f * (s + h * k1 / 2.0);
        let k3 = f * (s + h * k2 / 2.0);
        let k4 = f * (s + h * k3);
        s += h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0;
    }
    let [_, s1, s2, ..] = armsim::machines::friction::elements::belt(1000.0, 5.0, (f * wrap).exp());
    close(s1 / s2, s, 1e-10, "S1/S2 = e^(f α)");
}

#[test]
fn screw_is_an_incline_of_its_lead_angle() {
    for (p, dm, f) in [
        (0.003, 0.0225, 0.1),
        (0.008, 0.046, 0.05),
        (0.02, 0.03, 0.2),
    ] {
        let sc = screw(1000.0, p, dm, f, 0.0, 0.0);
        // The thread's torque pushes the nut horizontally: β = 90°.
        let inc = incline(1000.0, sc.lead_angle, f, FRAC_PI_2).unwrap();
        close(sc.efficiency, inc.efficiency, 1e-12, "η");
        close(
            sc.reverse_efficiency,
            inc.reverse_efficiency.unwrap(),
            1e-12,
            "reverse η",
        );
        assert_eq!(sc.self_locking, inc.self_locking);
        assert_eq!(sc.self_locking, sc.reverse_efficiency <= 0.0);
        // Thread torque = horizontal push on the incline × mean radius.
        close(sc.thread_torque, inc.up * dm / 2.0, 1e-9, "M");
    }
    close(series(&[0.9, 0.8]), 0.72, 1e-15, "series");
    close(parallel(&[1.0, 3.0], &[0.8, 0.6]), 0.65, 1e-15, "parallel");
}

#[test]
fn collar_torques_match_integrating_the_pressure() {
    // Uniform pressure p = Q/(π(R1² − R2²)); uniform wear p r = const.
    let (f, q, r1, r2) = (0.15_f64, 1000.0_f64, 0.04_f64, 0.02_f64);
    let n = 20000;
    let dr = (r1 - r2) / n as f64;
    let (mut new, mut worn) = (0.0, 0.0);
    let c = q / (2.0 * std::f64::consts::PI * (r1 - r2));
    for k in 0..n {
        let r = r2 + (k as f64 + 0.5) * dr;
        new += f * q / (std::f64::consts::PI * (r1 * r1 - r2 * r2))
            * 2.0
            * std::f64::consts::PI
            * r
            * r
            * dr;
        worn += f * (c / r) * 2.0 * std::f64::consts::PI * r * r * dr;
    }
    close(collar_torque(f, q, r1, r2, false), new, 1e-6, "new");
    close(collar_torque(f, q, r1, r2, true), worn, 1e-6, "worn");
}

/// The push `P` at `β` to the upward vertical that moves the load `Q` up (`dir = 1`) or
/// lets it slide down (`dir = −1`) on an incline of angle `a`: the force balance along
/// and across the plane, `P d + N n ∓ f N t − Q ŷ = 0`, solved as a 2×2 system.
fn push_by_force_balance(q: f64, a: f64, f: f64, beta: f64, dir: f64) -> (f64, f64) {
    let (t, n, d) = (
        [a.cos(), a.sin()],
        [-a.sin(), a.cos()],
        [beta.sin(), beta.cos()],
    );
    // Columns: P, N; friction −dir f N t.
    let m = [[d[0], n[0] - dir * f * t[0]], [d[1], n[1] - dir * f * t[1]]];
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    let p = (0.0 * m[1][1] - m[0][1] * q) / det;
    let normal = (m[0][0] * q - m[1][0] * 0.0) / det;
    (p, normal)
}

#[test]
fn incline_push_at_any_angle_balances_the_forces_on_the_load() {
    for (a, f) in [(25.0_f64, 0.15), (10.0, 0.3), (40.0, 0.05)] {
        let a = a.to_radians();
        for beta in [0.0_f64, 30.0, 65.0, 90.0, 110.0] {
            let inc = incline(1000.0, a, f, beta.to_radians()).unwrap();
            let (up, n_up) = push_by_force_balance(1000.0, a, f, beta.to_radians(), 1.0);
            let (down, _) = push_by_force_balance(1000.0, a, f, beta.to_radians(), -1.0);
            close(inc.up, up, 1e-9, "P up");
            close(inc.down, down, 1e-9, "P down");
            assert!(n_up >= -1e-9, "the plane pulls: N = {n_up}");
            // A straight lift (β = 0) leaves the plane: no friction, P = Q.
            if beta == 0.0 {
                close(inc.up, 1000.0, 1e-9, "lift");
            }
        }
        let phi = f.atan();
        let h = incline(1000.0, a, f, FRAC_PI_2).unwrap();
        close(
            h.up,
            1000.0 * (a + phi).tan(),
            1e-9,
            "horizontal Q tan(a + φ)",
        );
        let along = incline(1000.0, a, f, FRAC_PI_2 - a).unwrap();
        close(
            along.up,
            1000.0 * (a.sin() + f * a.cos()),
            1e-9,
            "along Q(sin a + f cos a)",
        );
        close(
            along.efficiency,
            a.sin() / (a.sin() + f * a.cos()),
            1e-12,
            "η along",
        );
    }
    // Pushed from above at a + β + φ ≥ 180°, nothing moves the load up.
    assert!(incline(1000.0, 0.5, 0.1, 2.6).is_err());
}

#[test]
fn incline_scenario_gives_the_closed_forms_on_a_flat_plane_and_in_a_v_groove() {
    let v = run_json("scenarios/friction_incline_push_angle_v_groove.toml");
    for (i, up, down) in [
        (0, 1325.316, 591.259),
        (1, 1117.129, 573.344),
        (2, 1152.035, 680.192),
        (3, 1229.750, 460.723),
    ] {
        close(g(&v, i, "push_up_N"), up, 1e-3, "up");
        close(g(&v, i, "push_down_N"), down, 1e-3, "down");
    }
    close(
        g(&v, 3, "equivalent_friction"),
        0.15 / 45f64.to_radians().cos(),
        1e-12,
        "f/cos β",
    );
}

#[test]
fn shoe_brake_lever_balances_and_long_shoe_coefficient_integrates_the_pressure() {
    // Lever equilibrium about the pivot: G l + f N e − N b = 0, for either sign of e.
    for (gl, b, e, f) in [(180.0, 0.4, 0.06, 0.35), (50.0, 0.2, -0.05, 0.5)] {
        let n = shoe_normal_force(gl, b, e, f).unwrap();
        close(gl + f * n * e - n * b, 0.0, 1e-9, "lever moments");
    }
    assert_eq!(shoe_normal_force(1.0, 0.1, 0.5, 0.3), None, "b ≤ f e locks");
    // p = p0 cos ψ over ψ in [−θ/2, θ/2]: f' = f R ∫p dψ/(R ∫p cos ψ dψ).
    for deg in [1.0_f64, 60.0, 100.0, 180.0] {
        let th = deg.to_radians();
        let k = 100_000;
        let (mut fric, mut normal) = (0.0, 0.0);
        for i in 0..k {
            let psi = -th / 2.0 + (i as f64 + 0.5) * th / k as f64;
            fric += psi.cos();
            normal += psi.cos() * psi.cos();
        }
        close(shoe_coefficient(0.3, th), 0.3 * fric / normal, 1e-9, "f'");
    }
    close(shoe_coefficient(0.3, 0.0), 0.3, 0.0, "short shoe");
}

#[test]
fn shoe_brake_scenario_torques() {
    let v = run_json("scenarios/friction_shoe_brakes.toml");
    close(g(&v, 0, "braking_torque_Nm"), 41.5567, 1e-4, "single");
    close(
        g(&v, 0, "reverse_braking_torque_Nm"),
        37.4109,
        1e-4,
        "reverse",
    );
    close(g(&v, 1, "braking_torque_Nm"), 88.6932, 1e-4, "double");
    close(g(&v, 1, "equivalent_friction"), 0.392824, 1e-6, "f'");
    close(
        g(&v, 2, "lever_load_N"),
        202.947,
        1e-3,
        "lever load for 120 N m",
    );
    close(g(&v, 2, "braking_torque_Nm"), 120.0, 1e-9, "asked");
}

const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "friction_wheel_weight_on_rollers.toml",
        8,
        "element[0].wheel_weight",
        "applies to wheels on axles",
    ),
    (
        "friction_bodies_masses_and_weights.toml",
        4,
        "connected_bodies[0].masses",
        "one of the two",
    ),
    (
        "friction_bodies_pulley_count.toml",
        6,
        "connected_bodies[0].pulley_efficiency",
        "has 1 values, expected 2",
    ),
    (
        "friction_bodies_slack_rope.toml",
        6,
        "connected_bodies[0].slopes_deg",
        "a rope goes slack",
    ),
    (
        "friction_bodies_slope_range.toml",
        6,
        "connected_bodies[0].slopes_deg",
        "must be in [-90, 90], got 120",
    ),
    (
        "friction_bodies_static_below_kinetic.toml",
        7,
        "connected_bodies[0].static_friction",
        "below the kinetic one",
    ),
    (
        "friction_unknown_key.toml",
        6,
        "element.lod",
        "unknown field `lod`",
    ),
    (
        "friction_no_elements.toml",
        2,
        "kind",
        "at least one [[element]]",
    ),
    (
        "friction_unknown_type.toml",
        5,
        "element[0].type",
        "unknown element type 'clutch'",
    ),
    (
        "friction_missing_load.toml",
        4,
        "element[0].load",
        "missing",
    ),
    (
        "friction_negative_friction.toml",
        7,
        "element[0].friction",
        "must be in [0, 2]",
    ),
    (
        "friction_screw_diameters.toml",
        8,
        "element[0].diameters",
        "outer > root",
    ),
    (
        "friction_collar_half_given.toml",
        4,
        "element[0].collar_diameters",
        "together",
    ),
    (
        "friction_key_not_for_element.toml",
        10,
        "element[0].push_angle_deg",
        "does not apply to an element of type 'slide' (it reads load, friction, slide, groove_angle_deg)",
    ),
    (
        "friction_incline_push_jams.toml",
        10,
        "element[0].push_angle_deg",
        "no force at 150° to the vertical can push the load up",
    ),
    (
        "friction_shoe_brake_three_shoes.toml",
        11,
        "element[0].shoes",
        "must be 1 or 2, got 3",
    ),
    (
        "friction_nan_groove_angle.toml",
        7,
        "element[0].groove_angle_deg",
        "must be in [0, 89], got NaN",
    ),
    (
        "friction_infinite_rolling_arm.toml",
        8,
        "element[0].rolling_arms",
        "must be in [0, 1], got -inf",
    ),
    (
        "friction_bad_slide.toml",
        6,
        "element[0].slide",
        "unknown slide 'dovetail'",
    ),
    (
        "friction_belt_without_euler.toml",
        4,
        "element[0].euler_factor",
        "euler_factor",
    ),
    (
        "friction_wedge_angle.toml",
        7,
        "element[0].angle_deg",
        "must be in [0, 89]",
    ),
    ("friction_bad_speed.toml", 3, "speed_rpm", "≥ 0"),
    (
        "friction_band_brake_two_givens.toml",
        7,
        "element[0].lever_load",
        "one of the two",
    ),
    (
        "friction_band_brake_no_drum.toml",
        4,
        "element[0].drum_diameter",
        "missing",
    ),
];

#[test]
fn broken_friction_scenarios_give_located_errors() {
    common::assert_broken_scenarios("friction_", BROKEN, common::CheckSays::Refuses);
}

#[test]
fn drag_link_four_bar_with_friction_circles_pays_its_load_plus_the_friction() {
    let v = run_json("scenarios/four_bar_drag_link_friction.toml");
    let f = &v["kinetostatics"]["friction"];
    assert_eq!(f["all_converged"], true);
    close(
        f["friction_circle_radius"].as_f64().unwrap(),
        1e-3,
        1e-15,
        "ρ = f r",
    );
    // Energy per turn: the driver's work is the load's 20 · 2π plus the friction's.
    let wd = f["work_per_turn"]["driver"].as_f64().unwrap();
    let wf = f["work_per_turn"]["friction"].as_f64().unwrap();
    let useful = 40.0 * std::f64::consts::PI;
    close(wd - wf, useful, 1e-6 * useful, "W_d − W_f = load work");
    let eta = f["cycle_efficiency"].as_f64().unwrap();
    close(eta, useful / wd, 1e-9, "η = W_load/W_d");
    assert!(eta > 0.98 && eta < 1.0, "η {eta}");
    assert!(f["min_efficiency"].as_f64().unwrap() <= eta);
    // At every reported input the driver pays the ideal effort plus the friction power.
    for a in f["at"].as_array().unwrap() {
        let (d0, d) = (
            a["driving_ideal"].as_f64().unwrap(),
            a["driving"].as_f64().unwrap(),
        );
        close(
            (d - d0) * 10.0,
            a["friction_power"].as_f64().unwrap(),
            1e-9,
            "N_f",
        );
        assert!(d > d0);
    }
}

mod friction_circles {
    //! Linkage efficiency with friction circles: a crank against a tip force (closed form
    //! η = r/(r + ρ)) and a slider-crank over a turn, where the driver's extra power must
    //! equal the friction's loss (virtual power, no joint forces) at every position.
    use armsim::machines::friction::friction_circle::{solve_with_friction, JointFriction};
    use armsim::machines::linkage::catalog;
    use armsim::machines::linkage::description::{Driver, Linkage, PlanarLink, GROUND};
    use armsim::machines::linkage::kinetostatics::{Loads, PointForce};
    use armsim::machines::linkage::position::NewtonOptions;
    use armsim::machines::linkage::sweep::{sweep, SweepOptions};
    use armsim::machines::linkage::virtual_power::driving_effort;
    use armsim::machines::linkage::Vec2;
    use nalgebra::DVector;

    #[test]
    fn crank_against_a_tip_force_has_efficiency_r_over_r_plus_rho() {
        let (r, f, pin, force) = (0.2_f64, 0.15_f64, 0.01_f64, 500.0_f64);
        let l = Linkage::with_shared_pins(
            "crank",
            vec![("A".into(), Vec2::zeros())],
            vec![PlanarLink::binary("AB", "A", "B", r)],
            Vec::new(),
            Driver::Angle {
                link: 0,
                relative_to: GROUND,
            },
        );
        let omega = 3.0;
        for th in [0.3_f64, 1.7, 4.0] {
            let q = DVector::from_vec(vec![0.0, 0.0, th]);
            let qd = DVector::from_vec(vec![0.0, 0.0, omega]);
            let qdd = DVector::zeros(3);
            // The tip force opposes the tip's motion.
            let loads = Loads {
                forces: vec![PointForce {
                    link: 0,
                    p: Vec2::new(r, 0.0),
                    force: Vec2::new(th.sin(), -th.cos()) * force,
                }],
                ..Default::default()
            };
            let fr = [JointFriction {
                joint: 0,
                coefficient: f,
                pin_radius: pin,
            }];
            let w = solve_with_friction(&l, &q, &qd, &qdd, &loads, omega, &fr, 1e-12, 50);
            assert!(w.converged);
            let rho = f * pin;
            assert!((w.ideal.driving - force * r).abs() < 1e-9);
            assert!(
                (w.real.driving - force * (r + rho)).abs() < 1e-9,
                "{}",
                w.real.driving
            );
            let eta = w.efficiency.unwrap();
            assert!((eta - r / (r + rho)).abs() < 1e-12, "η {eta}");
        }
    }

    #[test]
    fn slider_crank_friction_power_is_the_drivers_extra_power_over_a_turn() {
        let (r, rod) = (0.1, 0.35);
        let mut l = catalog::slider_crank(r, rod, 0.0);
        l.links[0] = l.links[0]
            .clone()
            .with_mass(2.0, Vec2::new(r / 2.0, 0.0), 2e-3);
        l.links[1] = l.links[1]
            .clone()
            .with_mass(3.0, Vec2::new(rod / 2.0, 0.0), 3e-2);
        l.links[2] = l.links[2].clone().with_mass(4.0, Vec2::zeros(), 0.0);
        let guess = catalog::slider_crank_guess(&l, r, rod, 0.0, 0.3, 1.0);
        let opts = SweepOptions {
            from: 0.0,
            to: std::f64::consts::TAU,
            step: 5f64.to_radians(),
            assemble_at: 0.3,
            newton: NewtonOptions::default(),
        };
        let sw = sweep(&l, &guess, &opts).unwrap();
        let fr: Vec<JointFriction> = (0..l.joints.len())
            .map(|j| JointFriction {
                joint: j,
                coefficient: 0.1,
                pin_radius: 0.015,
            })
            .collect();
        let loads = Loads {
            gravity: Vec2::new(0.0, -9.81),
            forces: vec![PointForce {
                link: 2,
                p: Vec2::zeros(),
                force: Vec2::new(-800.0, 0.0),
            }],
            ..Default::default()
        };
        let speed = 20.0;
        let (mut wd, mut wf) = (0.0, 0.0);
        for st in &sw.samples {
            let (qd, qdd) = (st.qd(speed), st.qdd(speed, 0.0));
            let w = solve_with_friction(&l, &st.q, &qd, &qdd, &loads, speed, &fr, 1e-12, 100);
            assert!(w.converged, "at {}", st.s);
            assert!(w.friction_power >= 0.0);
            // Ideal constraints do no work: the driver pays exactly the friction loss.
            let extra = (w.real.driving - w.ideal.driving) * speed;
            assert!(
                (extra - w.friction_power).abs() <= 1e-8 * w.friction_power.max(1.0),
                "at {}: {extra} vs {}",
                st.s,
                w.friction_power
            );
            // Virtual power with the friction loads as applied loads: the same driving.
            let mut all = loads.clone();
            all.forces.extend(w.friction_loads.forces.iter().cloned());
            all.torques.extend(w.friction_loads.torques.iter().copied());
            let vp = driving_effort(&l, &st.q, &qd, &qdd, &all, speed).unwrap();
            assert!((vp - w.real.driving).abs() < 1e-8 * vp.abs().max(1.0));
            if let Some(eta) = w.efficiency {
                assert!(eta < 1.0, "η {eta}");
            }
            wd += w.driving_power;
            wf += w.friction_power;
        }
        // Over the turn (uniform speed: equal time steps) the kinetic energy returns and
        // the load force does no net work: the driver's work is all friction.
        let eta_cycle = 1.0 - wf / wd;
        assert!(eta_cycle.abs() < 0.05, "cycle: W_d {wd}, W_f {wf}");
    }
}

/// First-order friction power of the centric slider-crank `r`, `L` at crank angle `phi`
/// (speed `w1`, piston load `load`), pins of radii `pins = [A, B, C]`, coefficient `f`
/// everywhere: the frictionless reactions (the rod a two-force member, `P = F/cos ψ`,
/// guide `N = F tan ψ`) times each joint's relative speed.
fn slider_crank_friction_first_order(
    (r, l, w1, load): (f64, f64, f64, f64),
    phi: f64,
    pins: [f64; 3],
    f: f64,
) -> f64 {
    let rod_angle = |p: f64| {
        let cx = r * p.cos() + (l * l - (r * p.sin()).powi(2)).sqrt();
        ((r * p.sin()).atan2(r * p.cos() - cx), cx)
    };
    let h = 1e-6;
    let (w2, vc) = {
        let ((a1, c1), (a0, c0)) = (rod_angle(phi + h), rod_angle(phi - h));
        ((a1 - a0) / (2.0 * h) * w1, (c1 - c0) / (2.0 * h) * w1)
    };
    let sin_psi = r * phi.sin() / l;
    let cos_psi = (1.0 - sin_psi * sin_psi).sqrt();
    let (p, n) = (load / cos_psi, load * sin_psi / cos_psi);
    f * (pins[0] * p * w1.abs() + pins[1] * p * (w1 - w2).abs() + pins[2] * p * w2.abs())
        + f * n * vc.abs()
}

#[test]
fn three_different_pins_take_each_its_own_friction_circle() {
    // The bundled file with f = 0.001, where the first-order power is exact to ~1e-4.
    let path = "scenarios/slider_crank_three_pins_friction.toml";
    let text = std::fs::read_to_string(common::root().join(path)).unwrap();
    let small = text.replace(
        "friction_coefficient = 0.05",
        "friction_coefficient = 0.001",
    );
    assert_ne!(small, text);
    let dir = std::env::temp_dir().join(format!("armsim_pins_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let copy = dir.join("three_pins_small_f.toml");
    std::fs::write(&copy, small).unwrap();
    let v = common::cli_json(&["run", copy.to_str().unwrap(), "--json"]);
    std::fs::remove_dir_all(&dir).unwrap();
    let at = v["kinetostatics"]["friction"]["at"].as_array().unwrap();
    assert_eq!(at.len(), 5);
    for row in at {
        let phi = row["input"].as_f64().unwrap();
        let expected = slider_crank_friction_first_order(
            (0.05, 0.2, 100.0, 1000.0),
            phi,
            [0.04, 0.025, 0.015],
            0.001,
        );
        let got = row["friction_power"].as_f64().unwrap();
        close(got, expected, 1e-3 * expected, "friction power");
    }
    // The bundled file (f = 0.05): 90° by the converged friction circles, within the
    // second-order 3 % of the first-order estimate (400.2 W).
    let v = run_json(path);
    let f = &v["kinetostatics"]["friction"];
    assert_eq!(f["pin_radii"]["B"], 0.025);
    let at90 = &f["at"][2];
    let first = slider_crank_friction_first_order(
        (0.05, 0.2, 100.0, 1000.0),
        FRAC_PI_2,
        [0.04, 0.025, 0.015],
        0.05,
    );
    close(first, 400.2, 0.1, "first order at 90°");
    close(
        at90["friction_power"].as_f64().unwrap(),
        first,
        0.03 * first,
        "converged",
    );
}

fn cb(v: &Value, i: usize, k: &str) -> f64 {
    v["connected_bodies"][i][k]
        .as_f64()
        .unwrap_or_else(|| panic!("{k}"))
}

fn tension(v: &Value, i: usize, rope: usize, end: usize) -> f64 {
    v["connected_bodies"][i]["tensions_N"][rope][end]
        .as_f64()
        .unwrap()
}

#[test]
fn block_on_an_incline_pulled_by_a_hanging_weight_by_newtons_second_law() {
    let v = run_json("scenarios/friction_connected_bodies.toml");
    let g = 9.81_f64;
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    // a) 10 kg up the 30° plane (f = 0.2), 8 kg falling: (m1 + m2) a = m2 g − m1 g (sin + f cos).
    let a = (8.0 * g - 10.0 * g * (s + 0.2 * c)) / 18.0;
    assert_eq!(v["connected_bodies"][0]["motion"], "forward");
    close(cb(&v, 0, "acceleration_mps2"), a, 1e-12, "a) a");
    close(a, 0.69103, 1e-5, "a) a by hand");
    close(
        tension(&v, 0, 0, 0),
        8.0 * (g - a),
        1e-10,
        "a) T = m2 (g − a)",
    );
    close(tension(&v, 0, 0, 1), 72.952, 1e-3, "a) T");
    // b) 6 kg, static 0.25: 6g lies between 10g(sin − 0.25 cos) and 10g(sin + 0.25 cos).
    let b = &v["connected_bodies"][1];
    assert_eq!(b["motion"], "rest");
    assert_eq!(b["acceleration_mps2"], 0.0);
    assert!(b.get("tensions_N").is_none());
    close(
        cb(&v, 1, "start_forward_N"),
        10.0 * g * (s + 0.25 * c) - 6.0 * g,
        1e-10,
        "b) start up",
    );
    close(
        cb(&v, 1, "start_forward_N"),
        11.4293,
        1e-4,
        "b) start up by hand",
    );
    close(
        cb(&v, 1, "start_backward_N"),
        6.0 * g - 10.0 * g * (s - 0.25 * c),
        1e-10,
        "b) start down",
    );
    close(
        cb(&v, 1, "uniform_forward_N"),
        10.0 * g * (s + 0.2 * c) - 6.0 * g,
        1e-10,
        "b) uniformly up",
    );
    // c) 2 kg: the block slides down: (m1 + m2) a = m2 g − m1 g (sin − f cos) < 0.
    assert_eq!(v["connected_bodies"][2]["motion"], "backward");
    let a = (2.0 * g - 10.0 * g * (s - 0.2 * c)) / 12.0;
    close(cb(&v, 2, "acceleration_mps2"), a, 1e-12, "c) a");
    close(tension(&v, 2, 0, 0), 2.0 * (g - a), 1e-10, "c) T");
    // Moving from rest, the resistance is f N on the block alone.
    close(
        v["connected_bodies"][2]["resistance_N"][0]
            .as_f64()
            .unwrap(),
        0.2 * 10.0 * g * c,
        1e-10,
        "c) R",
    );
}

#[test]
fn two_inclines_over_a_lossy_pulley_and_a_cart_between_two_weights() {
    let v = run_json("scenarios/friction_connected_bodies.toml");
    let g = 9.81_f64;
    let (s30, c30) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let (s60, c60) = (60f64.to_radians().sin(), 60f64.to_radians().cos());
    // d) 12 kg slides down 60° (f = 0.15) pulling 10 kg up 30° (f = 0.1); the pulley
    // passes η = 0.95 of the falling side's tension: T0 = 0.95 T1,
    // 12 a = 12 g (sin 60 − 0.15 cos 60) − T1, 10 a = T0 − 10 g (sin 30 + 0.1 cos 30).
    let (d1, d0) = (12.0 * g * (s60 - 0.15 * c60), 10.0 * g * (s30 + 0.1 * c30));
    let a = (0.95 * d1 - d0) / (10.0 + 0.95 * 12.0);
    close(cb(&v, 3, "acceleration_mps2"), a, 1e-12, "d) a");
    let t1 = d1 - 12.0 * a;
    close(tension(&v, 3, 0, 1), t1, 1e-10, "d) T at the falling block");
    close(
        tension(&v, 3, 0, 0),
        0.95 * t1,
        1e-10,
        "d) T at the rising block",
    );
    close(
        10.0 * a,
        tension(&v, 3, 0, 0) - d0,
        1e-10,
        "d) the rising block's equation",
    );
    // e) 5 kg rising, a 20 kg cart (w = 0.012, wheels J/R² = 1.5 kg) on the table, 10 kg
    // falling, both pulleys η = 0.98. Each body's equation with its rope ends:
    // 10 a = 10 g − T1f; 21.5 a = T1b − T0f − 0.012·20 g; 5 a = T0b − 5 g;
    // T1b = 0.98 T1f, T0b = 0.98 T0f.
    let e = 0.98_f64;
    let a = (e * e * 10.0 * g - e * 0.012 * 20.0 * g - 5.0 * g) / (5.0 + e * 21.5 + e * e * 10.0);
    close(cb(&v, 4, "acceleration_mps2"), a, 1e-12, "e) a");
    let t1f = 10.0 * (g - a);
    let t0f = e * t1f - 21.5 * a - 0.012 * 20.0 * g;
    close(
        tension(&v, 4, 1, 1),
        t1f,
        1e-10,
        "e) T1 at the falling weight",
    );
    close(tension(&v, 4, 1, 0), e * t1f, 1e-10, "e) T1 at the cart");
    close(tension(&v, 4, 0, 1), t0f, 1e-10, "e) T0 at the cart");
    close(
        tension(&v, 4, 0, 0),
        e * t0f,
        1e-10,
        "e) T0 at the rising weight",
    );
    close(
        5.0 * a,
        e * t0f - 5.0 * g,
        1e-10,
        "e) the rising weight's equation",
    );
}

#[test]
fn cart_pull_counts_the_wheels_weight_at_the_rail_only() {
    let v = run_json("scenarios/friction_rolling_cart_wheel_weight.toml");
    // P = [(Q + G_w) k + Q f r]/R with Q = 20 000, G_w = 4 × 500, k = 0.0005, f = 0.08,
    // r = 0.03, R = 0.2.
    let (q, gw, k, f, r, rr) = (20000.0, 2000.0, 0.0005, 0.08, 0.03, 0.2);
    close(
        g(&v, 0, "force_N"),
        ((q + gw) * k + q * f * r) / rr,
        1e-9,
        "P",
    );
    close(g(&v, 0, "force_N"), 295.0, 1e-9, "P by hand");
    close(g(&v, 0, "rolling_N"), 55.0, 1e-9, "rail");
    close(g(&v, 0, "journal_N"), 240.0, 1e-9, "journals");
    close(g(&v, 0, "wheels_weight_N"), 2000.0, 1e-9, "G_w");
    // Without the wheels' weight: the old Q (f d2 + 2k)/d1.
    close(
        g(&v, 1, "force_N"),
        q * (f * 0.06 + 2.0 * k) / 0.4,
        1e-9,
        "no G_w",
    );
    close(g(&v, 1, "force_N"), 290.0, 1e-9, "no G_w by hand");
}
