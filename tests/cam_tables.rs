//! Cams beyond the named laws: motions given by a displacement table or a velocity or
//! acceleration diagram (against the laws they sample or integrate to), and a flat face
//! inclined to the stroke (its radius of curvature against the contact curve's own
//! geometry, its least base radius against the closed form).

use armsim::machines::cams::laws::{Displacement, Law, MotionLaw};
use armsim::machines::cams::motion_table::{MotionTable, TableKind};
use armsim::machines::cams::profile::{min_flat_base_radius, sample, CamFollower};
use std::f64::consts::PI;

mod common;
use common::run_json;

fn law(h: f64, rise: f64, dwell: f64, ret: f64, l: Law) -> MotionLaw {
    MotionLaw {
        stroke: h,
        rise: rise.to_radians(),
        dwell_top: dwell.to_radians(),
        ret: ret.to_radians(),
        rise_law: l,
        return_law: l,
    }
}

fn assert_same_motion(a: &dyn Displacement, b: &dyn Displacement, tol: [f64; 3], what: &str) {
    for k in 0..3600 {
        let phi = 2.0 * PI * (k as f64 + 0.37) / 3600.0;
        let (x, y) = (a.eval(phi), b.eval(phi));
        for o in 0..3 {
            assert!(
                (x[o] - y[o]).abs() <= tol[o],
                "{what}: derivative {o} at {:.3}°: {} vs {}",
                phi.to_degrees(),
                x[o],
                y[o]
            );
        }
    }
}

fn rad(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    points.iter().map(|&(d, v)| (d.to_radians(), v)).collect()
}

#[test]
fn acceleration_diagram_of_rectangles_integrates_to_the_parabolic_law() {
    let diagram = rad(&[
        (0.0, 1.0),
        (45.0, 1.0),
        (45.0, -1.0),
        (90.0, -1.0),
        (90.0, 0.0),
        (180.0, 0.0),
        (180.0, -1.0),
        (225.0, -1.0),
        (225.0, 1.0),
        (270.0, 1.0),
        (270.0, 0.0),
        (360.0, 0.0),
    ]);
    let t = MotionTable::new(TableKind::Acceleration, &diagram)
        .unwrap()
        .scaled_to(30.0);
    let m = law(30.0, 90.0, 90.0, 90.0, Law::Parabolic);
    assert_same_motion(&t, &m, [1e-9, 1e-9, 1e-9], "parabolic");
    assert!((t.stroke() - 30.0).abs() < 1e-12);
    // The scenario: CM-2's R_b,min = 480/π² − 15.
    let v = run_json("scenarios/cam_table_acceleration_diagram.toml");
    let r = v["summary"]["min_flat_base_radius"].as_f64().unwrap();
    assert!((r - (480.0 / (PI * PI) - 15.0)).abs() < 1e-6, "{r}");
    let jerk: Vec<f64> =
        serde_json::from_value(v["summary"]["infinite_jerk_at_deg"].clone()).unwrap();
    assert_eq!(jerk, vec![0.0, 45.0, 90.0, 180.0, 225.0, 270.0]);
}

#[test]
fn a_diagram_that_starts_mid_motion_gets_the_starting_speed_that_closes_it() {
    // The cycloidal rise's s'' = (2πh/Φ²) sin(2πφ/Φ) sampled finely, shifted by 30°:
    // the diagram starts at 30° into the rise, where s' ≠ 0.
    let m = law(10.0, 120.0, 30.0, 120.0, Law::Cycloidal);
    let shift = 30f64.to_radians();
    let pts: Vec<(f64, f64)> = (0..=7200)
        .map(|k| {
            let phi = 2.0 * PI * k as f64 / 7200.0;
            (phi, m.eval(phi + shift)[2])
        })
        .collect();
    let t = MotionTable::new(TableKind::Acceleration, &pts).unwrap();
    for k in 0..360 {
        let phi = 2.0 * PI * k as f64 / 360.0;
        let (a, b) = (t.eval(phi), m.eval(phi + shift));
        assert!(
            (a[0] - b[0]).abs() < 1e-5 && (a[1] - b[1]).abs() < 1e-5,
            "{phi}: {a:?} {b:?}"
        );
    }
}

#[test]
fn velocity_diagram_of_rectangles_is_the_uniform_law() {
    let v = 1.0 / 90f64.to_radians();
    let diagram = rad(&[
        (0.0, v),
        (90.0, v),
        (90.0, 0.0),
        (200.0, 0.0),
        (200.0, -v),
        (290.0, -v),
        (290.0, 0.0),
        (360.0, 0.0),
    ]);
    let t = MotionTable::new(TableKind::Velocity, &diagram)
        .unwrap()
        .scaled_to(12.0);
    let m = law(12.0, 90.0, 110.0, 90.0, Law::Uniform);
    assert_same_motion(&t, &m, [1e-9, 1e-9, 1e-9], "uniform");
}

