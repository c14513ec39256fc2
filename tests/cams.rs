//! Cams (docs/reference_data.md §M3): every published checkpoint through `armsim run --json`
//! on its bundled scenario, and independent routes — the eccentric cam's closed forms,
//! the laws' derivatives by finite differences, the pressure angle from the profile's
//! geometry, the curvature from three-point circles, the roller's working profile at
//! distance r_r from the pitch curve, the base-radius search at its limit — and the
//! broken files.

use armsim::machines::cams::laws::{Law, MotionLaw};
use armsim::machines::cams::profile::{
    min_prime_radius, pressure_angle_numeric, sample, CamFollower,
};
use serde_json::Value;
use std::f64::consts::PI;

mod common;
use common::run_json;

fn at(v: &Value, key: &str, deg: usize) -> f64 {
    v["samples"][key][deg].as_f64().unwrap()
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}

fn design_motion() -> MotionLaw {
    MotionLaw {
        stroke: 25.0,
        rise: 120f64.to_radians(),
        dwell_top: 60f64.to_radians(),
        ret: 90f64.to_radians(),
        rise_law: Law::Cycloidal,
        return_law: Law::Polynomial345,
    }
}

// ---------------------------------------------------------------------------------------
// Published checkpoints.

#[test]
fn cm1_eccentric_cam_with_knife_and_roller() {
    let v = run_json("scenarios/cam_cm1_eccentric_knife.toml");
    for (deg, s) in [
        (0, 0.0),
        (45, 1.637),
        (90, 7.321),
        (135, 15.779),
        (180, 20.0),
    ] {
        close(at(&v, "s", deg), s, 5e-4, &format!("s({deg}°)"));
    }
    for (deg, a) in [(0, 0.0), (45, 20.7), (90, 30.0), (135, 20.7), (180, 0.0)] {
        close(
            at(&v, "pressure_angle_deg", deg),
            a,
            0.05,
            &format!("α({deg}°)"),
        );
    }
    close(
        v["summary"]["max_pressure_angle"]["value_deg"]
            .as_f64()
            .unwrap(),
        30.0,
        1e-9,
        "|α|max",
    );
    close(v["summary"]["stroke"].as_f64().unwrap(), 20.0, 1e-12, "h");
    let v = run_json("scenarios/cam_cm1_eccentric_roller.toml");
    close(
        at(&v, "pressure_angle_deg", 90),
        19.0 + 28.0 / 60.0,
        0.01,
        "α(90°) = 19°28'",
    );
    close(at(&v, "s", 90), 8.284, 5e-4, "s(90°)");
    close(v["summary"]["stroke"].as_f64().unwrap(), 20.0, 1e-12, "h");
}

