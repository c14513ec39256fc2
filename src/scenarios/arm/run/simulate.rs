//! Step 4 of a run: the simulation of the planned motion with exactly the named effects
//! (the rapier contact scene only when `contact` is named), streamed into the recording,
//! and its summary (tracking, residual vibration, energy audit, effect runs).

use crate::core::diag::LocatedError as ScenarioError;
use crate::dynamics::EffectRuns;
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::motion::{AsReference, Trajectory};
use crate::scenarios::arm::checks::named;
use crate::scenarios::arm::contact::{ContactReport, ContactSim};
use crate::scenarios::arm::run::sim_sample::SimSample;
use crate::scenarios::arm::run::write_outputs::Recorder;
use crate::scenarios::arm::scene::{Scene, SimSettings};
use crate::scenarios::arm::task_motion::Plan;
use crate::scenarios::kind::RunOptions;
use crate::sim::{SimConfig, SimReport, Simulator, StepHook};
use serde_json::{json, Map, Value};
use std::time::Instant;

/// What the simulation step produced.
pub(super) struct SimOut {
    pub samples: Vec<SimSample>,
    pub sim_json: Value,
    pub contact_report: Option<ContactReport>,
    pub effect_runs: Option<EffectRuns>,
    pub contact_built: bool,
}

/// Simulates the scene when `[simulation]` is enabled (else an empty result).
pub(super) fn simulate(
    scene: &Scene,
    plan: &Plan,
    opts: &RunOptions,
    recorder: &mut Option<Recorder>,
    timings: &mut Map<String, Value>,
) -> Result<SimOut, ScenarioError> {
    let mut out = SimOut {
        samples: Vec::new(),
        sim_json: Value::Null,
        contact_report: None,
        effect_runs: None,
        contact_built: false,
    };
    if let Some(ss) = &scene.simulation {
        let t0 = Instant::now();
        let (sim_report, runs) = run_simulation(scene, plan, opts, ss, recorder, &mut out)?;
        out.sim_json = simulation_json(scene, plan, ss, &sim_report, &out.samples, runs);
        timings.insert("simulation_s".into(), json!(t0.elapsed().as_secs_f64()));
    }
    Ok(out)
}

/// Runs the simulator (and the contact scene), recording samples into `out`.
fn run_simulation(
    scene: &Scene,
    plan: &Plan,
    opts: &RunOptions,
    ss: &SimSettings,
    recorder: &mut Option<Recorder>,
    out: &mut SimOut,
) -> Result<(SimReport, EffectRuns), ScenarioError> {
    let model = &scene.model;
    let traj = &plan.trajectory;
    let duration = traj.duration();
    let fail = |key: &str, msg: String| scene.error_at(key, msg);
    let samples = &mut out.samples;
    let mut contact_built = false;
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
    let stop_fn = || opts.stop_requested();
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
    struct Interrupt<'o>(&'o RunOptions);
    impl StepHook for Interrupt<'_> {
        fn before_step(
            &mut self,
            _t: f64,
            _q: &[f64],
            _qd: &[f64],
            _w: &mut Vec<crate::dynamics::ExternalWrench>,
        ) -> bool {
            !self.0.stop_requested()
        }
    }
    let mut interrupt = Interrupt(opts);
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
    out.effect_runs = Some(sim.effect_runs());
    let sim_report = match result {
        Ok(r) => r,
        Err(e) => {
            return Err(fail(
                "simulation",
                format!("{e} (the planned motion, torque check and collision check passed; the simulation settings did not)"),
            ))
        }
    };
    out.contact_report = contact.as_ref().map(|c| c.report());
    out.contact_built = contact_built;
    let runs = sim.effect_runs();
    Ok((sim_report, runs))
}

/// The simulation's part of the report.
fn simulation_json(
    scene: &Scene,
    plan: &Plan,
    ss: &SimSettings,
    sim_report: &SimReport,
    samples: &[SimSample],
    runs: EffectRuns,
) -> Value {
    let model = &scene.model;
    let names = model.dof_names();
    let n = model.nv;
    let duration = plan.trajectory.duration();
    // Tracking and residual vibration.
    let mut data = Data::new(model);
    let mut tool_err_max: f64 = 0.0;
    let mut tool_err_settle: f64 = 0.0;
    let mut settle_err = vec![0.0f64; n];
    let mut peak_tau = vec![0.0f64; n];
    for s in samples {
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
                (el.stiffness[k] * (1.0 / el.motor_inertia[k] + 1.0 / m[(k, k)].max(1e-12))).sqrt()
                    / (2.0 * std::f64::consts::PI)
            })
            .collect();
        named(&names, &f)
    });
    let vib = vibration_frequency(samples, duration);
    json!({
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
