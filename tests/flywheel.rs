//! Flywheel sizing (`kind = "flywheel"`): the problem book's checkpoints (docs/reference_data.md
//! §M6) through `armsim run --json`, against closed forms (a sine turning moment, the linear
//! motor's integral), the older [`flywheel::size`] on the same samples, and RK4 time
//! runs; located errors for broken files.

use armsim::machines::flywheel;
use armsim::machines::flywheel::design::{self as fd, Torque};
use armsim::machines::flywheel::machine_motion::Characteristic;
use serde_json::Value;
use std::f64::consts::PI;

mod common;
use common::run_json;

fn close(a: &Value, b: f64, tol: f64, what: &str) {
    let a = a
        .as_f64()
        .unwrap_or_else(|| panic!("{what}: not a number: {a}"));
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

#[test]
fn flywheel_139_needs_6_kg_m2_and_0_06_on_the_motor_shaft() {
    let v = run_json("scenarios/flywheel_139.toml");
    let c = &v["cycle"];
    close(&c["energy_fluctuation"], 50.0 * PI, 1e-9, "ΔE = 50π");
    close(&c["flywheel_inertia"], 6.0, 5e-3, "J_fw (book 6)");
    close(
        &c["flywheel_inertia"],
        50.0 * PI / (625.0 * 0.04) - 0.28,
        1e-9,
        "J_fw closed form",
    );
    close(&c["transferred"]["inertia"], 0.06, 5e-5, "J' (book 0.06)");
    close(&c["max_energy_at_deg"], 45.0, 1e-9, "E max where M_c = M_d");
    close(&c["min_energy_at_deg"], 135.0, 1e-9, "E min");
    // The rim: 4 J/D², not the book's 100 kg (which divides by D).
    let j = c["flywheel_inertia"].as_f64().unwrap();
    close(&c["rim"]["mass"], 4.0 * j / 0.0576, 1e-9, "rim mass");
    assert!((c["rim"]["mass"].as_f64().unwrap() - 416.7).abs() < 0.5);
    // RK4 in time with J_total holds the band it was sized for.
    let tc = &c["time_check"];
    close(&tc["speed_band"][0], 24.5, 1e-4, "ω min by RK4");
    close(&tc["speed_band"][1], 25.5, 1e-4, "ω max by RK4");
    close(&tc["speed_fluctuation"], 0.04, 1e-5, "δ by RK4");
}

#[test]
fn flywheel_156_four_times_the_speed_divides_the_fluctuation_by_16() {
    let base = run_json("scenarios/flywheel_156_speed_base.toml");
    let fast = run_json("scenarios/flywheel_156_speed_fast.toml");
    // δ = 0.02 at ω and δ = 1/800 at 4ω need the same flywheel: J = ΔE/(ω² δ) = 4π.
    close(&base["cycle"]["flywheel_inertia"], 4.0 * PI, 1e-9, "J at ω");
    close(
        &fast["cycle"]["flywheel_inertia"],
        4.0 * PI,
        1e-9,
        "J at 4ω",
    );
    // The time-domain run of that J at 4ω holds δ = 1/800 (book).
    close(
        &fast["cycle"]["time_check"]["speed_fluctuation"],
        1.0 / 800.0,
        2e-6,
        "δ by RK4",
    );
}

#[test]
fn flywheel_158_stroke_integral_closed_form_and_time_run() {
    let v = run_json("scenarios/flywheel_158.toml");
    let s = &v["stroke"];
    close(&s["integral"], 1.6485, 5e-5, "∫ ω dω/(M_d − M_c)");
    close(
        &s["integral"],
        s["integral_closed_form"].as_f64().unwrap(),
        1e-10,
        "Gauss–Legendre vs closed form",
    );
    close(&s["required_inertia"], 1.906, 5e-4, "J (book 1.91)");
    close(
        &s["time_check_speed"],
        101.5,
        1e-4,
        "speed after the stroke by RK4",
    );
}

#[test]
fn flywheel_159_overload_limit_is_half_over_pi() {
    let v = run_json("scenarios/flywheel_159.toml");
    close(
        &v["overload"]["required_inertia"],
        1.0 / PI,
        1e-4,
        "J_total",
    );
    close(
        &v["overload"]["flywheel_inertia"],
        0.5 / PI,
        1e-4,
        "J_fw (book 0.5/π)",
    );
}

#[test]
fn sine_turning_moment_matches_the_closed_form_and_the_older_sizer() {
    // M_d = M0 + A sin 2φ against M0: E(φ) = A (1 − cos 2φ)/2, ΔE = A exactly.
    let (m0, a) = (50.0, 30.0);
    let table: Vec<(f64, f64)> = (0..=3600)
        .map(|k| {
            let phi = 2.0 * PI * k as f64 / 3600.0;
            (phi, m0 + a * (2.0 * phi).sin())
        })
        .collect();
    let s = fd::size_cycle(
        &Torque::Table(table.clone()),
        &Torque::Constant(m0),
        2.0 * PI,
        3600,
        (100.0, 0.02),
        0.0,
    );
    assert!(
        (s.energy_fluctuation - a).abs() < 1e-5 * a,
        "{}",
        s.energy_fluctuation
    );
    // E is largest at 90° (and 270°), zero (smallest) at 0°, 180° and 360°.
    assert!(
        (s.max_energy_at_deg % 180.0 - 90.0).abs() < 0.1,
        "{}",
        s.max_energy_at_deg
    );
    assert!(
        (s.min_energy_at_deg + 1.0) % 180.0 < 2.0,
        "{}",
        s.min_energy_at_deg
    );
    // The older sizer (drive samples, the cycle mean as load) agrees on the same samples.
    let phi: Vec<f64> = table.iter().map(|p| p.0).collect();
    let md: Vec<f64> = table.iter().map(|p| p.1).collect();
    let old = flywheel::size(&phi, &md, None, 100.0, 0.02);
    assert!((old.energy_fluctuation - s.energy_fluctuation).abs() < 1e-9);
    assert!((old.inertia - s.required_inertia).abs() < 1e-12);
}

#[test]
fn work_stroke_time_run_agrees_for_a_nonlinear_motor() {
    // A quadratic motor: no closed form; the RK4 run over the stroke angle with the
    // sized J ends on the band's lower speed when the load wins, on the upper one when
    // the motor does.
    let drive = Characteristic(vec![900.0, 4.0, -0.08]);
    let s = fd::size_stroke(&drive, 900.0, fd::StrokeSpan::Angle(2.0), [60.0, 62.0], 0.1).unwrap();
    assert!(s.integral_closed_form.is_none());
    assert!(
        (s.time_check_speed - 60.0).abs() < 1e-6,
        "{}",
        s.time_check_speed
    );
    assert!((s.flywheel_inertia - (s.required_inertia - 0.1)).abs() < 1e-15);
    // ∫ ω dω / (ω (4 − 0.08 ω)) from 62 to 60 in closed form.
    let prim = |w: f64| -(4.0 - 0.08 * w).abs().ln() / 0.08;
    assert!((s.integral - (prim(60.0) - prim(62.0))).abs() < 1e-12);
    let up = fd::size_stroke(&drive, 700.0, fd::StrokeSpan::Angle(2.0), [60.0, 62.0], 0.0).unwrap();
    assert!(
        (up.time_check_speed - 62.0).abs() < 1e-6,
        "{}",
        up.time_check_speed
    );
}

/// A stroke given by its duration: `J = T / ∫ dω/(M_d − M_c)`. For a linear motor
/// `M_d − M_c = 2375 − 22.7 ω − 1800` (the load wins: the speed falls 38 → 36) the integral is `ln|…|` in closed form; the RK4 run of
/// `J ω̇ = M_d − M_c` for `T` ends on the band's lower speed; and sizing the same stroke by
/// the angle that run swept gives the same `J` (the angle route, another integral).
#[test]
fn work_stroke_given_by_its_duration_matches_its_angle() {
    let drive = Characteristic(vec![2375.0, -22.7]);
    let (load, t) = (1800.0, 0.05);
    let s = fd::size_stroke(&drive, load, fd::StrokeSpan::Duration(t), [36.0, 38.0], 0.0).unwrap();
    let net = |w: f64| 2375.0 - 22.7 * w - load;
    let closed = (net(38.0).abs().ln() - net(36.0).abs().ln()) / 22.7;
    assert!(
        (s.integral - closed).abs() < 1e-12,
        "{} vs {closed}",
        s.integral
    );
    assert!((s.integral_closed_form.unwrap() - closed).abs() < 1e-12);
    assert!((s.required_inertia - t / closed).abs() < 1e-9);
    assert!(
        (s.time_check_speed - 36.0).abs() < 1e-6,
        "{}",
        s.time_check_speed
    );
    assert!((s.time_check_duration - t).abs() < 1e-12);
    let by_angle = fd::size_stroke(
        &drive,
        load,
        fd::StrokeSpan::Angle(s.time_check_angle),
        [36.0, 38.0],
        0.0,
    )
    .unwrap();
    let rel = (by_angle.required_inertia - s.required_inertia).abs() / s.required_inertia;
    assert!(
        rel < 1e-9,
        "{} vs {}",
        by_angle.required_inertia,
        s.required_inertia
    );
    assert!((by_angle.time_check_duration - t).abs() < 1e-7);
}

const BROKEN: &[(&str, usize, &str, &str)] = &[
    ("flywheel_nothing.toml", 1, "file", "nothing to size"),
    (
        "flywheel_constant_without_load.toml",
        3,
        "cycle",
        "no fluctuation",
    ),
    ("flywheel_not_steady.toml", 3, "cycle", "no steady state"),
    (
        "flywheel_angle_outside_period.toml",
        6,
        "cycle.load_deg[2]",
        "outside the period",
    ),
    (
        "flywheel_decreasing_angles.toml",
        6,
        "cycle.load_deg[2]",
        "must not decrease",
    ),
    (
        "flywheel_missing_fluctuation.toml",
        3,
        "cycle",
        "speed_fluctuation",
    ),
    (
        "flywheel_band_reversed.toml",
        7,
        "cycle.speed_band",
        "lowest < highest",
    ),
    (
        "flywheel_negative_fluctuation.toml",
        8,
        "cycle.speed_fluctuation",
        "strictly between",
    ),
    (
        "flywheel_equilibrium_in_band.toml",
        7,
        "stroke.speed_band",
        "cannot cross",
    ),
    (
        "flywheel_empty_motor.toml",
        4,
        "stroke.drive",
        "coefficients",
    ),
    (
        "flywheel_zero_deceleration.toml",
        6,
        "overload.max_deceleration",
        "must be positive",
    ),
    (
        "flywheel_unknown_key.toml",
        7,
        "overload.inertia",
        "unknown field",
    ),
    ("flywheel_drive_twice.toml", 4, "cycle.drive", "not both"),
    (
        "flywheel_density_without_rim.toml",
        8,
        "cycle.density",
        "applies to the rim only",
    ),
    (
        "flywheel_stroke_angle_and_duration.toml",
        7,
        "stroke.duration",
        "not both",
    ),
];

#[test]
fn broken_flywheel_scenarios_give_located_errors() {
    common::assert_broken_scenarios("flywheel_", BROKEN, common::CheckSays::SameKey);
}
