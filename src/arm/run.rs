//! Running an arm scenario end to end: plan the task, check the joint torques it needs
//! with the named effects (for every payload of a sweep), check collisions along it,
//! simulate it with exactly the named effects (with the rapier contact scene only when
//! `contact` is named), write the output files, and assemble the report (JSON + text).

use super::contact::{ContactReport, ContactSim};
use super::plan::{plan, Plan};
use super::plots;
use super::scene::{Scene, Timing};
use crate::data::Data;
use crate::diag::LocatedError as ScenarioError;
use crate::dynamics::{Effects, Payload};
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::recording::mcap_out::{wall_clock_ns, McapWriter};
use crate::recording::obstacles::{markers_of, ObstacleMarker};
use crate::recording::{CollisionEvent, Header, TorqueRow};
use crate::report::Report;
use crate::sim::{SimConfig, Simulator, StepHook};
use crate::spatial::Inertia;
use crate::trajectory::{
    check_torques, check_torques_switched, AsReference, CheckOptions, PlotFormat, TorqueReport,
    Trajectory,
};
use serde_json::{json, Map, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of a run that do not come from the file.
#[derive(Clone)]
pub struct RunOptions {
    /// Output directory (overrides `[outputs] dir`; default `out/<name>`).
    pub out_dir: Option<PathBuf>,
    /// Write output files at all.
    pub write_files: bool,
    /// Polled during the simulation: `true` stops it (SIGINT).
    pub stop: fn() -> bool,
    /// Also log the run to Rerun (an `.rrd` file or a spawned viewer).
    pub rerun: Option<crate::recording::rerun_out::RerunSink>,
    /// Directories searched first for `package://` mesh URIs (`--package-path`).
    pub package_path: Vec<PathBuf>,
    /// Keep the recording's robot description's mesh URIs as the model file writes them
    /// instead of absolute `file://` URIs (`--keep-mesh-uris`).
    pub keep_mesh_uris: bool,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            out_dir: None,
            write_files: true,
            stop: || false,
            rerun: None,
            package_path: Vec::new(),
            keep_mesh_uris: false,
        }
    }
}

/// One recorded simulation sample.
#[derive(Clone, Debug)]
pub struct SimSample {
    pub t: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub tau: Vec<f64>,
    pub q_ref: Vec<f64>,
}

/// Everything a run produced, for callers that want more than the report (tests,
/// recordings).
pub struct Outcome {
    pub scene: Scene,
    pub plan: Plan,
    pub torque: TorqueReport,
    /// `(payload mass, report)` of each sweep entry.
    pub sweep: Vec<(f64, TorqueReport)>,
    pub samples: Vec<SimSample>,
    pub contact: Option<ContactReport>,
    /// How often each effect's code ran in the simulation.
    pub effect_runs: Option<crate::dynamics::EffectRuns>,
    pub contact_built: bool,
    pub report: Report,
}

fn named(names: &[String], v: &[f64]) -> Value {
    Value::Object(
        names
            .iter()
            .zip(v)
            .map(|(n, x)| (n.clone(), json!(x)))
            .collect::<Map<_, _>>(),
    )
}

fn effects_with_mass(scene: &Scene, mass: f64) -> Result<Effects, String> {
    let mut fx = scene.effects.clone();
    if let Some((link, inertia)) = scene.payload_inertia {
        let i = Inertia::new(mass, inertia.com, inertia.inertia_com);
        fx.payload = Some(Payload::new(&scene.model, link, i)?);
    }
    Ok(fx)
}