#[test]
fn displacement_table_spline_converges_to_the_law_at_fourth_order() {
    // A smooth periodic motion s = 5 (1 − cos φ): the spline's error falls by ~16 per halving.
    let exact = |phi: f64| [5.0 * (1.0 - phi.cos()), 5.0 * phi.sin(), 5.0 * phi.cos()];
    let err = |n: usize| {
        let pts: Vec<(f64, f64)> = (0..n)
            .map(|k| {
                let phi = 2.0 * PI * k as f64 / n as f64;
                (phi, exact(phi)[0])
            })
            .collect();
        let t = MotionTable::new(TableKind::Displacement, &pts).unwrap();
        (0..1000)
            .map(|k| {
                let phi = 2.0 * PI * (k as f64 + 0.5) / 1000.0;
                (t.eval(phi)[0] - exact(phi)[0]).abs()
            })
            .fold(0.0, f64::max)
    };
    let (e1, e2) = (err(24), err(48));
    assert!(e1 < 1e-3 && e1 / e2 > 12.0, "{e1} {e2}");
    // The bundled table samples a harmonic law every 15°: its largest pressure angles
    // are within 0.05° of the law's.
    let v = run_json("scenarios/cam_table_displacement.toml");
    let m = law(20.0, 120.0, 60.0, 120.0, Law::Harmonic);
    let f = CamFollower::Translating {
        offset: 5.0,
        roller: 8.0,
        r0: 40.0,
    };
    let best = |rising: bool| {
        (0..3600)
            .map(|k| sample(&m, &f, 2.0 * PI * k as f64 / 3600.0))
            .filter(|s| (s.s[1] > 1e-12) == rising && s.s[1].abs() > 1e-12)
            .map(|s| s.pressure_angle.abs().to_degrees())
            .fold(0.0, f64::max)
    };
    let got = &v["summary"]["max_pressure_angle"];
    for (k, rising) in [("rise", true), ("return", false)] {
        let a = got[k]["value_deg"].as_f64().unwrap();
        assert!(
            (a - best(rising)).abs() < 0.05,
            "{k}: {a} vs {}",
            best(rising)
        );
    }
}

#[test]
fn inclined_flat_face_curvature_is_rb_plus_cos_beta_s_plus_s2() {
    let m = law(30.0, 90.0, 20.0, 110.0, Law::Cycloidal);
    let beta = 15f64.to_radians();
    let rb = 30.0;
    let f = CamFollower::Flat {
        rb,
        face_angle: beta,
    };
    for k in 0..720 {
        let phi = 2.0 * PI * (k as f64 + 0.3) / 720.0;
        let s = sample(&m, &f, phi);
        assert!((s.pressure_angle - beta).abs() < 1e-15);
        // The contact point is on the face: n·q = cos β (R_b / cos β + s) in the fixed frame.
        let (sn, cs) = phi.sin_cos();
        let q = [
            cs * s.pitch[0] - sn * s.pitch[1],
            sn * s.pitch[0] + cs * s.pitch[1],
        ];
        let p = beta.sin() * q[0] + beta.cos() * q[1];
        assert!((p - (rb + beta.cos() * s.s[0])).abs() < 1e-9, "{p}");
        // ρ against the circle through three neighbouring profile points.
        let h = 2e-4;
        let (a, b, c) = (
            sample(&m, &f, phi - h).pitch,
            s.pitch,
            sample(&m, &f, phi + h).pitch,
        );
        let d = |u: [f64; 2], w: [f64; 2]| ((u[0] - w[0]).powi(2) + (u[1] - w[1]).powi(2)).sqrt();
        let area2 = ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs();
        let r = d(a, b) * d(b, c) * d(a, c) / (2.0 * area2);
        let expect = rb + beta.cos() * (s.s[0] + s.s[2]);
        assert!(
            (r - expect.abs()).abs() < 1e-3 * expect.abs().max(1.0),
            "φ {phi}: {r} vs {expect}"
        );
    }
    let perpendicular = min_flat_base_radius(&m, 0.0, 3600);
    let inclined = min_flat_base_radius(&m, beta, 3600);
    assert!((inclined - beta.cos() * perpendicular).abs() < 1e-12);
    let v = run_json("scenarios/cam_flat_inclined_face.toml");
    let r = v["summary"]["min_flat_base_radius"].as_f64().unwrap();
    assert!(
        (r - 15f64.to_radians().cos() * (480.0 / (PI * PI) - 15.0)).abs() < 1e-6,
        "{r}"
    );
    let a = v["summary"]["max_pressure_angle"]["rise"]["value_deg"]
        .as_f64()
        .unwrap();
    assert!((a - 15.0).abs() < 1e-9);
}

// ---------------------------------------------------------------------------------------
// A cam given by its profile.

use armsim::machines::cams::given_profile::{ProfileElement, ProfileFollower, ProfileMotion};

fn disc() -> Vec<ProfileElement> {
    vec![ProfileElement::Arc {
        centre: [0.0, -10.0],
        radius: 30.0,
        from: 0.0,
        to: 2.0 * PI,
    }]
}

/// The disc's centre in the fixed frame: `R(φ) (0, −10)`.
fn centre(phi: f64) -> [f64; 2] {
    [10.0 * phi.sin(), -10.0 * phi.cos()]
}

