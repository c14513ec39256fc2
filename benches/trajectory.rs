//! Trajectory figures: TOPP duration and solve time against the grid size (UR5 and the
//! planar 2R along the minimum-jerk path through four waypoints, with and without binding
//! torque limits), compared with the trapezoidal and minimum-jerk durations; the cost of
//! sampling each trajectory type and of the torque check per sample. Single-threaded.
//! Run: `cargo bench --bench trajectory`.

use armsim::dynamics::{Effects, Friction, Rotor};
use armsim::model::Model;
use armsim::motion::topp;
use armsim::motion::{
    check_torques, JointLimits, MinJerk, Quintic, ToppOptions, TorqueCheckOptions, Trajectory,
    Trapezoidal,
};
use std::time::Instant;

fn case(name: &str, m: &Model, w: &[Vec<f64>], lim: &JointLimits, effort: &[f64]) {
    let g = Effects::gravity(m.gravity);
    let trap = Trapezoidal::new(w, lim).unwrap();
    let path = MinJerk::new(w, lim).unwrap();
    println!(
        "\n{name}: trapezoidal {:.4} s, quintic {:.4} s, minimum-jerk {:.4} s",
        trap.duration(),
        Quintic::new(w, lim).unwrap().duration(),
        path.duration()
    );
    println!("| torque limits | segments | TOPP s | vs trapezoidal | solves | IPM iterations | clarabel s | wall s |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for torque in [false, true] {
        let mut l = lim.clone();
        if torque {
            l.effort = effort.to_vec();
        }
        for segments in [100, 200, 400, 800] {
            let opts = ToppOptions {
                segments,
                ..Default::default()
            };
            match topp(m, path.clone(), &l, &g, &opts) {
                Ok(tp) => {
                    let s = tp.stats();
                    println!(
                        "| {} | {segments} | {:.4} | {:.1} % | {} | {} | {:.3} | {:.3} |",
                        if torque {
                            format!("{effort:.1?}")
                        } else {
                            "none".into()
                        },
                        tp.duration(),
                        100.0 * (tp.duration() / trap.duration() - 1.0),
                        s.solves,
                        s.solver_iterations,
                        s.solve_time_s,
                        s.wall_time_s
                    );
                }
                Err(e) => println!("| {torque} | {segments} | failed: {e} |"),
            }
        }
    }
}

fn main() {
    let root = env!("CARGO_MANIFEST_DIR");
    let (ur5, _) = Model::load(format!("{root}/robots/ur5.urdf")).unwrap();
    let w = vec![
        vec![0.0, -1.57, 1.57, -1.57, -1.57, 0.0],
        vec![0.8, -1.2, 1.2, -1.0, -1.2, 0.5],
        vec![1.5, -1.8, 0.9, -1.4, -1.6, 1.2],
        vec![0.5, -1.0, 1.8, -2.0, -1.0, 0.3],
    ];
    let lim = JointLimits::from_model(&ur5, vec![3.0, 3.0, 3.0, 6.0, 6.0, 6.0]);
    let inf = f64::INFINITY;
    case("UR5", &ur5, &w, &lim, &[6.0, 40.0, 20.0, inf, inf, inf]);

    let (planar, _) = Model::load(format!("{root}/robots/planar_2r.toml")).unwrap();
    let wp = vec![
        vec![0.0, 0.0],
        vec![1.0, 0.8],
        vec![2.0, -0.5],
        vec![0.5, 0.3],
    ];
    let lp = JointLimits {
        velocity: vec![2.0, 3.0],
        acceleration: vec![5.0, 8.0],
        effort: vec![inf; 2],
        jerk: None,
    };
    case("planar 2R", &planar, &wp, &lp, &[15.0, 3.5]);

    // Sampling and checking costs.
    let path = MinJerk::new(&w, &lim).unwrap();
    let trap = Trapezoidal::new(&w, &lim).unwrap();
    let tp = topp(
        &ur5,
        path.clone(),
        &lim,
        &Effects::default(),
        &ToppOptions::default(),
    )
    .unwrap();
    let (mut q, mut qd, mut qdd) = (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
    println!("\n| UR5 | ns per sample |\n|---|---:|");
    let trajs: [(&str, &dyn Trajectory); 3] = [
        ("trapezoidal", &trap),
        ("minimum-jerk", &path),
        ("TOPP", &tp),
    ];
    for (name, traj) in trajs {
        let k = 1_000_000;
        let start = Instant::now();
        for i in 0..k {
            traj.sample(
                traj.duration() * i as f64 / k as f64,
                &mut q,
                &mut qd,
                &mut qdd,
            );
        }
        println!(
            "| {name} | {:.1} |",
            start.elapsed().as_secs_f64() * 1e9 / k as f64
        );
    }
    let eff = Effects {
        gravity: Some(ur5.gravity),
        friction: Some(Friction::from_model(&ur5)),
        rotor: Some(Rotor::from_model(&ur5, 0.9)),
        ..Default::default()
    };
    let opts = TorqueCheckOptions {
        dt: 1e-5,
        ..Default::default()
    };
    let start = Instant::now();
    let rep = check_torques(&ur5, &path, &eff, &opts).unwrap();
    let el = start.elapsed().as_secs_f64();
    println!(
        "| torque check (gravity, friction, rotor), {} samples | {:.1} |",
        rep.t.len(),
        el * 1e9 / rep.t.len() as f64
    );
}
