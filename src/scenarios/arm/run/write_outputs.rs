//! Step 5 of a run: the output directory, the MCAP recording (opened before the
//! simulation streams into it, finished here), the Rerun log, the plots and CSV files.

use crate::core::diag::LocatedError as ScenarioError;
use crate::io::plots::torque_chart::{write_torque_plot, PlotFormat};
use crate::io::record::mcap_out::McapWriter;
use crate::io::record::obstacle_markers::{markers_of, ObstacleMarker};
use crate::io::record::{CollisionEvent, Header, TorqueRow};
use crate::model::data::Data;
use crate::motion::{TorqueReport, Trajectory};
use crate::scenarios::arm::run::sim_sample::SimSample;
use crate::scenarios::arm::scene::Scene;
use crate::scenarios::arm::sim_plots as plots;
use crate::scenarios::arm::task_motion::Plan;
use serde_json::Value;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The open recording: writer, TF builder, a workspace, and the first write error.
pub(super) type Recorder = (
    McapWriter,
    crate::io::record::tf::RobotTf,
    Data,
    Option<String>,
);

/// What the output steps read.
pub(super) struct OutputContext<'a> {
    pub scene: &'a Scene,
    pub plan: &'a Plan,
    pub torque: &'a TorqueReport,
    pub collisions: &'a Value,
    pub tool_path: &'a Option<crate::io::record::PointCloud>,
    pub samples: &'a [SimSample],
    pub sim_json: &'a Value,
    pub out_dir: &'a Path,
    pub started_ns: u64,
}

/// The output directory (created when files are written) and the recording, opened
/// with its header and obstacles when `outputs.mcap` is on.
pub(super) fn open_recording(
    scene: &Scene,
    opts: &crate::scenarios::arm::run::RunOptions,
    started_ns: u64,
) -> Result<(PathBuf, Option<Recorder>), ScenarioError> {
    let model = &scene.model;
    let fail = |key: &str, msg: String| scene.error_at(key, msg);
    let out_dir = opts
        .out_dir
        .clone()
        .or_else(|| scene.outputs.dir.clone())
        .unwrap_or_else(|| Path::new("out").join(&scene.name));
    if opts.write_files {
        std::fs::create_dir_all(&out_dir).map_err(|e| {
            fail(
                "outputs.dir",
                format!("cannot create {}: {e}", out_dir.display()),
            )
        })?;
    }
    let recorder = if opts.write_files && scene.outputs.mcap {
        let (header, robot_tf) = recording_header(scene, started_ns, opts.keep_mesh_uris);
        let path = out_dir.join(format!("{}.mcap", scene.name));
        let rec_err = |e: crate::io::record::record_error::RecordError| {
            fail("outputs", format!("recording: {e}"))
        };
        let mut w = McapWriter::create(&path, &header).map_err(rec_err)?;
        let markers = obstacle_markers(scene);
        if !markers.is_empty() {
            w.write_obstacles(&markers).map_err(rec_err)?;
        }
        Some((w, robot_tf, Data::new(model), None::<String>))
    } else {
        None
    };
    Ok((out_dir, recorder))
}

/// Finishes the recording: the planned motion when nothing was simulated, the torque
/// check, the tool path and the first collision; returns the file written.
pub(super) fn finish_recording(cx: &OutputContext, rec: Recorder) -> Result<String, ScenarioError> {
    let OutputContext {
        scene,
        plan,
        torque,
        collisions,
        tool_path,
        samples,
        ..
    } = *cx;
    let (mut w, tf, mut data, err) = rec;
    let model = &scene.model;
    let n = model.nv;
    let traj = &plan.trajectory;
    let duration = traj.duration();
    let fail = |key: &str, msg: String| scene.error_at(key, msg);
    let rec_err = |e: String| fail("outputs", format!("recording: {e}"));
    if let Some(e) = err {
        return Err(rec_err(e));
    }
    if samples.is_empty() {
        // No simulation: record the planned motion (torques of the check) at 100 Hz.
        let every = ((0.01 / torque.dt).round() as usize).max(1);
        let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for k in (0..torque.t.len()).step_by(every) {
            traj.sample(torque.t[k], &mut q, &mut qd, &mut qdd);
            let tau = &torque.tau[k * n..(k + 1) * n];
            let frame = tf.frame_at(model, &mut data, torque.t[k], &q, &qd, tau);
            w.write_frame(&frame).map_err(|e| rec_err(e.to_string()))?;
        }
    }
    let rows: Vec<TorqueRow> = torque
        .joints
        .iter()
        .map(|j| TorqueRow {
            joint: j.joint.clone(),
            peak_torque: j.peak_torque,
            rms_torque: j.rms_torque,
            peak_speed: j.peak_speed,
            peak_power: j.peak_power,
            limit: j.limit.is_finite().then_some(j.limit),
            velocity_limit: j.velocity_limit.is_finite().then_some(j.velocity_limit),
            margin: j.limit.is_finite().then_some(j.margin),
            ok: j.ok,
            first_violation: j.first_violation_s,
        })
        .collect();
    if let Some(c) = &tool_path {
        w.write_cloud(c).map_err(|e| rec_err(e.to_string()))?;
    }
    w.write_torque_check(duration, &rows)
        .map_err(|e| rec_err(e.to_string()))?;
    if let Some(ev) = first_collision_event(collisions) {
        w.write_collisions(&[ev])
            .map_err(|e| rec_err(e.to_string()))?;
    }
    let p = w.finish().map_err(|e| rec_err(e.to_string()))?;
    Ok(p.display().to_string())
}