#[test]
fn disc_profile_drives_each_follower_as_its_closed_form() {
    // Translating roller on x = 5: y = c_y + √((R + r)² − (e − c_x)²).
    let y = |phi: f64| {
        let c = centre(phi);
        c[1] + (38f64.powi(2) - (5.0 - c[0]).powi(2)).sqrt()
    };
    let m = ProfileMotion::new(
        &disc(),
        ProfileFollower::Translating {
            offset: 5.0,
            roller: 8.0,
        },
    )
    .unwrap();
    let lo = (0..3600)
        .map(|k| y(2.0 * PI * k as f64 / 3600.0))
        .fold(f64::INFINITY, f64::min);
    for k in 0..360 {
        let phi = 2.0 * PI * (k as f64 + 0.25) / 360.0;
        let s = m.eval(phi);
        assert!(
            (s[0] - (y(phi) - lo)).abs() < 1e-6,
            "{phi}: {} vs {}",
            s[0],
            y(phi) - lo
        );
        let dy = (y(phi + 1e-6) - y(phi - 1e-6)) / 2e-6;
        assert!((s[1] - dy).abs() < 1e-5, "{phi}: s' {} vs {dy}", s[1]);
    }
    // Flat face inclined 10°: p = c·n + R, y = p / cos β.
    let b = 10f64.to_radians();
    let m = ProfileMotion::new(&disc(), ProfileFollower::Flat { face_angle: b }).unwrap();
    let p = |phi: f64| (centre(phi)[0] * b.sin() + centre(phi)[1] * b.cos() + 30.0) / b.cos();
    for k in 0..360 {
        let phi = 2.0 * PI * k as f64 / 360.0;
        assert!((m.eval(phi)[0] - (p(phi) - (30.0 - 10.0) / b.cos())).abs() < 1e-9);
    }
    // Oscillating roller, arm 60 about (70, 0): the roller centre is R + r from the disc's.
    let m = ProfileMotion::new(
        &disc(),
        ProfileFollower::Oscillating {
            arm: 60.0,
            pivot: 70.0,
            roller: 8.0,
        },
    )
    .unwrap();
    let psi0 = m.base();
    for k in 0..360 {
        let phi = 2.0 * PI * k as f64 / 360.0;
        let psi = psi0 + m.eval(phi)[0];
        let q = [70.0 - 60.0 * psi.cos(), 60.0 * psi.sin()];
        let c = centre(phi);
        let d = ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2)).sqrt();
        assert!((d - 38.0).abs() < 1e-9, "{phi}: {d}");
    }
}

#[test]
fn a_law_cams_pitch_curve_given_as_a_polygon_gives_back_the_law() {
    let m = law(20.0, 100.0, 40.0, 100.0, Law::Cycloidal);
    let f = CamFollower::Translating {
        offset: 6.0,
        roller: 0.0,
        r0: 35.0,
    };
    let n = 7200;
    let pts: Vec<[f64; 2]> = (0..n)
        .map(|k| sample(&m, &f, -2.0 * PI * k as f64 / n as f64).pitch)
        .collect();
    // The pitch points run clockwise in φ; the polygon's order does not matter.
    let els: Vec<ProfileElement> = (0..n)
        .map(|k| ProfileElement::Segment(pts[k], pts[(k + 1) % n]))
        .collect();
    let g = ProfileMotion::new(
        &els,
        ProfileFollower::Translating {
            offset: 6.0,
            roller: 0.0,
        },
    )
    .unwrap();
    let s0 = (35f64.powi(2) - 36.0).sqrt();
    assert!((g.base() - s0).abs() < 1e-6, "{}", g.base());
    for k in 0..360 {
        let phi = 2.0 * PI * (k as f64 + 0.5) / 360.0;
        let (a, b) = (g.eval(phi), m.eval(phi));
        assert!((a[0] - b[0]).abs() < 1e-4, "{phi}: s {} vs {}", a[0], b[0]);
    }
}

#[test]
fn tangent_cam_lifts_the_roller_by_nose_centre_plus_nose_minus_base() {
    let v = run_json("scenarios/cam_profile_tangent_cam.toml");
    assert_eq!(v["cam"], "profile");
    let stroke = v["summary"]["stroke"].as_f64().unwrap();
    assert!((stroke - 13.0).abs() < 1e-4, "{stroke}");
    // On the base arc the follower dwells; on a flank s'' jumps (the profile's curvature
    // jumps from 20 to ∞); the jumps of s'' are reported where the contact changes.
    let jumps = v["summary"]["infinite_jerk_at_deg"].as_array().unwrap();
    assert!(jumps.len() >= 4, "{jumps:?}");
    // The pitch curve the report draws lies 5 mm (the roller) from the given profile.
    let v = run_json("scenarios/cam_profile_eccentric_disc.toml");
    for p in v["profile"]["working"].as_array().unwrap() {
        let (x, y) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
        let r = (x * x + (y + 10.0).powi(2)).sqrt();
        assert!((r - 30.0).abs() < 1e-4, "working point {x}, {y}: {r}");
    }
}
