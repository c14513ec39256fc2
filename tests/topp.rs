//! TOPP by reachability analysis (the default solver) against independent references:
//!
//! - the conic program (clarabel) on the same discretised problems: same optimum;
//! - closed forms along a straight line: the trapezoid and the triangle of the line
//!   parameter, and bang–bang under a pure-inertia torque limit;
//! - an independent dense re-check of every limit (velocity, acceleration, RNEA torque
//!   with friction written out here) on a fine time grid;
//! - jerk limits: the jerk of the timed motion, by finite differences of its sampled
//!   accelerations, within the limit, and the duration tending to the unlimited optimum
//!   as the limit grows;
//! - `limits.jerk` in scenario files: bad values and keys that do not apply are refused
//!   at their line.

mod common;

use armsim::dynamics::{rnea, Effects, Friction};
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::motion::topp;
use armsim::motion::{JointLimits, LinearPath, MinJerk, ToppMethod, ToppOptions, Trajectory};
use armsim::scenarios::arm;

fn planar() -> Model {
    common::load("robots/planar_2r.toml")
}

fn ur5() -> Model {
    common::load("robots/ur5.urdf")
}

fn ur5_path() -> (Vec<Vec<f64>>, JointLimits) {
    let m = ur5();
    let w = vec![
        vec![0.0, -1.57, 1.57, -1.57, -1.57, 0.0],
        vec![0.8, -1.2, 1.2, -1.0, -1.2, 0.5],
        vec![1.5, -1.8, 0.9, -1.4, -1.6, 1.2],
        vec![0.5, -1.0, 1.8, -2.0, -1.0, 0.3],
    ];
    let lim = JointLimits::from_model(&m, vec![3.0, 3.0, 3.0, 6.0, 6.0, 6.0]);
    (w, lim)
}

fn planar_path() -> (Vec<Vec<f64>>, JointLimits) {
    let w = vec![
        vec![0.0, 0.0],
        vec![1.0, 0.8],
        vec![2.0, -0.5],
        vec![0.5, 0.3],
    ];
    let lim = JointLimits {
        velocity: vec![2.0, 3.0],
        acceleration: vec![5.0, 8.0],
        effort: vec![f64::INFINITY; 2],
        jerk: None,
    };
    (w, lim)
}

fn opts(method: ToppMethod) -> ToppOptions {
    ToppOptions {
        segments: 200,
        method,
        ..Default::default()
    }
}

/// Largest ratios (velocity, acceleration, torque) on a uniform grid of `k` samples, the
/// torque by plain RNEA plus the friction law written out.
fn verify(
    m: &Model,
    traj: &dyn Trajectory,
    lim: &JointLimits,
    fr: Option<&Friction>,
    k: usize,
) -> [f64; 3] {
    let n = m.nv;
    let mut d = Data::new(m);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut r = [0.0f64; 3];
    for i in 0..=k {
        let t = traj.duration() * i as f64 / k as f64;
        traj.sample(t, &mut q, &mut qd, &mut qdd);
        let tau = rnea(m, &mut d, &q, &qd, &qdd).to_vec();
        for j in 0..n {
            let f = fr.map_or(0.0, |f| {
                let v = qd[j];
                let s = (-(v / f.stribeck_velocity[j]).powi(2)).exp();
                f.viscous[j] * v
                    + (f.coulomb[j] + (f.stiction[j] - f.coulomb[j]) * s) * (v / f.smoothing).tanh()
            });
            r[0] = r[0].max(qd[j].abs() / lim.velocity[j]);
            r[1] = r[1].max(qdd[j].abs() / lim.acceleration[j]);
            r[2] = r[2].max((tau[j] + f).abs() / lim.effort[j]);
        }
    }
    r
}