#[test]
fn cm2_flat_face_minimum_base_radius() {
    let v = run_json("scenarios/cam_cm2_flat_min_base_radius.toml");
    let r = v["summary"]["min_flat_base_radius"].as_f64().unwrap();
    close(r, 480.0 / (PI * PI) - 15.0, 1e-6, "Rb_min");
    close(r, 33.6, 0.05, "33.6 mm");
    let jerk: Vec<f64> = v["summary"]["infinite_jerk_at_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(jerk.contains(&45.0) && jerk.contains(&0.0), "{jerk:?}");
}

#[test]
fn cm4_uniform_rise_pressure_angle() {
    let v = run_json("scenarios/cam_cm4_uniform_rise.toml");
    close(
        v["summary"]["max_pressure_angle"]["rise"]["value_deg"]
            .as_f64()
            .unwrap(),
        46.70,
        0.005,
        "46°40'",
    );
    close(
        (50.0 / PI / 15.0).atan().to_degrees(),
        46.70,
        0.005,
        "closed form",
    );
    let acc: Vec<f64> = v["summary"]["infinite_acceleration_at_deg"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(acc.contains(&0.0) && acc.contains(&180.0), "{acc:?}");
    // The profile is an Archimedean spiral: radius grows linearly with the cam angle.
    for deg in [30, 60, 120, 150] {
        let p = &v["profile"]["pitch"][deg];
        let r = (p[0].as_f64().unwrap().powi(2) + p[1].as_f64().unwrap().powi(2)).sqrt();
        close(r, 15.0 + 50.0 * deg as f64 / 180.0, 1e-9, "spiral");
    }
}

#[test]
fn cm5_oscillating_flat_face_swing_and_pressure_angle() {
    let v = run_json("scenarios/cam_cm5_oscillating_flat.toml");
    close(
        v["summary"]["swing_deg"].as_f64().unwrap(),
        30.0,
        1e-6,
        "swing",
    );
    close(
        at(&v, "pressure_angle_deg", 90),
        14.0 + 2.0 / 60.0,
        0.005,
        "α(90°) = 14°2'",
    );
    // The position equation holds at every sample.
    for deg in (0..360).step_by(15) {
        let t = at(&v, "face_angle_deg", deg).to_radians();
        let p = (deg as f64).to_radians();
        close(
            40.0 * t.sin() + 10.0 * (p - t).sin(),
            10.0,
            1e-9,
            "position equation",
        );
    }
}

#[test]
fn problem_260_book_construction_radius() {
    let v = run_json("scenarios/cam_260_oscillating_knife.toml");
    // s is the swing (rad): 30° for this cam.
    assert_eq!(v["follower_motion"], "oscillating");
    let s_max = v["samples"]["s"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|x| x.as_f64())
        .fold(0.0, f64::max);
    close(s_max, 30f64.to_radians(), 1e-9, "swing");
    close(
        v["summary"]["book_lowest_position_radius"]
            .as_f64()
            .unwrap(),
        40.0,
        1e-9,
        "R_min = X",
    );
}

// ---------------------------------------------------------------------------------------
// Independent routes.

#[test]
fn eccentric_cam_matches_the_books_closed_forms_everywhere() {
    let v = run_json("scenarios/cam_cm1_eccentric_knife.toml");
    let r = run_json("scenarios/cam_cm1_eccentric_roller.toml");
    for deg in 0..360 {
        let p = (deg as f64).to_radians();
        let s = 10.0 * (2.0 * (1.0 - (p.sin() / 2.0).powi(2)).sqrt() - p.cos() - 1.0);
        close(at(&v, "s", deg), s, 1e-9, "knife s");
        close(
            at(&v, "pressure_angle_deg", deg).to_radians(),
            (p.sin() / 2.0).asin(),
            1e-12,
            "knife α",
        );
        let s = 10.0 * (3.0 * (1.0 - (p.sin() / 3.0).powi(2)).sqrt() - p.cos() - 2.0);
        close(at(&r, "s", deg), s, 1e-9, "roller s");
    }
}

#[test]
fn law_derivatives_match_finite_differences() {
    for law in [
        Law::Uniform,
        Law::Parabolic,
        Law::Harmonic,
        Law::Cycloidal,
        Law::Cubic,
        Law::Polynomial345,
    ] {
        let f0 = law.eval(0.0);
        let f1 = law.eval(1.0);
        close(f0[0], 0.0, 1e-12, "f(0)");
        close(f1[0], 1.0, 1e-12, "f(1)");
        let h = 1e-6;
        for u in [0.1, 0.3, 0.45, 0.62, 0.9] {
            for k in 0..3 {
                let d = (law.eval(u + h)[k] - law.eval(u - h)[k]) / (2.0 * h);
                close(
                    law.eval(u)[k + 1],
                    d,
                    1e-5 * (1.0 + d.abs()),
                    &format!("{law:?} order {} at {u}", k + 1),
                );
            }
        }
    }
    // Cycloidal and 3-4-5 start and end at rest with zero acceleration.
    for law in [Law::Cycloidal, Law::Polynomial345] {
        for u in [0.0, 1.0] {
            close(law.eval(u)[1], 0.0, 1e-12, "v");
            close(law.eval(u)[2], 0.0, 1e-9, "a");
        }
    }
}

#[test]
fn pressure_angle_formula_agrees_with_the_profile_geometry() {
    let m = design_motion();
    let f = CamFollower::Translating {
        offset: 5.0,
        roller: 8.0,
        r0: 40.0,
    };
    for k in 0..72 {
        let phi = 2.0 * PI * (k as f64 + 0.3) / 72.0;
        let s = sample(&m, &f, phi);
        close(
            s.pressure_angle.abs(),
            pressure_angle_numeric(&m, &f, phi),
            1e-7,
            &format!("α at {phi}"),
        );
    }
    let f = CamFollower::Oscillating {
        arm: 120.0,
        pivot: 150.0,
        roller: 0.0,
        r0: 60.0,
    };
    for k in 0..36 {
        let phi = 2.0 * PI * (k as f64 + 0.3) / 36.0;
        close(
            sample(&m, &f, phi).pressure_angle,
            pressure_angle_numeric(&m, &f, phi),
            1e-7,
            "oscillating α",
        );
    }
}

#[test]
fn curvature_and_working_profile_agree_with_the_point_cloud() {
    let m = design_motion();
    let rr = 8.0;
    let f = CamFollower::Translating {
        offset: 5.0,
        roller: rr,
        r0: 40.0,
    };
    let h = 1e-3;
    for k in 0..60 {
        let phi = 2.0 * PI * (k as f64 + 0.5) / 60.0;
        let [a, b, c] = [phi - h, phi, phi + h].map(|p| sample(&m, &f, p).pitch);
        // Circle through three points: R = |ab||bc||ca| / (4 area), signed by the turn.
        let d = |p: [f64; 2], q: [f64; 2]| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
        let area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        let r3 = -d(a, b) * d(b, c) * d(c, a) / (2.0 * area2);
        let s = sample(&m, &f, phi);
        // Compare curvatures (flat stretches have huge radii): O(h²) three-point error.
        let (k1, k3) = (1.0 / s.rho_pitch, 1.0 / r3);
        close(
            k1,
            k3,
            1e-7 + 1e-4 * k3.abs(),
            &format!("curvature at {phi}"),
        );
        // The working point is r_r from the pitch point, along the pitch curve's normal.
        close(d(s.working, s.pitch), rr, 1e-9, "roller offset");
        let t = [c[0] - a[0], c[1] - a[1]];
        let w = [s.working[0] - s.pitch[0], s.working[1] - s.pitch[1]];
        close(
            (t[0] * w[0] + t[1] * w[1]) / d(a, c),
            0.0,
            1e-4,
            "normal (chord of ±1e-3 rad)",
        );
    }
}

#[test]
fn minimum_base_radius_reaches_the_pressure_angle_limit() {
    let m = design_motion();
    let (ar, aret) = (30f64.to_radians(), 45f64.to_radians());
    let e = 5.0;
    let n = 7200;
    let r0 = min_prime_radius(&m, e, ar, aret, n);
    let f = CamFollower::Translating {
        offset: e,
        roller: 0.0,
        r0,
    };
    let (mut worst_rise, mut worst_ret) = (0.0_f64, 0.0_f64);
    for k in 0..n {
        let s = sample(&m, &f, 2.0 * PI * k as f64 / n as f64);
        if s.s[1] > 0.0 {
            worst_rise = worst_rise.max(s.pressure_angle.abs());
        } else if s.s[1] < 0.0 {
            worst_ret = worst_ret.max(s.pressure_angle.abs());
        }
    }
    // One limit is reached exactly (the binding one), neither is exceeded.
    assert!(
        worst_rise <= ar + 1e-9 && worst_ret <= aret + 1e-9,
        "{worst_rise} {worst_ret}"
    );
    assert!(
        (worst_rise - ar).abs() < 1e-9 || (worst_ret - aret).abs() < 1e-9,
        "{worst_rise} {worst_ret}"
    );
    let v = run_json("scenarios/cam_roller_cycloidal_design.toml");
    let opt = v["summary"]["optimum_offset"]["base_radius"]
        .as_f64()
        .unwrap();
    assert!(opt <= v["summary"]["min_base_radius"].as_f64().unwrap() + 1e-9);
}

// ---------------------------------------------------------------------------------------
// Broken files.

const BROKEN: &[(&str, usize, &str, &str)] = &[
    (
        "cam_unknown_key.toml",
        8,
        "motion.dwel_top_deg",
        "unknown field",
    ),
    ("cam_no_motion.toml", 2, "kind", "needs a [motion] table"),
    ("cam_motion_and_eccentric.toml", 9, "eccentric", "not both"),
    (
        "cam_bad_law.toml",
        7,
        "motion.law",
        "unknown law 'sinusoidal'",
    ),
    (
        "cam_bad_follower_type.toml",
        10,
        "follower.type",
        "\"mushroom\"",
    ),
    (
        "cam_roller_without_radius.toml",
        9,
        "follower.roller_radius",
        "missing",
    ),
    (
        "cam_offset_too_large.toml",
        12,
        "follower.offset",
        "less than the base radius",
    ),
    (
        "cam_overfull_turn.toml",
        7,
        "motion.dwell_top_deg",
        "390° exceeds a turn",
    ),
    (
        "cam_swing_for_translating.toml",
        4,
        "motion.stroke",
        "needs `stroke`",
    ),
    (
        "cam_bad_limit.toml",
        14,
        "limits.pressure_angle_deg",
        "between 1° and 89°",
    ),
    (
        "cam_oscillating_unreachable.toml",
        14,
        "follower.base_radius",
        "cannot reach",
    ),
    (
        "cam_eccentricity_too_large.toml",
        6,
        "eccentric.eccentricity",
        "less than the disc radius",
    ),
    ("cam_profile_and_motion.toml", 8, "profile", "give one of"),
    (
        "cam_profile_base_radius.toml",
        8,
        "follower.base_radius",
        "the profile sets it",
    ),
    (
        "cam_table_not_closed.toml",
        6,
        "motion.points",
        "does not close",
    ),
    (
        "cam_table_with_law_keys.toml",
        5,
        "motion.rise_deg",
        "does not apply to a table",
    ),
    (
        "cam_face_angle_on_roller.toml",
        12,
        "follower.face_angle_deg",
        "applies only to a translating flat face",
    ),
];

#[test]
fn broken_cam_scenarios_give_located_errors() {
    common::assert_broken_scenarios("cam_", BROKEN, common::CheckSays::Refuses);
}

/// A flat face on a base circle below the minimum: the profile's radius of curvature is the
/// signed `ρ = R_b + s + s''` (it goes negative just after the switch of the parabolic
/// rise: the face would cut a swallowtail), its least value is `R_b − R_b,min` with the
/// report's own minimum, and the sign agrees with the geometry — where ρ < 0 the contact
/// point runs backwards along the face. The report says the profile is concave and
/// undercut; on the bundled 40 mm circle it is neither.
#[test]
fn flat_face_below_the_minimum_base_radius_is_undercut() {
    let m = MotionLaw {
        stroke: 30.0,
        rise: 90f64.to_radians(),
        dwell_top: 0.0,
        ret: 90f64.to_radians(),
        rise_law: Law::Parabolic,
        return_law: Law::Parabolic,
    };
    let rb_min = 480.0 / (PI * PI) - 15.0;
    let rb = 20.0;
    let f = CamFollower::Flat {
        rb,
        face_angle: 0.0,
    };
    let mut least = f64::INFINITY;
    let (mut negative, mut positive) = (0, 0);
    for k in 0..3600 {
        let phi = 2.0 * PI * (k as f64 + 0.5) / 3600.0;
        let s = sample(&m, &f, phi);
        let [_, _, s2, _] = s.s;
        close(s.rho_pitch, rb + s.s[0] + s2, 1e-9, "ρ = Rb + s + s''");
        least = least.min(s.rho_pitch);
        // The contact point's speed along the face, by central differences in the cam
        // frame turned back to the fixed frame: its sign is the sign of ρ.
        let h = 1e-6;
        let (a, c) = (
            sample(&m, &f, phi - h).working,
            sample(&m, &f, phi + h).working,
        );
        let (sn, cs) = phi.sin_cos();
        let along = cs * (c[0] - a[0]) - sn * (c[1] - a[1]);
        if s.rho_pitch.abs() > 1e-3 {
            let same = (along > 0.0) == (s.rho_pitch > 0.0);
            if s.rho_pitch < 0.0 {
                negative += 1;
            } else {
                positive += 1;
            }
            assert!(
                same || along.abs() < 1e-9,
                "φ = {phi}: ρ {} vs {along}",
                s.rho_pitch
            );
        }
    }
    assert!(negative > 0 && positive > 0, "{negative} {positive}");
    close(
        least,
        rb - rb_min,
        0.05,
        "least ρ = Rb − Rb_min (0.1° samples)",
    );

    let dir = std::env::temp_dir().join(format!("armsim_flat_cam_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string("scenarios/cam_cm2_flat_min_base_radius.toml").unwrap();
    let file = dir.join("flat_20.toml");
    std::fs::write(&file, text.replace("base_radius = 40", "base_radius = 20")).unwrap();
    let small = common::cli_json(&["run", file.to_str().unwrap(), "--json"]);
    let bundled = run_json("scenarios/cam_cm2_flat_min_base_radius.toml");
    for (v, bad) in [(&small, true), (&bundled, false)] {
        assert_eq!(v["summary"]["concave_parts"], bad, "{}", v["summary"]);
        assert_eq!(v["summary"]["undercut"], bad, "{}", v["summary"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
