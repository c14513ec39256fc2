//! Criterion benchmarks: collision checking of a UR5 whose mesh collision geometry is
//! replaced by primitives (capsules, spheres, cylinders: 9 shapes) against 4 obstacles
//! (table, wall, ball, post), cycling over 256 random configurations inside the limits.
//! Per configuration: placing the shapes (FK included), the first-collision test and the
//! two minimum distances (environment and self), on the random configurations (most in
//! collision: early exits, penetration depths) and on the 256 samples of a free
//! trajectory passing close to the base (every pair tested); and the whole trajectory
//! check (collisions and distances at every sample).
//! Run: `cargo bench --bench collision`.

use armsim::collision::{
    CollisionData, CollisionModel, CollisionOptions, Obstacle, Scope, TrajectoryOptions,
};
use armsim::core::spatial::Se3;
use armsim::model::{Geometry, Model, Shape};
use armsim::studies::bench::{random_states, STATES};
use criterion::{criterion_group, criterion_main, Criterion};
use std::f64::consts::FRAC_PI_2;
use std::hint::black_box;

/// UR5 with primitive collision geometry in its link frames (see robots/ur5.urdf).
fn ur5_primitives() -> Model {
    let path = format!("{}/robots/ur5.urdf", env!("CARGO_MANIFEST_DIR"));
    let mut spec = Model::read_spec(std::path::Path::new(&path)).unwrap();
    let geom = |xyz: [f64; 3], rpy: [f64; 3], shape: Shape| Geometry {
        origin: Se3::from_xyz_rpy(xyz, rpy),
        shape,
        rgba: None,
    };
    let capsule = |radius, length| Shape::Capsule { radius, length };
    for l in &mut spec.links {
        l.collisions = match l.name.as_str() {
            "base_link_inertia" => vec![geom(
                [0.0, 0.0, 0.043],
                [0.0; 3],
                Shape::Cylinder {
                    radius: 0.075,
                    length: 0.086,
                },
            )],
            "shoulder_link" => vec![geom([0.0; 3], [0.0; 3], capsule(0.06, 0.04))],
            "upper_arm_link" => vec![geom(
                [-0.2125, 0.0, 0.13585],
                [0.0, FRAC_PI_2, 0.0],
                capsule(0.06, 0.425),
            )],
            "forearm_link" => vec![geom(
                [-0.196125, 0.0, 0.0165],
                [0.0, FRAC_PI_2, 0.0],
                capsule(0.05, 0.39225),
            )],
            "wrist_1_link" | "wrist_2_link" => {
                vec![geom([0.0; 3], [0.0; 3], Shape::Sphere { radius: 0.045 })]
            }
            "wrist_3_link" => vec![geom(
                [0.0, 0.0, -0.02],
                [0.0; 3],
                Shape::Cylinder {
                    radius: 0.0375,
                    length: 0.04,
                },
            )],
            "tool0" => vec![geom(
                [0.0, 0.0, 0.05],
                [0.0; 3],
                Shape::Sphere { radius: 0.04 },
            )],
            _ => vec![],
        };
    }
    Model::build(spec).unwrap().0
}

fn obstacles() -> Vec<Obstacle> {
    vec![
        Obstacle::cuboid("table", [1.5, 1.5, 0.05], [0.0, 0.0, -0.025]),
        Obstacle::cuboid("wall", [0.05, 1.0, 1.0], [0.75, 0.0, 0.5]),
        Obstacle::sphere("ball", 0.1, [0.4, 0.3, 0.5]),
        Obstacle::new(
            "post",
            Shape::Cylinder {
                radius: 0.05,
                length: 1.0,
            },
            Se3::from_xyz_rpy([-0.4, -0.4, 0.5], [0.0; 3]),
        ),
    ]
}

/// A smooth free trajectory: 256 samples of a small sinusoidal motion around a pose
/// clear of everything (checks every sample, no collision, distances recorded).
fn free_trajectory(nv: usize) -> (Vec<f64>, Vec<Vec<f64>>) {
    let times: Vec<f64> = (0..STATES).map(|i| i as f64 * 0.01).collect();
    let traj: Vec<Vec<f64>> = times
        .iter()
        .map(|t| {
            let base = [1.57, -1.2, 1.0, -1.4, -1.57, 0.0];
            (0..nv)
                .map(|j| base[j] + 0.3 * (t + j as f64).sin())
                .collect()
        })
        .collect();
    (times, traj)
}