/// One solve each (a tolerance that accepts any excess: no refinement), so both solvers
/// see exactly the same discretised problem; and the full verified call.
#[test]
fn reachability_duration_equals_the_conic_optimum_on_the_same_problems() {
    let cases = [
        ("planar", planar(), planar_path()),
        ("UR5", ur5(), ur5_path()),
    ];
    for (name, m, (w, lim)) in cases {
        let path = MinJerk::new(&w, &lim).unwrap();
        let g = Effects::gravity(m.gravity);
        // Torque limits at 1.3 × the static torque along the path on the first joints.
        let mut tight = lim.clone();
        let free = topp(&m, path.clone(), &lim, &g, &opts(ToppMethod::Reachability)).unwrap();
        tight.effort = static_peak(&m, &free)
            .iter()
            .map(|x| 1.3 * x + 1.0)
            .collect();
        for (what, l) in [("no torque", &lim), ("torque", &tight)] {
            let single = |method| ToppOptions {
                tolerance: 1e9,
                ..opts(method)
            };
            let ra = topp(&m, path.clone(), l, &g, &single(ToppMethod::Reachability)).unwrap();
            let cone = topp(&m, path.clone(), l, &g, &single(ToppMethod::Conic)).unwrap();
            let (a, b) = (ra.duration(), cone.duration());
            println!("{name}, {what}, one solve: reachability {a:.8} s, conic {b:.8} s");
            assert_eq!(ra.stats().solves, 1);
            assert!(
                a >= b * (1.0 - 1e-7),
                "{name} {what}: below the optimum, {a} vs {b}"
            );
            assert!(a <= b * (1.0 + 1e-4), "{name} {what}: {a} vs {b}");
            let ra = topp(&m, path.clone(), l, &g, &opts(ToppMethod::Reachability)).unwrap();
            let cone = topp(&m, path.clone(), l, &g, &opts(ToppMethod::Conic)).unwrap();
            let (a, b) = (ra.duration(), cone.duration());
            println!(
                "{name}, {what}, verified: reachability {a:.6} s ({} solves, {:.2} ms), conic \
                 {b:.6} s ({} solves, {:.1} ms)",
                ra.stats().solves,
                ra.stats().wall_time_s * 1e3,
                cone.stats().solves,
                cone.stats().wall_time_s * 1e3
            );
            assert!((a - b).abs() <= 1e-4 * b, "{name} {what}: {a} vs {b}");
        }
    }
}

/// Peak of `|g(q)|` per joint along a trajectory.
fn static_peak(m: &Model, traj: &dyn Trajectory) -> Vec<f64> {
    let n = m.nv;
    let mut d = Data::new(m);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let z = vec![0.0; n];
    let mut peak = vec![0.0f64; n];
    for i in 0..=2000 {
        traj.sample(
            traj.duration() * i as f64 / 2000.0,
            &mut q,
            &mut qd,
            &mut qdd,
        );
        for (p, g) in peak.iter_mut().zip(rnea(m, &mut d, &q, &z, &z)) {
            *p = p.max(g.abs());
        }
    }
    peak
}

/// One joint moving along a straight line under velocity and acceleration limits: the
/// trapezoid `D/v + v/a` when `D ≥ v²/a`, else the triangle `2√(D/a)`.
#[test]
fn one_joint_line_takes_the_trapezoid_or_triangle_time() {
    let m = planar();
    let lim = JointLimits {
        velocity: vec![1.0, 1.0],
        acceleration: vec![2.0, 2.0],
        effort: vec![f64::INFINITY; 2],
        jerk: None,
    };
    for (dist, shape) in [(2.0, "trapezoid"), (0.3, "triangle")] {
        let path = LinearPath::new(vec![0.0, 0.4], vec![dist, 0.4]).unwrap();
        let tp = topp(&m, path, &lim, &Effects::default(), &ToppOptions::default()).unwrap();
        let (v, a) = (1.0f64, 2.0f64);
        let want = if dist >= v * v / a {
            dist / v + v / a
        } else {
            2.0 * (dist / a).sqrt()
        };
        let got = tp.duration();
        println!("{shape}: {got:.6} s, closed form {want:.6} s");
        assert!(got >= want * (1.0 - 1e-9), "{shape}: {got} below {want}");
        assert!(got <= want * (1.0 + 2e-3), "{shape}: {got} vs {want}");
        let r = verify(&m, &tp, &lim, None, 20_000);
        assert!(r[0] <= 1.0 + 1e-9 && r[1] <= 1.0 + 1e-9, "{r:?}");
    }
}

