//! Running an arm scenario end to end: plan the task, check the joint torques it needs
//! with the named effects (for every payload of a sweep), check collisions along it,
//! simulate it with exactly the named effects (with the rapier contact scene only when
//! `contact` is named), write the output files, and assemble the report (JSON + text).

mod arm_report;
mod sim_sample;
mod simulate;
mod write_outputs;

pub use crate::scenarios::arm::run::sim_sample::SimSample;
pub use crate::scenarios::arm::run::write_outputs::obstacle_markers;

use crate::core::diag::LocatedError as ScenarioError;
use crate::core::spatial::Inertia;
use crate::dynamics::{Effects, Payload};
use crate::io::record::mcap_out::wall_clock_ns;
use crate::io::report::Report;
use crate::motion::{check_torques, check_torques_switched, TorqueCheckOptions, TorqueReport};
use crate::scenarios::arm::contact::ContactReport;
use crate::scenarios::arm::scene::Scene;
use crate::scenarios::arm::task_motion::{plan, Plan};
pub use crate::scenarios::kind::RunOptions;
use serde_json::{json, Map, Value};
use std::time::Instant;

/// Everything a run produced, for callers that want more than the report (tests,
/// recordings).
pub struct Outcome {
    /// The validated scenario.
    pub scene: Scene,
    /// The planned motion.
    pub plan: Plan,
    /// The torque check of the motion.
    pub torque: TorqueReport,
    /// `(payload mass, report)` of each sweep entry.
    pub sweep: Vec<(f64, TorqueReport)>,
    /// The recorded simulation samples.
    pub samples: Vec<SimSample>,
    /// What happened in the contact scene, with the `contact` effect.
    pub contact: Option<ContactReport>,
    /// How often each effect's code ran in the simulation.
    pub effect_runs: Option<crate::dynamics::EffectRuns>,
    /// Whether the contact pipeline was built.
    pub contact_built: bool,
    /// The report (JSON and text).
    pub report: Report,
}

fn effects_with_mass(scene: &Scene, mass: f64) -> Result<Effects, String> {
    let mut fx = scene.effects.clone();
    if let Some((link, inertia)) = scene.payload_inertia {
        let i = Inertia::new(mass, inertia.com, inertia.inertia_com);
        fx.payload = Some(Payload::new(&scene.model, link, i).map_err(|e| e.to_string())?);
    }
    Ok(fx)
}