/// Runs a parsed, validated scene.
pub fn run_scene(scene: Scene, opts: &RunOptions) -> Result<Outcome, ScenarioError> {
    let model = &scene.model;
    let names = model.dof_names();
    let n = model.nv;
    let file = scene.file.clone();
    let fail = |key: &str, msg: String| ScenarioError::new(&file, None, key, msg);
    // The recording's epoch: simulated t = 0 is the run's wall-clock start.
    let started_ns = wall_clock_ns();
    let mut timings = Map::new();
    let mut warnings = scene.warnings.clone();
    warnings.extend(scene.model_warnings.iter().cloned());

    // 1. Plan.
    let plan = plan(&scene)?;
    timings.insert("plan_s".into(), json!(plan.planning_time_s));
    let traj = &plan.trajectory;
    let duration = traj.duration();

    // 2. Torque check (each payload of a sweep; the last is the nominal one).
    let t0 = Instant::now();
    let masses = if scene.payload_masses.is_empty() {
        vec![f64::NAN]
    } else {
        scene.payload_masses.clone()
    };
    let mut sweep = Vec::new();
    for (i, m) in masses.iter().enumerate() {
        let fx = if m.is_nan() {
            scene.effects.clone()
        } else {
            effects_with_mass(&scene, *m).map_err(|e| fail("payload", e))?
        };
        let copts = CheckOptions {
            dt: scene.check_dt,
            effort_limit: Some(scene.check_effort.clone()),
            velocity_limit: Some(scene.check_velocity.clone()),
            keep_series: i + 1 == masses.len(),
        };
        // With a grasped part, its payload only between the attach and the detach.
        let r = match plan.carry {
            Some(window) => {
                let bare = Effects {
                    payload: None,
                    ..fx.clone()
                };
                check_torques_switched(model, traj, &bare, &fx, window, &copts)
            }
            None => check_torques(model, traj, &fx, &copts),
        }
        .map_err(|e| fail("trajectory", format!("torque check: {e}")))?;
        sweep.push((*m, r));
    }
    let torque = sweep.last().expect("one").1.clone();
    let sweep = if scene.payload_masses.len() > 1 {
        sweep
    } else {
        Vec::new()
    };
    timings.insert("torque_check_s".into(), json!(t0.elapsed().as_secs_f64()));

    // 3. Collisions along the planned motion.
    let t0 = Instant::now();
    let collisions = match &scene.collision {
        None => json!({"checked": false}),
        Some(copts) => super::checks::check_collisions(&scene, &plan, copts, &mut warnings)
            .map_err(|e| fail("collision", e))?,
    };
    let tool_path = super::checks::planned_tool_path(&scene, &plan);
    timings.insert("collisions_s".into(), json!(t0.elapsed().as_secs_f64()));

    // The output directory and the recording (streamed during the simulation, so an
    // interrupted run still leaves a valid file).
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
    let mut recorder = if opts.write_files && scene.outputs.mcap {
        let (header, robot_tf) = recording_header(&scene, started_ns, opts.keep_mesh_uris);
        let path = out_dir.join(format!("{}.mcap", scene.name));
        let rec_err =
            |e: crate::recording::error::RecordError| fail("outputs", format!("recording: {e}"));
        let mut w = McapWriter::create(&path, &header).map_err(rec_err)?;
        let markers = obstacle_markers(&scene);
        if !markers.is_empty() {
            w.write_obstacles(&markers).map_err(rec_err)?;
        }
        Some((w, robot_tf, Data::new(model), None::<String>))
    } else {
        None
    };

    // 4. Simulation with exactly the named effects.
    let mut samples: Vec<SimSample> = Vec::new();
    let mut sim_json = Value::Null;
    let mut contact_report = None;
    let mut effect_runs = None;
    let mut contact_built = false;
    if let Some(ss) = &scene.simulation {
        let t0 = Instant::now();
        let sim_duration = ss.duration.unwrap_or(duration + ss.settle);
        let mut sim = Simulator::new(model, scene.effects.clone())
            .map_err(|e| fail("simulation", e.to_string()))?;
        sim.set_payload_window(plan.carry);
        let cfg = SimConfig {
            dt: ss.dt,
            duration: sim_duration,
            integrator: ss.integrator,
            controller: ss.controller.clone(),
            record_every: ((1.0 / (ss.record_rate * ss.dt)).round() as usize).max(1),
        };
        let reference = AsReference(traj);
        let stop = opts.stop;
        let stop_fn = move || stop();
        let mut contact = scene.contact.as_ref().map(|c| {
            contact_built = true;
            let g = scene
                .effects
                .gravity
                .map(|g| scene.base.rot * g)
                .unwrap_or_default();
            let mut cs = ContactSim::new(model, scene.base, c, [g.x, g.y, g.z], ss.dt, &stop_fn);
            cs.trace.reserve((sim_duration / ss.dt) as usize + 2);
            cs.place(&scene.q0);
            cs
        });
        struct Interrupt(fn() -> bool);
        impl StepHook for Interrupt {
            fn before_step(
                &mut self,
                _t: f64,
                _q: &[f64],
                _qd: &[f64],
                _w: &mut Vec<crate::dynamics::ExternalWrench>,
            ) -> bool {
                !(self.0)()
            }
        }
        let mut interrupt = Interrupt(opts.stop);
        let hook: &mut dyn StepHook = match contact.as_mut() {
            Some(c) => c,
            None => &mut interrupt,
        };
        let result = sim.run_with_hook(&scene.q0, &cfg, &reference, hook, |s| {
            if let Some((w, tf, data, err)) = recorder.as_mut() {
                if err.is_none() {
                    let frame = tf.frame_at(model, data, s.t, s.q, s.qd, s.tau);
                    if let Err(e) = w.write_frame(&frame) {
                        *err = Some(e.to_string());
                    }
                }
            }
            samples.push(SimSample {
                t: s.t,
                q: s.q.to_vec(),
                qd: s.qd.to_vec(),
                tau: s.tau.to_vec(),
                q_ref: s.q_ref.to_vec(),
            })
        });
        effect_runs = Some(sim.effect_runs());
        let sim_report = match result {
            Ok(r) => r,
            Err(e) => {
                return Err(fail(
                    "simulation",
                    format!("{e} (the planned motion, torque check and collision check passed; the simulation settings did not)"),
                ))
            }
        };
        contact_report = contact.as_ref().map(|c| c.report());
        // Tracking and residual vibration.
        let mut data = Data::new(model);
        let mut tool_err_max: f64 = 0.0;
        let mut tool_err_settle: f64 = 0.0;
        let mut settle_err = vec![0.0f64; n];
        let mut peak_tau = vec![0.0f64; n];
        for s in &samples {
            for (p, t) in peak_tau.iter_mut().zip(&s.tau) {
                *p = p.max(t.abs());
            }
            forward_kinematics(model, &mut data, &s.q);
            let p = frame_placement(model, &data, scene.tool).trans;
            forward_kinematics(model, &mut data, &s.q_ref);
            let pr = frame_placement(model, &data, scene.tool).trans;
            let e = (p - pr).norm();
            tool_err_max = tool_err_max.max(e);
            if s.t > duration {
                tool_err_settle = tool_err_settle.max(e);
                for (e, (q, r)) in settle_err.iter_mut().zip(s.q.iter().zip(&s.q_ref)) {
                    *e = e.max((q - r).abs());
                }
            }
        }
        let natural = scene.effects.elasticity.as_ref().map(|el| {
            let m = crate::dynamics::crba(model, &mut data, &scene.q0);
            let f: Vec<f64> = (0..n)
                .map(|k| {
                    (el.stiffness[k] * (1.0 / el.motor_inertia[k] + 1.0 / m[(k, k)].max(1e-12)))
                        .sqrt()
                        / (2.0 * std::f64::consts::PI)
                })
                .collect();
            named(&names, &f)
        });
        let vib = vibration_frequency(&samples, duration);
        let runs = sim.effect_runs();
        sim_json = json!({
            "integrator": sim_report.integrator,
            "controller": match &ss.controller {
                crate::sim::Controller::None => "none",
                crate::sim::Controller::ComputedTorque { .. } => "computed_torque",
                crate::sim::Controller::PdGravity { .. } => "pd_gravity",
            },
            "dt": sim_report.dt,
            "steps": sim_report.steps,
            "sim_time_s": sim_report.sim_time_s,
            "wall_time_s": sim_report.wall_time_s,
            "real_time_factor": sim_report.real_time_factor,
            "interrupted": sim_report.interrupted,
            "max_tracking_error": named(&names, &sim_report.max_tracking_error),
            "peak_applied_torque": named(&names, &peak_tau),
            "max_tool_error_m": tool_err_max,
            "residual_tool_error_m": tool_err_settle,
            "residual_joint_error": named(&names, &settle_err),
            "residual_vibration_hz": vib,
            "natural_frequency_hz": natural,
            "energy_audit": sim_report.energy.as_ref().map(|e| json!({
                "max_drift_j": e.max_drift_j,
                "max_relative_drift": e.max_relative_drift,
            })),
            "energy_audit_skipped": sim_report.energy.is_none().then_some(
                "something dissipates or acts from outside (friction, damping, rotor losses, payload, contact): no energy balance to check"),
            "final_q": named(&names, &sim_report.final_q),
            "effect_runs": {
                "gravity": runs.gravity, "friction": runs.friction, "rotor_inertia": runs.rotor,
                "joint_elasticity": runs.elasticity, "payload": runs.payload, "external": runs.external,
            },
            "recorded_samples": samples.len(),
        });
        timings.insert("simulation_s".into(), json!(t0.elapsed().as_secs_f64()));
    }

    // 5. Output files.
    let mut outputs: Vec<String> = Vec::new();
    if let Some((mut w, tf, mut data, err)) = recorder.take() {
        let t0 = Instant::now();
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
        if let Some(ev) = first_collision_event(&collisions) {
            w.write_collisions(&[ev])
                .map_err(|e| rec_err(e.to_string()))?;
        }
        let p = w.finish().map_err(|e| rec_err(e.to_string()))?;
        outputs.push(p.display().to_string());
        timings.insert("recording_s".into(), json!(t0.elapsed().as_secs_f64()));
    }
    if let Some(sink) = &opts.rerun {
        let t0 = Instant::now();
        let (header, tf) = recording_header(&scene, started_ns, opts.keep_mesh_uris);
        let mut data = Data::new(model);
        let frames = samples
            .iter()
            .map(|s| tf.frame_at(model, &mut data, s.t, &s.q, &s.qd, &s.tau))
            .collect();
        let collisions = first_collision_event(&collisions).into_iter().collect();
        let rec = crate::recording::Recording {
            header,
            frames,
            collisions,
            clouds: tool_path.iter().cloned().collect(),
            obstacles: obstacle_markers(&scene),
            ..Default::default()
        };
        let extras = crate::recording::rerun_out::SceneExtras {
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
        let rep = crate::recording::rerun_out::log_recording_with(
            &rec,
            Some(&scene.spec),
            scene.model_path.parent(),
            &extras,
            sink,
        )
        .map_err(|e| fail("outputs", format!("rerun: {e}")))?;
        warnings.extend(rep.warnings);
        if let crate::recording::rerun_out::RerunSink::Save(p) = sink {
            outputs.push(p.display().to_string());
        }
        timings.insert("rerun_s".into(), json!(t0.elapsed().as_secs_f64()));
    }
    if opts.write_files {
        let t0 = Instant::now();
        let out_err = |e: String| fail("outputs", e);
        if let Some(fmt) = scene.outputs.torque_plot {
            let ext = if fmt == PlotFormat::Png { "png" } else { "svg" };
            let p = out_dir.join(format!("{}_torques.{ext}", scene.name));
            torque
                .write_plot_titled(&p, fmt, Some(&scene.name))
                .map_err(|e| out_err(e.to_string()))?;
            outputs.push(p.display().to_string());
            if !samples.is_empty() {
                let p = out_dir.join(format!("{}_simulation.{ext}", scene.name));
                plots::write(
                    &p,
                    &format!("{}: simulation", scene.name),
                    &simulation_subtitle(&scene, &sim_json),
                    &plots::simulation_panels(&scene, &samples),
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
            for x in &samples {
                let _ = write!(s, "{}", x.t);
                for v in x.q.iter().chain(&x.qd).chain(&x.tau).chain(&x.q_ref) {
                    let _ = write!(s, ",{v}");
                }
                s.push('\n');
            }
            crate::io::write_atomic(&p, s.as_bytes())
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
        timings.insert("outputs_s".into(), json!(t0.elapsed().as_secs_f64()));
    }

    // 6. Report.
    let sweep_json: Vec<Value> = sweep
        .iter()
        .map(|(m, r)| {
            let worst = r
                .joints
                .iter()
                .min_by(|a, b| a.margin.total_cmp(&b.margin))
                .expect("joints");
            json!({
                "payload_mass": m,
                "ok": r.ok,
                "worst_joint": worst.joint,
                "worst_margin": worst.margin,
                "first_violation_s": r.joints.iter().filter_map(|j| j.first_violation_s).reduce(f64::min),
                "peak_torque": named(&names, &r.joints.iter().map(|j| j.peak_torque).collect::<Vec<_>>()),
            })
        })
        .collect();
    let collision_free = collisions
        .get("collision_free")
        .and_then(Value::as_bool)
        .unwrap_or(true);
    let ok = torque.ok && collision_free;
    let json = json!({
        "scenario": scene.name,
        "file": scene.file,
        "description": scene.description,
        "model": {
            "file": scene.model_path.display().to_string(),
            "name": model.name,
            "dof": n,
            "joints": names,
            "tool": model.links[scene.tool].name,
            "base_xyz": [scene.base.trans.x, scene.base.trans.y, scene.base.trans.z],
        },
        "effects": scene.effect_names,
        "plan": {
            "task": scene.task_kind,
            "trajectory": scene.timing.as_str(),
            "duration_s": duration,
            "pieces": plan.pieces,
            "ik_solves": plan.ik_solves,
            "planner": plan.planner,
            "part_carried_s": plan.carry.map(|(a, b)| [a, b]),
        },
        "torque_check": torque.json_rows(),
        "torque_check_ok": torque.ok,
        "torque_check_dt": torque.dt,
        "torque_check_note": scene.contact.is_some().then_some(
            "the planned torques do not include the contact forces (unknown before simulating): see simulation.peak_applied_torque"),
        "payload_sweep": if sweep_json.is_empty() { Value::Null } else { Value::Array(sweep_json) },
        "collisions": collisions,
        "contact": contact_report.as_ref().map(|c| serde_json::to_value(c).expect("serialise")),
        "contact_pipeline_built": contact_built,
        "simulation": sim_json,
        "ok": ok,
        "timings": timings,
        "warnings": warnings,
        "outputs": outputs,
    });
    let text = summary(&scene, &plan, &torque, &json);
    if opts.write_files && scene.outputs.report {
        let p = out_dir.join(format!("{}.json", scene.name));
        let body = serde_json::to_string_pretty(&json).expect("json") + "\n";
        crate::io::write_atomic(&p, body.as_bytes())
            .map_err(|e| fail("outputs", format!("{}: {e}", p.display())))?;
    }
    let report = Report { json, text };
    Ok(Outcome {
        scene,
        plan,
        torque,
        sweep,
        samples,
        contact: contact_report,
        effect_runs,
        contact_built,
        report,
    })
}

/// The recording header of a scene: the model's (joints, limits, robot description, fixed
/// frames) with the scene's `world` → base transform first, the scenario metadata, and the
/// epoch `epoch_ns` (Unix ns of `t = 0`); mesh URIs made absolute unless `keep_uris`.
fn recording_header(
    scene: &Scene,
    epoch_ns: u64,
    keep_uris: bool,
) -> (Header, crate::recording::tf::RobotTf) {
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
        crate::recording::tf::to_transform("world", &model.links[0].name, &scene.base),
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
fn first_collision_event(collisions: &Value) -> Option<CollisionEvent> {
    let f = collisions.get("first").filter(|f| !f.is_null())?;
    Some(CollisionEvent {
        t: f["time"].as_f64().unwrap_or(0.0),
        body_a: f["pair"][0].as_str().unwrap_or("").into(),
        body_b: f["pair"][1].as_str().unwrap_or("").into(),
    })
}

/// The dominant frequency of `q − q_ref` after the motion ends (zero crossings of the
/// joint with the largest residual), if it oscillates.
fn vibration_frequency(samples: &[SimSample], t_end: f64) -> Option<f64> {
    let tail: Vec<&SimSample> = samples.iter().filter(|s| s.t > t_end).collect();
    if tail.len() < 8 {
        return None;
    }
    let n = tail[0].q.len();
    let j = (0..n).max_by(|&a, &b| {
        let amp = |k: usize| {
            tail.iter()
                .map(|s| (s.q[k] - s.q_ref[k]).abs())
                .fold(0.0, f64::max)
        };
        amp(a).total_cmp(&amp(b))
    })?;
    let e: Vec<(f64, f64)> = tail.iter().map(|s| (s.t, s.q[j] - s.q_ref[j])).collect();
    let mean = e.iter().map(|x| x.1).sum::<f64>() / e.len() as f64;
    let crossings: Vec<f64> = e
        .windows(2)
        .filter(|w| (w[0].1 - mean) * (w[1].1 - mean) < 0.0)
        .map(|w| w[0].0)
        .collect();
    if crossings.len() < 3 {
        return None;
    }
    let span = crossings.last()? - crossings.first()?;
    (span > 0.0).then(|| (crossings.len() - 1) as f64 / (2.0 * span))
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
    crate::io::write_atomic(path, s.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))
}

fn summary(scene: &Scene, plan: &Plan, torque: &TorqueReport, j: &Value) -> String {
    let mut s = String::new();
    let model = &scene.model;
    let _ = writeln!(s, "scenario {} ({})", scene.name, scene.file);
    if let Some(d) = &scene.description {
        let _ = writeln!(s, "  {d}");
    }
    let _ = writeln!(
        s,
        "model: {} ({} joints, tool {}); effects: {}",
        scene.model_path.display(),
        model.nv,
        model.links[scene.tool].name,
        if scene.effect_names.is_empty() {
            "none (rigid bodies only)".to_string()
        } else {
            scene.effect_names.join(", ")
        }
    );
    let _ = writeln!(
        s,
        "plan: {} timed {}, {} pieces, {:.3} s (planned in {:.1} ms, {} IK solves)",
        scene.task_kind,
        scene.timing.as_str(),
        plan.pieces.len(),
        plan.trajectory.duration(),
        plan.planning_time_s * 1e3,
        plan.ik_solves
    );
    if scene.timing == Timing::TimeOptimal {
        let _ = writeln!(
            s,
            "  (time-optimal under the velocity, acceleration and torque limits)"
        );
    }
    let _ = writeln!(s);
    s.push_str(&torque.table());
    if let Some(Value::Array(sw)) = j.get("payload_sweep") {
        let _ = writeln!(s, "\npayload sweep:");
        for r in sw {
            let _ = writeln!(
                s,
                "  {:>8.3} kg: {} (worst {} margin {:.1} %{})",
                r["payload_mass"].as_f64().unwrap_or(f64::NAN),
                if r["ok"].as_bool() == Some(true) {
                    "ok"
                } else {
                    "LIMITS EXCEEDED"
                },
                r["worst_joint"].as_str().unwrap_or("-"),
                r["worst_margin"].as_f64().unwrap_or(f64::NAN),
                r["first_violation_s"]
                    .as_f64()
                    .map_or(String::new(), |t| format!(", first violation at {t:.3} s"))
            );
        }
        let first_bad = sw.iter().find(|r| r["ok"].as_bool() == Some(false));
        if let Some(r) = first_bad {
            let _ = writeln!(
                s,
                "  the joints are overloaded from {} kg on",
                r["payload_mass"].as_f64().unwrap_or(f64::NAN)
            );
        }
    }
    let c = &j["collisions"];
    let _ = writeln!(s);
    if c["checked"].as_bool() == Some(true) {
        match c.get("first").filter(|f| !f.is_null()) {
            Some(f) => {
                let _ = writeln!(
                    s,
                    "collisions: FIRST COLLISION at t = {:.4} s between {} and {} (depth {:.4} m)",
                    f["time"].as_f64().unwrap_or(f64::NAN),
                    f["pair"][0].as_str().unwrap_or("?"),
                    f["pair"][1].as_str().unwrap_or("?"),
                    f["depth"].as_f64().unwrap_or(f64::NAN)
                );
            }
            None => {
                let _ = writeln!(s, "collisions: none along the motion");
            }
        }
        for (key, what) in [
            ("min_environment", "closest to the environment"),
            ("min_self", "closest to itself"),
        ] {
            if let Some(m) = c.get(key).filter(|m| !m.is_null()) {
                let _ = writeln!(
                    s,
                    "  {what}: {} - {} at {:.4} m (t = {:.3} s)",
                    m["pair"][0].as_str().unwrap_or("?"),
                    m["pair"][1].as_str().unwrap_or("?"),
                    m["distance"].as_f64().unwrap_or(f64::NAN),
                    m["time"].as_f64().unwrap_or(f64::NAN)
                );
            }
        }
        let _ = writeln!(
            s,
            "  {} pairs, {} configurations checked",
            c["pairs_tested"], c["configurations_checked"]
        );
        if let Some(u) = c["unprotected_links"].as_array().filter(|u| !u.is_empty()) {
            let _ = writeln!(
                s,
                "  WARNING: {} link(s) have no collision shape and are not checked (set collision.skeleton_radius)",
                u.len()
            );
        }
    } else {
        let _ = writeln!(s, "collisions: not checked ([collision] enabled = false)");
    }
    let sim = &j["simulation"];
    if !sim.is_null() {
        let _ = writeln!(
            s,
            "\nsimulation: {} with {}, step {:e} s, {} steps, {:.3} s simulated in {:.3} s (real-time factor {:.1}){}",
            sim["integrator"].as_str().unwrap_or("?"),
            sim["controller"].as_str().unwrap_or("?"),
            sim["dt"].as_f64().unwrap_or(f64::NAN),
            sim["steps"],
            sim["sim_time_s"].as_f64().unwrap_or(f64::NAN),
            sim["wall_time_s"].as_f64().unwrap_or(f64::NAN),
            sim["real_time_factor"].as_f64().unwrap_or(f64::NAN),
            if sim["interrupted"].as_bool() == Some(true) { " INTERRUPTED" } else { "" }
        );
        let _ = writeln!(
            s,
            "  tool tracking error: max {:.3e} m, after the motion {:.3e} m",
            sim["max_tool_error_m"].as_f64().unwrap_or(f64::NAN),
            sim["residual_tool_error_m"].as_f64().unwrap_or(f64::NAN)
        );
        if let Some(f) = sim["residual_vibration_hz"].as_f64() {
            let _ = writeln!(s, "  residual vibration at {f:.2} Hz");
        }
        if let Some(nf) = sim["natural_frequency_hz"].as_object() {
            let list: Vec<String> = nf
                .iter()
                .map(|(k, v)| format!("{k} {:.1}", v.as_f64().unwrap_or(f64::NAN)))
                .collect();
            let _ = writeln!(
                s,
                "  joint-spring natural frequencies (Hz): {}",
                list.join(", ")
            );
        }
        match sim["energy_audit"].as_object() {
            Some(e) => {
                let _ = writeln!(
                    s,
                    "  energy audit: max |E - E0 - W| = {:.3e} J ({:.2e} relative)",
                    e["max_drift_j"].as_f64().unwrap_or(f64::NAN),
                    e["max_relative_drift"].as_f64().unwrap_or(f64::NAN)
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "  energy audit: skipped (the scene dissipates or is driven from outside)"
                );
            }
        }
        let runs = &sim["effect_runs"];
        let ran: Vec<String> = runs
            .as_object()
            .map(|m| {
                m.iter()
                    .filter(|(_, v)| v.as_u64() != Some(0))
                    .map(|(k, v)| format!("{k} x{v}"))
                    .collect()
            })
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "  effect code run: {}",
            if ran.is_empty() {
                "none".to_string()
            } else {
                ran.join(", ")
            }
        );
    }
    if let Some(c) = j.get("contact").filter(|c| !c.is_null()) {
        let _ = writeln!(
            s,
            "\ncontact (rapier3d): box moved {:.4} m, top speed {:.3} m/s, peak push {:.2} N, sliding push {} N vs Coulomb mu m g = {:.2} N, in contact {:.3} s from t = {}",
            c["box_displacement_m"].as_f64().unwrap_or(f64::NAN),
            c["box_max_speed"].as_f64().unwrap_or(f64::NAN),
            c["max_contact_force_n"].as_f64().unwrap_or(f64::NAN),
            c["sliding_force_n"].as_f64().map_or("-".into(), |f| format!("{f:.2}")),
            c["coulomb_force_n"].as_f64().unwrap_or(f64::NAN),
            c["contact_time_s"].as_f64().unwrap_or(f64::NAN),
            c["first_contact_s"].as_f64().map_or("-".into(), |t| format!("{t:.3} s")),
        );
    }
    let _ = writeln!(
        s,
        "\nverdict: {}",
        match (
            torque.ok,
            j["collisions"]["collision_free"].as_bool() != Some(false)
        ) {
            (true, true) => "OK: the joints can deliver the motion and nothing collides",
            (false, true) => "NOT OK: joint limits exceeded",
            (true, false) => "NOT OK: collision",
            (false, false) => "NOT OK: joint limits exceeded and collision",
        }
    );
    if let Some(w) = j["warnings"].as_array().filter(|w| !w.is_empty()) {
        let _ = writeln!(s, "warnings:");
        for x in w {
            let _ = writeln!(s, "  {}", x.as_str().unwrap_or(""));
        }
    }
    if let Some(o) = j["outputs"].as_array().filter(|o| !o.is_empty()) {
        let _ = writeln!(s, "outputs:");
        for x in o {
            let _ = writeln!(s, "  {}", x.as_str().unwrap_or(""));
        }
    }
    if let Some(t) = j["timings"].as_object() {
        let list: Vec<String> = t
            .iter()
            .map(|(k, v)| {
                format!(
                    "{} {:.1} ms",
                    k.trim_end_matches("_s"),
                    v.as_f64().unwrap_or(0.0) * 1e3
                )
            })
            .collect();
        let _ = writeln!(s, "timings: {}", list.join(", "));
    }
    s
}