/// Pure-inertia torque limit (the planar arm without gravity turning joint 1, joint 2
/// held): bang–bang at `±τ_max`, `T = 2√(D M₁₁/τ_max)`, and the conic solver agrees.
#[test]
fn torque_bound_line_is_bang_bang_and_matches_the_conic_solver() {
    let m = planar();
    let q2 = 0.7f64;
    let dist = 1.5;
    let (l, m1, m2) = (0.5f64, 2.0, 1.0);
    let m11 = m1 * l * l / 3.0 + m2 * l * l * (4.0 / 3.0 + q2.cos());
    let tau_max = 2.0;
    let lim = JointLimits {
        velocity: vec![100.0, 100.0],
        acceleration: vec![1000.0, 1000.0],
        effort: vec![tau_max, f64::INFINITY],
        jerk: None,
    };
    let path = LinearPath::new(vec![0.0, q2], vec![dist, q2]).unwrap();
    let fx = Effects::default();
    let ra = topp(&m, path.clone(), &lim, &fx, &opts(ToppMethod::Reachability)).unwrap();
    let cone = topp(&m, path, &lim, &fx, &opts(ToppMethod::Conic)).unwrap();
    let want = 2.0 * (dist * m11 / tau_max).sqrt();
    let (a, b) = (ra.duration(), cone.duration());
    println!("torque bang-bang: reachability {a:.6}, conic {b:.6}, closed form {want:.6}");
    assert!(
        a >= want * (1.0 - 1e-9) && a <= want * (1.0 + 5e-3),
        "{a} vs {want}"
    );
    assert!((a - b).abs() <= 1e-5 * b, "{a} vs {b}");
    let mut zero_g = m.clone();
    zero_g.gravity = armsim::core::spatial::Vec3::zeros();
    let r = verify(&zero_g, &ra, &lim, None, 20_000);
    assert!(r[2] <= 1.0 + 1e-9 && r[2] > 0.999, "{r:?}");
}

/// UR5 with gravity, friction and binding torque limits on the shoulder and elbow: every
/// limit holds on a 40 000-sample time grid, re-checked outside armsim's TOPP.
#[test]
fn reachability_motion_exceeds_no_limit_on_an_independent_dense_check() {
    let m = ur5();
    let (w, lim) = ur5_path();
    let path = MinJerk::new(&w, &lim).unwrap();
    let fr = Friction {
        viscous: vec![2.0, 2.0, 1.5, 0.5, 0.5, 0.5],
        coulomb: vec![3.0, 3.0, 2.0, 1.0, 1.0, 1.0],
        stiction: vec![3.0, 3.0, 2.0, 1.0, 1.0, 1.0],
        stribeck_velocity: vec![0.1; 6],
        smoothing: 1e-3,
    };
    let fx = Effects {
        gravity: Some(m.gravity),
        friction: Some(fr.clone()),
        ..Default::default()
    };
    let free = topp(&m, path.clone(), &lim, &fx, &opts(ToppMethod::Reachability)).unwrap();
    let (peak, stat) = (torque_peaks(&m, &free, &fr), static_peak(&m, &free));
    let mut tight = lim.clone();
    // On joints 2 and 3 (shoulder, elbow): half-way between what moving slowly needs at
    // worst (static torque plus Coulomb friction, which does not vanish with the speed)
    // and the peak of the free optimum.
    for j in [1, 2] {
        let slow = stat[j] + fr.coulomb[j];
        assert!(peak[j] > slow, "joint {j}: {} vs {slow}", peak[j]);
        tight.effort[j] = slow + 0.5 * (peak[j] - slow);
    }
    let tp = topp(&m, path, &tight, &fx, &opts(ToppMethod::Reachability)).unwrap();
    let r = verify(&m, &tp, &tight, Some(&fr), 40_000);
    println!(
        "UR5 friction + torque: free {:.4} s, limited {:.4} s, ratios {r:.7?}, {:?}",
        free.duration(),
        tp.duration(),
        tp.stats()
    );
    assert!(r.iter().all(|x| *x <= 1.0 + 1e-6), "{r:?}");
    assert!(r[2] > 0.99, "torque limit not active: {r:?}");
    assert!(tp.duration() > free.duration());
}

