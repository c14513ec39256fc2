//! A sample Rerun recording of a model: a smooth motion around the neutral pose with RNEA
//! torques, the workspace cloud coloured by manipulability, one collision marker.
//!
//! ```text
//! cargo run --release --example rerun_demo -- robots/ur5.urdf ur5.rrd   # write a file
//! cargo run --release --example rerun_demo -- robots/ur5.urdf --spawn   # open the viewer
//! ```

use armsim::dynamics::rnea;
use armsim::io::record::rerun::rerun_out::{log_recording, RerunSink};
use armsim::io::record::{CollisionEvent, Header, PointCloud, Recording};
use armsim::model::data::Data;
use armsim::model::Model;
use armsim::workspace::{sample_workspace, WorkspaceOptions};
use std::path::Path;
use std::process::ExitCode;

fn run(model_path: &str, target: &str) -> Result<(), String> {
    let (model, _) = Model::load(model_path).map_err(|e| e.to_string())?;
    let spec = Model::read_spec(Path::new(model_path)).map_err(|e| e.to_string())?;
    let (header, robot_tf) = Header::for_model(
        format!("{} demo", model.name),
        Path::new(model_path),
        &model,
        &spec,
    );
    let mut rec = Recording {
        header,
        ..Default::default()
    };
    let mut data = Data::new(&model);
    let q0 = model.neutral();
    let (n, w, dt) = (model.nv, 1.5, 0.02);
    for k in 0..250 {
        let t = k as f64 * dt;
        let ph = |i: usize| w * t + i as f64;
        let q: Vec<f64> = (0..n).map(|i| q0[i] + 0.5 * ph(i).sin()).collect();
        let qd: Vec<f64> = (0..n).map(|i| 0.5 * w * ph(i).cos()).collect();
        let qdd: Vec<f64> = (0..n).map(|i| -0.5 * w * w * ph(i).sin()).collect();
        let tau = rnea(&model, &mut data, &q, &qd, &qdd).to_vec();
        rec.frames
            .push(robot_tf.frame_at(&model, &mut data, t, &q, &qd, &tau));
    }
    let ws = sample_workspace(
        &model,
        &WorkspaceOptions {
            samples: 1 << 16,
            replicates: 2,
            keep_points: 20_000,
            quiet: true,
            ..Default::default()
        },
    )
    .map_err(|e| e.to_string())?;
    rec.clouds.push(PointCloud {
        t: 0.0,
        frame: "world".into(),
        points: ws.points.iter().map(|p| p.p.map(|x| x as f32)).collect(),
        values: ws.points.iter().map(|p| p.manipulability as f32).collect(),
    });
    if let (Some(first), Some(last)) = (rec.frames[0].tf.first(), rec.frames[0].tf.last()) {
        rec.collisions.push(CollisionEvent {
            t: 2.0,
            body_a: last.child.clone(),
            body_b: first.child.clone(),
        });
    }
    let sink = if target == "--spawn" {
        RerunSink::Spawn
    } else {
        RerunSink::Save(target.into())
    };
    let r = log_recording(&rec, Some(&spec), None, &sink).map_err(|e| e.to_string())?;
    for w in &r.warnings {
        eprintln!("warning: {w}");
    }
    println!(
        "{} links, {} frames, {} visuals, {} points{}",
        r.links.len(),
        r.frames,
        r.visuals,
        r.points,
        r.bytes
            .map(|b| format!(", wrote {target} ({b} bytes)"))
            .unwrap_or_default()
    );
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [model, target] = args.as_slice() else {
        eprintln!("usage: rerun_demo MODEL (OUT.rrd | --spawn)");
        return ExitCode::from(2);
    };
    match run(model, target) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
