//! Writes a sample MCAP recording, for checking armsim's files with other tools
//! (`tools/check_mcap.py`, Foxglove, `rerun`); see `docs/recording.md`.
//!
//! ```text
//! cargo run --release --example write_sample_mcap -- OUT.mcap [MODEL] [SECONDS]
//! ```
//!
//! MODEL defaults to the crate's `robots/ur5.urdf` (a DH table works too: its URDF is generated);
//! SECONDS (default 2) of a sine motion at 100 Hz with gravity torques, a workspace cloud
//! with manipulability, a torque check and two collision events.

use armsim::dynamics::gravity_torque;
use armsim::io::record::mcap_out::McapWriter;
use armsim::io::record::{CollisionEvent, Header, PointCloud, TorqueRow};
use armsim::kinematics::{
    compute_joint_jacobians, frame_jacobian, frame_placement, manipulability, Expressed,
};
use armsim::model::data::Data;
use armsim::model::Model;
use rand::{Rng, SeedableRng};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = PathBuf::from(
        args.first()
            .ok_or("usage: write_sample_mcap OUT.mcap [MODEL] [SECONDS]")?,
    );
    let default_model = concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf");
    let model_path = PathBuf::from(args.get(1).map_or(default_model, String::as_str));
    let seconds: f64 = args.get(2).map_or(Ok(2.0), |s| s.parse())?;
    let (model, _) = Model::load(&model_path)?;
    let spec = Model::read_spec(&model_path)?;
    let n = model.nv;
    let (mut header, robot_tf) =
        Header::for_model(format!("sample {}", model.name), &model_path, &model, &spec);
    header.metadata = vec![("model".into(), model_path.display().to_string())];
    let mut w = McapWriter::create(&out, &header)?;
    let mut data = Data::new(&model);
    let mid: Vec<f64> = (0..n)
        .map(|k| {
            let (lo, hi) = (model.lower[k].max(-1.0), model.upper[k].min(1.0));
            0.5 * (lo + hi)
        })
        .collect();
    let steps = (seconds * 100.0).round() as usize;
    let mut peak = vec![0.0f64; n];
    for s in 0..=steps {
        let t = s as f64 * 0.01;
        let q: Vec<f64> = (0..n)
            .map(|k| mid[k] + 0.4 * (t + k as f64).sin())
            .collect();
        let qd: Vec<f64> = (0..n).map(|k| 0.4 * (t + k as f64).cos()).collect();
        let tau = gravity_torque(&model, &mut data, &q).to_vec();
        for (p, x) in peak.iter_mut().zip(&tau) {
            *p = p.max(x.abs());
        }
        w.write_frame(&robot_tf.frame_at(&model, &mut data, t, &q, &qd, &tau))?;
    }
    // Workspace: the origin of the last link on the last body, at random configurations.
    let last_body = model.nbodies().saturating_sub(1);
    let tip = (model.links.iter())
        .rposition(|l| l.body == last_body)
        .unwrap_or(model.links.len() - 1);
    let mut rng = rand::rngs::SmallRng::seed_from_u64(1);
    let mut jac = nalgebra::DMatrix::zeros(6, n);
    let mut cloud = PointCloud {
        t: seconds,
        frame: model.links[0].name.clone(),
        ..PointCloud::default()
    };
    for _ in 0..2000 {
        let q: Vec<f64> = (0..n)
            .map(|k| rng.random_range(model.lower[k].max(-3.1)..=model.upper[k].min(3.1)))
            .collect();
        compute_joint_jacobians(&model, &mut data, &q);
        let p = frame_placement(&model, &data, tip).trans;
        frame_jacobian(&model, &data, tip, Expressed::World, &mut jac);
        cloud.points.push([p.x as f32, p.y as f32, p.z as f32]);
        cloud.values.push(manipulability(&jac) as f32);
    }
    w.write_cloud(&cloud)?;
    let rows: Vec<TorqueRow> = (0..n)
        .map(|k| {
            let limit = model.effort_limit[k];
            let margin = limit.is_finite().then(|| 100.0 * (limit - peak[k]) / limit);
            TorqueRow {
                joint: header.joint_names[k].clone(),
                peak_torque: peak[k],
                rms_torque: 0.7 * peak[k],
                peak_speed: 0.4,
                peak_power: 0.4 * peak[k],
                limit: limit.is_finite().then_some(limit),
                velocity_limit: Some(model.velocity_limit[k]).filter(|v| v.is_finite()),
                margin,
                ok: margin.is_none_or(|m| m >= 0.0),
                first_violation: None,
            }
        })
        .collect();
    w.write_torque_check(seconds, &rows)?;
    let last = &model.links[tip].name;
    w.write_collisions(&[
        CollisionEvent {
            t: 0.5 * seconds,
            body_a: last.clone(),
            body_b: "table".into(),
        },
        CollisionEvent {
            t: 0.75 * seconds,
            body_a: last.clone(),
            body_b: "table".into(),
        },
    ])?;
    let path = w.finish()?;
    println!(
        "{}: {} frames, {} workspace points",
        path.display(),
        steps + 1,
        cloud.points.len()
    );
    Ok(())
}