/// Peak `|τ_j|` (RNEA plus the friction law written out) per joint.
fn torque_peaks(m: &Model, traj: &dyn Trajectory, f: &Friction) -> Vec<f64> {
    let n = m.nv;
    let mut d = Data::new(m);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut peak = vec![0.0f64; n];
    for i in 0..=4000 {
        traj.sample(
            traj.duration() * i as f64 / 4000.0,
            &mut q,
            &mut qd,
            &mut qdd,
        );
        let tau = rnea(m, &mut d, &q, &qd, &qdd).to_vec();
        for j in 0..n {
            let v = qd[j];
            let s = (-(v / f.stribeck_velocity[j]).powi(2)).exp();
            let fr = f.viscous[j] * v
                + (f.coulomb[j] + (f.stiction[j] - f.coulomb[j]) * s) * (v / f.smoothing).tanh();
            peak[j] = peak[j].max((tau[j] + fr).abs());
        }
    }
    peak
}

/// Largest `|q⃛_j| / J_j`, the jerk by central differences of the sampled accelerations
/// (step `h`), on `k` samples.
fn jerk_ratio(traj: &dyn Trajectory, jerk: &[f64], k: usize, h: f64) -> f64 {
    let n = jerk.len();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    let (mut a0, mut a1) = (vec![0.0; n], vec![0.0; n]);
    let mut worst = 0.0f64;
    let d = traj.duration();
    for i in 0..=k {
        let t = (d * i as f64 / k as f64).clamp(h, d - h);
        traj.sample(t - h, &mut q, &mut qd, &mut a0);
        traj.sample(t + h, &mut q, &mut qd, &mut a1);
        for j in 0..n {
            worst = worst.max(((a1[j] - a0[j]) / (2.0 * h)).abs() / jerk[j]);
        }
    }
    worst
}

/// Jerk limits on the UR5 path: the timed motion's jerk (finite differences, outside
/// armsim) stays within the limit, every other limit still holds, and the duration
/// decreases toward the unlimited optimum as the limit grows.
#[test]
fn jerk_limited_motion_stays_within_the_limit_and_tends_to_the_optimum() {
    let m = ur5();
    let (w, lim) = ur5_path();
    let path = MinJerk::new(&w, &lim).unwrap();
    let fx = Effects::gravity(m.gravity);
    let o = opts(ToppMethod::Reachability);
    let free = topp(&m, path.clone(), &lim, &fx, &o).unwrap();
    let t_opt = free.duration();
    let mut last = f64::INFINITY;
    let mut gaps = Vec::new();
    for jmax in [10.0, 100.0, 1000.0, 10_000.0] {
        let mut jl = lim.clone();
        jl.jerk = Some(vec![jmax; 6]);
        let tp = topp(&m, path.clone(), &jl, &fx, &o).unwrap();
        let st = tp.stats();
        let fd = jerk_ratio(&tp, &[jmax; 6], 20_000, 1e-5 * tp.duration());
        let r = verify(&m, &tp, &lim, None, 20_000);
        println!(
            "jerk {jmax}: {:.4} s (optimum {t_opt:.4} s), window {:.4} s, slow-down {:.4}, \
             jerk ratio {:.6} (finite differences {fd:.6}), ratios {r:.6?}",
            tp.duration(),
            st.jerk_window_s,
            st.jerk_slowdown,
            st.max_jerk_ratio
        );
        assert!(st.max_jerk_ratio <= 1.0 + 1e-9, "{}", st.max_jerk_ratio);
        let active = st
            .max_jerk_ratio
            .max(st.max_velocity_ratio)
            .max(st.max_acceleration_ratio);
        assert!(active > 0.99, "no limit active: {st:?}");
        assert!(fd <= 1.0 + 1e-3, "jerk {jmax}: {fd}");
        assert!(r[0] <= 1.0 + 1e-6 && r[1] <= 1.0 + 1e-6, "{r:?}");
        assert!(tp.duration() >= t_opt && tp.duration() < last * (1.0 + 1e-3));
        last = tp.duration();
        gaps.push(tp.duration() / t_opt - 1.0);
    }
    assert!(gaps[3] < 0.02 && gaps[3] < 0.5 * gaps[1], "{gaps:?}");
}