/// Logs the run to Rerun; returns the file written (when saving).
pub(super) fn log_rerun(
    cx: &OutputContext,
    sink: &crate::io::record::rerun::rerun_out::RerunSink,
    opts: &crate::scenarios::arm::run::RunOptions,
    warnings: &mut Vec<String>,
) -> Result<Option<String>, ScenarioError> {
    let OutputContext {
        scene,
        collisions,
        tool_path,
        samples,
        started_ns,
        ..
    } = *cx;
    let model = &scene.model;
    let fail = |key: &str, msg: String| scene.error_at(key, msg);
    let (header, tf) = recording_header(scene, started_ns, opts.keep_mesh_uris);
    let mut data = Data::new(model);
    let frames = samples
        .iter()
        .map(|s| tf.frame_at(model, &mut data, s.t, &s.q, &s.qd, &s.tau))
        .collect();
    let collisions = first_collision_event(collisions).into_iter().collect();
    let rec = crate::io::record::Recording {
        header,
        frames,
        collisions,
        clouds: tool_path.iter().cloned().collect(),
        obstacles: obstacle_markers(scene),
        ..Default::default()
    };
    let extras = crate::io::record::rerun::rerun_out::SceneExtras {
        obstacles: scene
            .obstacles
            .iter()
            .filter_map(|o| o.to_obstacle().ok())
            .map(|o| {
                let g = crate::model::Geometry {
                    origin: scene.base.mul(&o.pose),
                    shape: o.shape.clone(),
                    rgba: None,
                };
                (o.name.clone(), g)
            })
            .collect(),
        obstacle_dir: Path::new(&scene.file).parent().map(Path::to_path_buf),
    };
    let rep = crate::io::record::rerun::rerun_out::log_recording_with(
        &rec,
        Some(&scene.spec),
        scene.model_path.parent(),
        &extras,
        sink,
    )
    .map_err(|e| fail("outputs", format!("rerun: {e}")))?;
    warnings.extend(rep.warnings);
    Ok(match sink {
        crate::io::record::rerun::rerun_out::RerunSink::Save(p) => Some(p.display().to_string()),
        _ => None,
    })
}

/// Writes the plots, the CSV files (and names the report file, written last); returns
/// the files in order.
pub(super) fn write_files(cx: &OutputContext) -> Result<Vec<String>, ScenarioError> {
    let OutputContext {
        scene,
        plan,
        torque,
        samples,
        sim_json,
        out_dir,
        ..
    } = *cx;
    let names = scene.model.dof_names();
    let traj = &plan.trajectory;
    let mut outputs = Vec::new();
    let fail = |key: &str, msg: String| scene.error_at(key, msg);
    let out_err = |e: String| fail("outputs", e);
    if let Some(fmt) = scene.outputs.torque_plot {
        let ext = if fmt == PlotFormat::Png { "png" } else { "svg" };
        let p = out_dir.join(format!("{}_torques.{ext}", scene.name));
        write_torque_plot(torque, &p, fmt, Some(&scene.name))
            .map_err(|e| out_err(e.to_string()))?;
        outputs.push(p.display().to_string());
        if !samples.is_empty() {
            let p = out_dir.join(format!("{}_simulation.{ext}", scene.name));
            plots::write(
                &p,
                &format!("{}: simulation", scene.name),
                &simulation_subtitle(scene, sim_json),
                &plots::simulation_panels(scene, samples),
                fmt,
            )
            .map_err(out_err)?;
            outputs.push(p.display().to_string());
        }
    }
    if scene.outputs.trajectory_csv {
        let p = out_dir.join(format!("{}_trajectory.csv", scene.name));
        write_csv(&p, &names, traj, scene.check_dt).map_err(out_err)?;
        outputs.push(p.display().to_string());
    }
    if scene.outputs.simulation_csv && !samples.is_empty() {
        let p = out_dir.join(format!("{}_simulation.csv", scene.name));
        let mut s = String::from("t");
        for pre in ["q", "qd", "tau", "q_ref"] {
            for nm in &names {
                let _ = write!(s, ",{pre}_{nm}");
            }
        }
        s.push('\n');
        for x in samples {
            let _ = write!(s, "{}", x.t);
            for v in x.q.iter().chain(&x.qd).chain(&x.tau).chain(&x.q_ref) {
                let _ = write!(s, ",{v}");
            }
            s.push('\n');
        }
        crate::core::files::write_atomic(&p, s.as_bytes())
            .map_err(|e| out_err(format!("{}: {e}", p.display())))?;
        outputs.push(p.display().to_string());
    }
    if scene.outputs.report {
        outputs.push(
            out_dir
                .join(format!("{}.json", scene.name))
                .display()
                .to_string(),
        );
    }
    Ok(outputs)
}

