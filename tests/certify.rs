//! Continuous certification of timed trajectories (`collision::Certifier`): the main
//! job's certificate against a dense re-check with the exact checker, a collision strictly
//! between two samples, the curve bound against measured motion on random smooth
//! trajectories, and the exact closest approach against the brute-force minimum.

use armsim::collision::{
    half_path_bound, CertifiedMotion, CertifyOptions, CollisionData, CollisionModel,
    CollisionOptions, Obstacle, Scope, TrajectoryOptions,
};
use armsim::core::spatial::Vec3;
use armsim::model::{LoadOptions, Model};
use armsim::motion::Trajectory;
use armsim::scenarios::arm::planner_setup::with_part;
use armsim::scenarios::arm::{self, RunOptions};
use rand::{Rng, SeedableRng};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn main_job() -> arm::Outcome {
    let path = root().join("scenarios/ur5_pick_and_place.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let opts = RunOptions {
        write_files: false,
        ..Default::default()
    };
    arm::run(&path, &text, &opts).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn main_job_executed_trajectory_has_no_penetration_densely_and_the_certificate_agrees() {
    let out = main_job();
    let c = &out.report.json["collisions"];
    let cert = &c["certificate"];
    assert_eq!(c["collision_free"], true, "{c}");
    assert_eq!(cert["collision_free_between_samples"], true, "{cert}");
    assert_eq!(cert["limits"]["ok"], true, "{cert}");
    for key in ["position", "velocity", "acceleration", "torque"] {
        let w = &cert["limits"][key];
        assert!(w["margin"].as_f64().unwrap() >= 0.0, "{key}: {w}");
        assert!(w["joint"].is_string(), "{key}: {w}");
    }
    assert!(cert["limits"]["jerk"].is_null());
    // Dense re-check with the exact checker: every 10 ms sample of the certificate and
    // every 1 ms in between, the bare arm outside the carry window, the part on the tool
    // inside it; real meshes, table and crate.
    let scene = &out.scene;
    let copts = scene.collision.clone().unwrap();
    let model = &scene.model;
    let cm = CollisionModel::from_specs(model, &scene.obstacles, &copts).unwrap();
    let pm = with_part(model, scene.tool, scene.part.as_ref().unwrap());
    let cp = CollisionModel::from_specs(&pm, &scene.obstacles, &copts).unwrap();
    let (mut bare, mut part) = (CollisionData::new(model, &cm), CollisionData::new(&pm, &cp));
    let (a, b) = out.plan.carry.unwrap();
    let traj = &out.plan.trajectory;
    let dur = traj.duration();
    let (mut q, mut qd, mut qdd) = (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
    let k10 = (dur / 0.01).ceil() as usize;
    let k1 = (dur / 0.001).ceil() as usize;
    let times = (0..=k10)
        .map(|i| dur * i as f64 / k10 as f64)
        .chain((0..=k1).map(|i| dur * i as f64 / k1 as f64));
    let mut dense_min = f64::INFINITY;
    let tmin = cert["min_clearance"]["time"].as_f64().unwrap();
    for t in times {
        traj.sample(t, &mut q, &mut qd, &mut qdd);
        let carried = (a..=b).contains(&t);
        let (m, c, d) = if carried {
            (&pm, &cp, &mut part)
        } else {
            (model, &cm, &mut bare)
        };
        assert!(
            !c.in_collision(m, d, &q, Scope::All),
            "penetration at t = {t}"
        );
        if (t - tmin).abs() < 0.05 {
            let ds = c.distances(m, d, &q);
            let e = ds.environment.unwrap().distance;
            let s = ds.self_collision.map_or(f64::INFINITY, |p| p.distance);
            dense_min = dense_min.min(e.min(s));
        }
    }
    // The certified lower bound holds on the dense grid, and the exact sample minimum is
    // no smaller than the dense one (the samples are among the dense times).
    let lb = ["environment", "self"]
        .iter()
        .filter_map(|k| cert["clearance_lower_bound"][k]["lower_bound"].as_f64())
        .fold(f64::INFINITY, f64::min);
    let reported = cert["min_clearance"]["distance"].as_f64().unwrap();
    assert!(
        lb > 0.0 && lb <= dense_min + 1e-9,
        "bound {lb}, dense {dense_min}"
    );
    assert!(
        dense_min <= reported + 1e-9,
        "dense {dense_min}, reported {reported}"
    );
    assert!(
        reported - dense_min < 2e-3,
        "dense {dense_min}, reported {reported}"
    );
}

/// One revolute joint about z carrying a 0.2 m bar from 0.8 m to 1.0 m out along x.
const SWING: &str = r#"<robot name="swing">
  <link name="base"/>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.9 0 0"/><geometry><box size="0.2 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="swing" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-4" upper="4" velocity="10" effort="100"/>
  </joint>
</robot>"#;

#[test]
fn certifier_catches_a_collision_strictly_between_two_samples_that_the_sample_check_misses() {
    let model = Model::load_str(SWING, "swing.urdf", &LoadOptions::default())
        .unwrap()
        .0;
    // A 1 cm wall at θ = 90°; the bar sweeps θ = π·(3u² − 2u³) in 1 s, sampled at 5 times
    // (θ = 0, 28°, 90°±... no sample sees the bar near the wall).
    let wall = Obstacle::cuboid("wall", [0.01, 0.2, 0.2], [0.0, 0.9, 0.0]);
    let cm = CollisionModel::new(&model, vec![wall], &CollisionOptions::default()).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    let pi = std::f64::consts::PI;
    let theta = |t: f64| pi * t * t * (3.0 - 2.0 * t);
    let sample = |t: f64, q: &mut [f64], qd: &mut [f64]| {
        q[0] = theta(t);
        qd[0] = pi * 6.0 * t * (1.0 - t);
    };
    let times = [0.0, 0.3, 0.7, 1.0];
    let qs: Vec<Vec<f64>> = times.iter().map(|&t| vec![theta(t)]).collect();
    let topts = TrajectoryOptions {
        max_step: None,
        ..Default::default()
    };
    let samples_only = cm
        .check_trajectory(&model, &mut cd, &times, &qs, &topts)
        .unwrap();
    assert!(samples_only.first_collision.is_none(), "the samples see it");
    let motion = CertifiedMotion {
        times: &times,
        sample: &sample,
        accel_bound: &[6.0 * pi],
    };
    let cert = cm
        .certifier(&model, Scope::All)
        .certify(&cm, &model, &mut cd, &motion, &CertifyOptions::default())
        .unwrap();
    assert!(!cert.collision_free);
    let first = cert.first_collision.expect("found between the samples");
    assert_eq!(first.names, ("arm".to_string(), "wall".to_string()));
    // First contact: the bar's inner trailing corner (r = 0.8, s = 0.025) reaches the
    // wall's face x = 0.005: 0.8 cos θ − 0.025 sin θ = 0.005.
    let (mut lo, mut hi) = (0.0f64, pi / 2.0);
    for _ in 0..100 {
        let m = 0.5 * (lo + hi);
        if 0.8 * m.cos() - 0.025 * m.sin() > 0.005 {
            lo = m;
        } else {
            hi = m;
        }
    }
    let (mut tl, mut th) = (0.0f64, 1.0f64);
    for _ in 0..100 {
        let m = 0.5 * (tl + th);
        if theta(m) < lo {
            tl = m;
        } else {
            th = m;
        }
    }
    assert!(
        (first.time - tl).abs() < 1e-5,
        "found {}, analytic {tl}",
        first.time
    );
    assert!(first.last_free.unwrap() < first.time);
}

/// Random smooth joint motion: `q_j(t) = c_j + Σ_m a_jm sin(ω_jm t + φ_jm)`, with `|q̈_j|`
/// bounded by `Σ_m a_jm ω_jm²`.
struct Sines {
    c: Vec<f64>,
    terms: Vec<[(f64, f64, f64); 3]>,
}

impl Sines {
    fn random(rng: &mut impl Rng, n: usize) -> Sines {
        let c = (0..n).map(|_| rng.random_range(-1.5..1.5)).collect();
        let terms = (0..n)
            .map(|_| {
                [0; 3].map(|_| {
                    (
                        rng.random_range(0.0..0.6),
                        rng.random_range(0.5..6.0),
                        rng.random_range(0.0..6.3),
                    )
                })
            })
            .collect();
        Sines { c, terms }
    }

    fn eval(&self, t: f64, q: &mut [f64], qd: &mut [f64]) {
        for j in 0..q.len() {
            q[j] = self.c[j];
            qd[j] = 0.0;
            for &(a, w, p) in &self.terms[j] {
                q[j] += a * (w * t + p).sin();
                qd[j] += a * w * (w * t + p).cos();
            }
        }
    }

    fn accel_bound(&self) -> Vec<f64> {
        self.terms
            .iter()
            .map(|ts| ts.iter().map(|(a, w, _)| a * w * w).sum())
            .collect()
    }
}

#[test]
fn curve_bound_is_never_violated_on_random_smooth_trajectories() {
    // UR5 with its meshes, table and crate: every pair's point-to-point distances change,
    // over each half-interval, by no more than the certifier's bound.
    let model = Model::load(root().join("robots/ur5.urdf")).unwrap().0;
    let obstacles = vec![
        Obstacle::cuboid("table", [0.8, 1.2, 0.04], [0.45, 0.0, -0.025]),
        Obstacle::cuboid("crate", [0.12, 0.12, 0.45], [0.5, 0.0, 0.225]),
    ];
    let cm = CollisionModel::new(&model, obstacles, &CollisionOptions::default()).unwrap();
    let cert = cm.certifier(&model, Scope::All);
    let mut cd = CollisionData::new(&model, &cm);
    let mut rng = rand::rngs::SmallRng::seed_from_u64(7);
    let (mut q, mut qd) = (vec![0.0; 6], vec![0.0; 6]);
    let mut worst_ratio = 0.0f64;
    for _ in 0..20 {
        let s = Sines::random(&mut rng, 6);
        let acc = s.accel_bound();
        let h = 0.05;
        for k in 0..20 {
            let t0 = k as f64 * h;
            s.eval(t0, &mut q, &mut qd);
            let lengths: Vec<f64> = (0..6).map(|j| half_path_bound(qd[j], acc[j], h)).collect();
            cm.update(&model, &mut cd, &q);
            // Random points in each pair's bounding spheres, in world at t0.
            let pts: Vec<(usize, [Vec3; 2], [Vec3; 2])> = (0..cert.num_pairs())
                .map(|p| {
                    let sh = cert.pair_shapes(p);
                    let local = sh.map(|k| {
                        let (c, r) = cert.ball(k);
                        let d = Vec3::new(
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                        );
                        Vec3::new(c[0], c[1], c[2]) + d.normalize() * r
                    });
                    let world = [0, 1].map(|i| cd.shape_pose(sh[i]).act_point(&local[i]));
                    (p, local, world)
                })
                .collect();
            for step in 1..=5 {
                let t = t0 + h / 2.0 * step as f64 / 5.0;
                s.eval(t, &mut q, &mut qd);
                cm.update(&model, &mut cd, &q);
                for (p, local, w0) in &pts {
                    let sh = cert.pair_shapes(*p);
                    let w = [0, 1].map(|i| cd.shape_pose(sh[i]).act_point(&local[i]));
                    let change = ((w[0] - w[1]).norm() - (w0[0] - w0[1]).norm()).abs();
                    let bound = cert.motion_bound(*p, &lengths);
                    assert!(change <= bound + 1e-12, "pair {p}: {change} > {bound}");
                    if bound > 1e-6 {
                        worst_ratio = worst_ratio.max(change / bound);
                    }
                }
            }
        }
    }
    // The bound is not vacuous: some motion comes within a factor 10 of it.
    assert!(worst_ratio > 0.1, "worst ratio {worst_ratio}");
}

#[test]
fn exact_minimum_distance_equals_the_brute_force_minimum_over_the_samples() {
    // The bare arm's part of the main job (before the grasp), against the old checker's
    // exact minimum distance at every sample.
    let out = main_job();
    let scene = &out.scene;
    let model = &scene.model;
    let copts = scene.collision.clone().unwrap();
    let cm = CollisionModel::from_specs(model, &scene.obstacles, &copts).unwrap();
    let mut cd = CollisionData::new(model, &cm);
    let traj = &out.plan.trajectory;
    let (a, _) = out.plan.carry.unwrap();
    let times: Vec<f64> = (0..=300).map(|i| a * i as f64 / 300.0).collect();
    let (mut q, mut qd, mut qdd) = (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
    let qs: Vec<Vec<f64>> = times
        .iter()
        .map(|&t| {
            traj.sample(t, &mut q, &mut qd, &mut qdd);
            q.clone()
        })
        .collect();
    let brute = cm
        .check_trajectory(model, &mut cd, &times, &qs, &TrajectoryOptions::default())
        .unwrap();
    let qdd = std::cell::RefCell::new(vec![0.0; 6]);
    let sample =
        |t: f64, q: &mut [f64], qd: &mut [f64]| traj.sample(t, q, qd, &mut qdd.borrow_mut());
    let motion = CertifiedMotion {
        times: &times,
        sample: &sample,
        accel_bound: &[5.0; 6],
    };
    let cert = cm
        .certifier(model, Scope::All)
        .certify(&cm, model, &mut cd, &motion, &CertifyOptions::default())
        .unwrap();
    let (te, de) = brute.min_environment.unwrap();
    let me = cert.min_environment.unwrap();
    assert!(
        (me.pair.distance - de.distance).abs() < 1e-9,
        "{me:?} vs {de:?}"
    );
    assert_eq!((me.pair.a, me.pair.b), (de.a, de.b));
    assert_eq!(me.time, te);
    let (ts, ds) = brute.min_self.unwrap();
    let ms = cert.min_self.unwrap();
    assert!(
        (ms.pair.distance - ds.distance).abs() < 1e-9,
        "{ms:?} vs {ds:?}"
    );
    assert_eq!(ms.time, ts);
    // Far fewer exact evaluations than the brute force's pairs × samples.
    assert!(cert.evaluations.exact < 200, "{:?}", cert.evaluations);
    // The certified clearance bound lies below the sample minimum, and close to it.
    let lb = cert.clearance_environment.unwrap().distance;
    assert!(
        lb <= me.pair.distance && lb > me.pair.distance - 0.02,
        "{lb}"
    );
}