/// The pick-and-place with its `[limits]` section carrying `extra`.
fn with_limits(extra: &str) -> String {
    let text =
        std::fs::read_to_string(common::root().join("scenarios/ur5_pick_and_place.toml")).unwrap();
    text.replace("[limits]\n", &format!("[limits]\n{extra}\n"))
}

fn refused(text: &str) -> String {
    let path = common::root().join("scenarios/ur5_pick_and_place.toml");
    arm::load(&path, text).err().expect("refused").to_string()
}

#[test]
fn bad_jerk_limits_are_refused_at_their_line() {
    for (extra, what) in [
        ("jerk = -5.0", "must be finite and > 0"),
        ("jerk = 0.0", "must be finite and > 0"),
        ("jerk = inf", "not finite"),
        ("jerk = nan", "not finite"),
        ("jerk = [50.0, 50.0]", "2 values for 6 joints"),
        ("jerk = { nonexistent_joint = 5.0 }", "nonexistent_joint"),
        ("jerk = \"fast\"", "limits.jerk"),
    ] {
        let text = with_limits(extra);
        let e = refused(&text);
        let line = text.lines().position(|l| l == extra).unwrap() + 1;
        println!("{extra}: {e}");
        assert!(e.contains(what), "{extra}: {e}");
        assert!(e.contains("limits.jerk"), "{extra}: {e}");
        assert!(e.contains(&format!(":{line}:")), "{extra}: {e}");
    }
    // Accepted forms: one value, a list, a table naming some joints.
    for extra in [
        "jerk = 50.0",
        "jerk = [50.0, 50.0, 50.0, 80.0, 80.0, 80.0]",
        "jerk = { shoulder_pan_joint = 40.0 }",
    ] {
        let path = common::root().join("scenarios/ur5_pick_and_place.toml");
        let scene = arm::load(&path, &with_limits(extra)).unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.limits.jerk.is_some(), "{extra}");
    }
}

#[test]
fn jerk_limit_where_nothing_is_time_optimal_is_refused_at_its_line() {
    // The pick-and-place without its planner: quintic timing only, no TOPP anywhere.
    let text =
        with_limits("jerk = 50.0").replace("planner = \"rrt-connect\"", "planner = \"none\"");
    let text = drop_section(&text, "[planner]");
    let e = refused(&text);
    let line = text.lines().position(|l| l == "jerk = 50.0").unwrap() + 1;
    assert!(e.contains("applies only to time-optimal"), "{e}");
    assert!(e.contains(&format!(":{line}:")), "{e}");
}

/// `text` without the table `header` (up to the next table).
fn drop_section(text: &str, header: &str) -> String {
    let mut out = String::new();
    let mut skip = false;
    for l in text.lines() {
        if l.starts_with('[') {
            skip = l.trim() == header;
        }
        if !skip {
            out.push_str(l);
            out.push('\n');
        }
    }
    out
}