/// The recording header of a scene: the model's (joints, limits, robot description, fixed
/// frames) with the scene's `world` → base transform first, the scenario metadata, and the
/// epoch `epoch_ns` (Unix ns of `t = 0`); mesh URIs made absolute unless `keep_uris`.
pub(super) fn recording_header(
    scene: &Scene,
    epoch_ns: u64,
    keep_uris: bool,
) -> (Header, crate::io::record::tf::RobotTf) {
    let model = &scene.model;
    let (mut header, tf) = Header::for_model_with(
        &scene.name,
        &scene.model_path,
        model,
        &scene.spec,
        (!keep_uris).then_some(&scene.package_paths),
    );
    header.static_tf.insert(
        0,
        crate::io::record::tf::to_transform("world", &model.links[0].name, &scene.base),
    );
    header.metadata = vec![
        ("scenario".into(), scene.file.clone()),
        ("effects".into(), scene.effect_names.join(",")),
        ("trajectory".into(), scene.timing.as_str().into()),
    ];
    header.epoch_ns = Some(epoch_ns);
    (header, tf)
}

/// The scene's obstacles as recording markers in `world` (the scene frame), mesh files
/// resolved against the scenario's directory.
pub fn obstacle_markers(scene: &Scene) -> Vec<ObstacleMarker> {
    // Validated when the scene was built.
    let obstacles: Vec<_> = scene
        .obstacles
        .iter()
        .filter_map(|o| o.to_obstacle().ok())
        .collect();
    markers_of(
        &obstacles,
        "world",
        &scene.base,
        Path::new(&scene.file).parent(),
    )
}

/// The first collision of the report's `collisions` JSON as a recording event.
pub(super) fn first_collision_event(collisions: &Value) -> Option<CollisionEvent> {
    let f = collisions.get("first").filter(|f| !f.is_null())?;
    Some(CollisionEvent {
        t: f["time"].as_f64().unwrap_or(0.0),
        body_a: f["pair"][0].as_str().unwrap_or("").into(),
        body_b: f["pair"][1].as_str().unwrap_or("").into(),
    })
}

/// The simulation plot's second title line: controller, integrator, step and effects.
fn simulation_subtitle(scene: &Scene, sim: &Value) -> String {
    format!(
        "{} control, {} integrator, step {} s - effects: {}",
        sim["controller"].as_str().unwrap_or("?"),
        sim["integrator"].as_str().unwrap_or("?"),
        sim["dt"].as_f64().unwrap_or(f64::NAN),
        if scene.effect_names.is_empty() {
            "none (rigid bodies)".to_string()
        } else {
            scene.effect_names.join(", ")
        }
    )
}

fn write_csv(path: &Path, names: &[String], traj: &dyn Trajectory, dt: f64) -> Result<(), String> {
    let n = names.len();
    let mut s = String::from("t");
    for pre in ["q", "qd", "qdd"] {
        for nm in names {
            let _ = write!(s, ",{pre}_{nm}");
        }
    }
    s.push('\n');
    let d = traj.duration();
    let k = ((d / dt).ceil() as usize).max(1);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for i in 0..=k {
        let t = d * i as f64 / k as f64;
        traj.sample(t, &mut q, &mut qd, &mut qdd);
        let _ = write!(s, "{t}");
        for v in q.iter().chain(&qd).chain(&qdd) {
            let _ = write!(s, ",{v}");
        }
        s.push('\n');
    }
    crate::core::files::write_atomic(path, s.as_bytes())
        .map_err(|e| format!("{}: {e}", path.display()))
}