/// Checks that the trajectory is free and prints its minimum distances.
fn report_free_trajectory(
    model: &Model,
    cm: &CollisionModel,
    cd: &mut CollisionData,
    times: &[f64],
    traj: &[Vec<f64>],
) {
    let r = cm
        .check_trajectory(model, cd, times, traj, &TrajectoryOptions::default())
        .unwrap();
    if let Some(c) = &r.first_collision {
        panic!(
            "the benchmark trajectory must be free: {:?} at t = {} (q = {:?})",
            c.names, c.time, c.q
        );
    }
    eprintln!(
        "trajectory: min environment distance {:.4} m, min self distance {:.4} m",
        r.min_environment.map_or(f64::NAN, |m| m.1.distance),
        r.min_self.map_or(f64::NAN, |m| m.1.distance)
    );
}

fn collision_benches(c: &mut Criterion) {
    let model = ur5_primitives();
    let opts = CollisionOptions {
        // The base stands on the table.
        disabled_pairs: vec![["base_link_inertia".into(), "table".into()]],
        ..Default::default()
    };
    let cm = CollisionModel::new(&model, obstacles(), &opts).unwrap();
    let mut cd = CollisionData::new(&model, &cm);
    let nv = model.nv;
    let qs = random_states(&model, 0xc011);
    let hits = (0..STATES)
        .filter(|&i| cm.in_collision(&model, &mut cd, &qs[i * nv..(i + 1) * nv], Scope::All))
        .count();
    eprintln!(
        "ur5_primitives: {} shapes, {} self + environment pairs, {hits}/{STATES} random configurations in collision",
        cm.num_shapes(),
        cm.tested_pairs(Scope::All).len(),
    );
    let mut g = c.benchmark_group("ur5_primitives");
    let mut k = 0usize;
    let mut next = move || {
        k = (k + 1) % STATES;
        k
    };
    g.bench_function("update", |b| {
        b.iter(|| {
            let i = next();
            cm.update(&model, &mut cd, black_box(&qs[i * nv..(i + 1) * nv]));
        })
    });
    g.bench_function("update+first_collision", |b| {
        b.iter(|| {
            let i = next();
            cm.update(&model, &mut cd, black_box(&qs[i * nv..(i + 1) * nv]));
            black_box(cm.first_collision(&cd, Scope::All))
        })
    });
    g.bench_function("update+min_distances", |b| {
        b.iter(|| {
            let i = next();
            cm.update(&model, &mut cd, black_box(&qs[i * nv..(i + 1) * nv]));
            black_box(cm.min_distance(&mut cd, Scope::Environment));
            black_box(cm.min_distance(&mut cd, Scope::SelfCollision))
        })
    });
    let (times, traj) = free_trajectory(nv);
    report_free_trajectory(&model, &cm, &mut cd, &times, &traj);
    // The same free configurations one at a time: no early exit, every pair tested.
    let mut k2 = 0usize;
    g.bench_function("free_update+first_collision", |b| {
        b.iter(|| {
            k2 = (k2 + 1) % STATES;
            cm.update(&model, &mut cd, black_box(&traj[k2]));
            black_box(cm.first_collision(&cd, Scope::All))
        })
    });
    let mut k3 = 0usize;
    g.bench_function("free_update+min_distances", |b| {
        b.iter(|| {
            k3 = (k3 + 1) % STATES;
            cm.update(&model, &mut cd, black_box(&traj[k3]));
            black_box(cm.min_distance(&mut cd, Scope::Environment));
            black_box(cm.min_distance(&mut cd, Scope::SelfCollision))
        })
    });
    g.bench_function("trajectory_256_samples", |b| {
        b.iter(|| {
            cm.check_trajectory(
                &model,
                &mut cd,
                black_box(&times),
                &traj,
                &TrajectoryOptions::default(),
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, collision_benches);
criterion_main!(benches);
