//! Writes the main job's collision stage inputs as JSON, for `tools/bench_collision.py`:
//! the collision geometries (mesh files, boxes), the obstacles, the tested body pairs of
//! the bare arm and of the arm carrying the part, and at every sample of the collision
//! stage (10 ms, the attach and detach instants included) the world pose of every
//! geometry, the part on the tool inside the carry window.
//!
//! ```sh
//! cargo run --release --example collision_poses -- scenarios/ur5_pick_and_place.toml out.json
//! ```

use armsim::collision::resolve::{resolve_with, PackagePaths};
use armsim::collision::{CollisionModel, Scope};
use armsim::core::spatial::Se3;
use armsim::kinematics::forward_kinematics;
use armsim::model::data::Data;
use armsim::model::{Model, Shape, WORLD};
use armsim::motion::Trajectory;
use armsim::scenarios::arm::planner_setup::with_part;
use armsim::scenarios::arm::{self, RunOptions};
use serde_json::{json, Value};
use std::path::Path;

fn geoms(model: &Model) -> Vec<Value> {
    let base = Path::new(&model.source).parent();
    let pkgs = PackagePaths::from_env(Vec::new());
    let mut out = Vec::new();
    for link in &model.links {
        for g in &link.collisions {
            out.push(match &g.shape {
                Shape::Mesh { uri, scale } => {
                    let p = resolve_with(uri, base, &pkgs).expect("mesh found");
                    json!({"link": link.name, "kind": "mesh", "path": p, "scale": scale})
                }
                Shape::Box { size } => json!({"link": link.name, "kind": "box", "size": size}),
                other => panic!("not in the main job: {other:?}"),
            });
        }
    }
    out
}

fn matrix(m: &Se3) -> Value {
    let r = &m.rot;
    let t = &m.trans;
    json!([
        [r[(0, 0)], r[(0, 1)], r[(0, 2)], t.x],
        [r[(1, 0)], r[(1, 1)], r[(1, 2)], t.y],
        [r[(2, 0)], r[(2, 1)], r[(2, 2)], t.z],
    ])
}

fn poses(model: &Model, data: &Data, base: &Se3) -> Vec<Value> {
    let mut out = Vec::new();
    for link in &model.links {
        let body = if link.body == WORLD {
            Se3::identity()
        } else {
            data.o_m_i[link.body]
        };
        for g in &link.collisions {
            out.push(matrix(&base.mul(&body).mul(&link.offset).mul(&g.origin)));
        }
    }
    out
}

fn pairs(cm: &CollisionModel) -> Vec<Value> {
    cm.tested_pairs(Scope::All)
        .into_iter()
        .map(|(a, b)| json!([cm.body_name(a), cm.body_name(b)]))
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (file, dest) = (&args[1], &args[2]);
    let text = std::fs::read_to_string(file).expect("scenario");
    let opts = RunOptions {
        write_files: false,
        ..Default::default()
    };
    let out = arm::run(Path::new(file), &text, &opts).unwrap_or_else(|e| panic!("{e}"));
    let (scene, plan) = (&out.scene, &out.plan);
    let copts = scene.collision.clone().expect("collisions checked");
    let model = &scene.model;
    let pm = with_part(model, scene.tool, scene.part.as_ref().expect("a part"));
    let cm = CollisionModel::from_specs(model, &scene.obstacles, &copts).unwrap();
    let cp = CollisionModel::from_specs(&pm, &scene.obstacles, &copts).unwrap();
    // The collision stage's samples (src/arm/checks.rs).
    let traj = &plan.trajectory;
    let duration = traj.duration();
    let k = ((duration / 0.01).ceil() as usize).clamp(50, 20_000);
    let mut times: Vec<f64> = (0..=k).map(|i| duration * i as f64 / k as f64).collect();
    let (a, b) = plan.carry.expect("carry window");
    times.extend([a, b]);
    times.sort_by(f64::total_cmp);
    times.dedup();
    let (mut q, mut qd, mut qdd) = (
        vec![0.0; model.nv],
        vec![0.0; model.nv],
        vec![0.0; model.nv],
    );
    let mut data = Data::new(model);
    let samples: Vec<Value> = times
        .iter()
        .map(|&t| {
            traj.sample(t, &mut q, &mut qd, &mut qdd);
            forward_kinematics(model, &mut data, &q);
            let carried = (a..=b).contains(&t);
            let m = if carried { &pm } else { model };
            json!({"t": t, "carried": carried, "poses": poses(m, &data, &scene.base)})
        })
        .collect();
    let obstacles: Vec<Value> = scene
        .obstacles
        .iter()
        .map(|o| json!({"name": o.name, "shape": o.shape, "size": o.size, "xyz": o.xyz, "rpy": o.rpy}))
        .collect();
    let disabled = &copts.disabled_pairs;
    let body = json!({
        "geoms_bare": geoms(model),
        "geoms_part": geoms(&pm),
        "obstacles": obstacles,
        "pairs_bare": pairs(&cm),
        "pairs_part": pairs(&cp),
        "disabled": disabled,
        "samples": samples,
        "armsim": {
            "collisions_s": out.report.json["timings"]["collisions_s"],
            "collisions": out.report.json["collisions"],
        },
    });
    std::fs::write(dest, serde_json::to_string(&body).unwrap()).expect("write");
    eprintln!("{} samples written to {dest}", times.len());
}