/// Runs a parsed, validated scene: plan, torques, collisions, simulate, record, report.
pub fn run_scene(scene: Scene, opts: &RunOptions) -> Result<Outcome, ScenarioError> {
    if let Some(w) = scene.model_warnings.first().filter(|_| opts.strict) {
        let msg = format!("--strict: {w}");
        return Err(scene.error_at("model.file", msg));
    }
    // The recording's epoch: simulated t = 0 is the run's wall-clock start.
    let started_ns = wall_clock_ns();
    let mut timings = Map::new();
    let mut warnings = scene.warnings.clone();
    warnings.extend(scene.model_warnings.iter().cloned());

    // 1. Plan.
    cancel_point(&scene, opts, "before planning")?;
    let plan = plan(&scene)?;
    crate::scenarios::arm::budget::check(&scene, &plan)?;
    timings.insert("plan_s".into(), json!(plan.planning_time_s));
    for (k, v) in &plan.stages {
        timings.insert(format!("plan_{k}"), v.clone());
    }

    // 2. Torque check (each payload of a sweep; the last is the nominal one).
    cancel_point(&scene, opts, "after planning")?;
    let t0 = Instant::now();
    let (torque, sweep) = check_torque_sweep(&scene, &plan)?;
    timings.insert("torque_check_s".into(), json!(t0.elapsed().as_secs_f64()));

    // 3. Collisions along the planned motion, certified with every limit.
    cancel_point(&scene, opts, "after the torque check")?;
    let t0 = Instant::now();
    let before = warnings.len();
    let (collisions, tool_path) = check_collisions(&scene, &plan, &torque, &mut warnings)?;
    // A collision mesh the check could not use (missing, unreadable) leaves a link
    // unprotected: under --strict that is the model warning it is.
    if let Some(w) = warnings[before..].first().filter(|_| opts.strict) {
        return Err(scene.error_at("model.file", format!("--strict: {w}")));
    }
    timings.insert("collisions_s".into(), json!(t0.elapsed().as_secs_f64()));

    cancel_point(&scene, opts, "after the collision check")?;
    // The output directory and the recording (streamed during the simulation, so an
    // interrupted run still leaves a valid file).
    let (out_dir, mut recorder) = write_outputs::open_recording(&scene, opts, started_ns)?;

    // 4. Simulation with exactly the named effects.
    let sim = simulate::simulate(&scene, &plan, opts, &mut recorder, &mut timings)?;
    // Cancelled during the simulation: `recorder` drops here, removing its temporary file.
    cancel_point(&scene, opts, "during the simulation")?;

    // 5. Output files.
    let ctx = write_outputs::OutputContext {
        scene: &scene,
        plan: &plan,
        torque: &torque,
        collisions: &collisions,
        tool_path: &tool_path,
        samples: &sim.samples,
        sim_json: &sim.sim_json,
        out_dir: &out_dir,
        started_ns,
    };
    let mut outputs: Vec<String> = Vec::new();
    if let Some(rec) = recorder.take() {
        let t0 = Instant::now();
        outputs.push(write_outputs::finish_recording(&ctx, rec)?);
        timings.insert("recording_s".into(), json!(t0.elapsed().as_secs_f64()));
    }
    if let Some(sink) = &opts.rerun {
        let t0 = Instant::now();
        outputs.extend(write_outputs::log_rerun(&ctx, sink, opts, &mut warnings)?);
        timings.insert("rerun_s".into(), json!(t0.elapsed().as_secs_f64()));
    }
    if opts.write_files {
        let t0 = Instant::now();
        outputs.extend(write_outputs::write_files(&ctx)?);
        timings.insert("outputs_s".into(), json!(t0.elapsed().as_secs_f64()));
    }

    // 6. Report.
    let parts = arm_report::Parts {
        sweep: &sweep,
        contact_report: &sim.contact_report,
        contact_built: sim.contact_built,
        timings,
        warnings,
        outputs,
    };
    let json = arm_report::report_json(&ctx, parts);
    let fail = |key: &str, msg: String| scene.error_at(key, msg);
    let text = arm_report::summary(&scene, &plan, &torque, &json);
    if opts.write_files && scene.outputs.report {
        let p = out_dir.join(format!("{}.json", scene.name));
        let body = serde_json::to_string_pretty(&json).expect("json") + "\n";
        crate::core::files::write_atomic(&p, body.as_bytes())
            .map_err(|e| fail("outputs", format!("{}: {e}", p.display())))?;
    }
    let report = Report { json, text };
    Ok(Outcome {
        scene,
        plan,
        torque,
        sweep,
        samples: sim.samples,
        contact: sim.contact_report,
        effect_runs: sim.effect_runs,
        contact_built: sim.contact_built,
        report,
    })
}

/// The run's end when [`RunOptions::cancelled`]: a "cancelled" error naming the stage,
/// before any output file is written.
fn cancel_point(scene: &Scene, opts: &RunOptions, stage: &str) -> Result<(), ScenarioError> {
    if opts.cancelled() {
        return Err(scene.error_at(
            "simulation",
            format!("cancelled {stage} (the stop flag was raised): no output file written"),
        ));
    }
    Ok(())
}

/// The torque check of the planned motion for each payload mass of a sweep: the nominal
/// (last) report, and the sweep's `(mass, report)` pairs (empty without a sweep).
type Sweep = (TorqueReport, Vec<(f64, TorqueReport)>);

fn check_torque_sweep(scene: &Scene, plan: &Plan) -> Result<Sweep, ScenarioError> {
    let model = &scene.model;
    let traj = &plan.trajectory;
    let fail = |key: &str, msg: String| scene.error_at(key, msg);
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
            effects_with_mass(scene, *m).map_err(|e| fail("payload", e))?
        };
        let copts = TorqueCheckOptions {
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
    Ok((torque, sweep))
}

/// The collision report of the planned motion, with its certificate (collisions between
/// samples and every limit's worst margin, see [`crate::scenarios::arm::checks`]), and the tool
/// path it sweeps.
fn check_collisions(
    scene: &Scene,
    plan: &Plan,
    torque: &TorqueReport,
    warnings: &mut Vec<String>,
) -> Result<(Value, Option<crate::io::record::PointCloud>), ScenarioError> {
    let fail = |key: &str, msg: String| scene.error_at(key, msg);
    let jerk = crate::scenarios::arm::checks::jerk_limit(scene);
    let (accel_bound, limits) =
        crate::scenarios::arm::checks::limits_pass(scene, plan, torque, jerk);
    let mut collisions = match &scene.collision {
        None => json!({"checked": false, "certificate": {}}),
        Some(copts) => crate::scenarios::arm::checks::check_collisions(
            scene,
            plan,
            copts,
            &accel_bound,
            warnings,
        )
        .map_err(|e| fail("collision", e))?,
    };
    collisions["certificate"]["limits"] = limits;
    let tool_path = crate::scenarios::arm::checks::planned_tool_path(scene, plan);
    Ok((collisions, tool_path))
}
