//! The work budgets of an arm run (RELIABILITY.md, "Value ranges and work budgets"): how
//! many simulation steps, recorded samples and dense check samples a run may take. The
//! motion's duration is known only once the task is planned, so [`check`] runs between
//! planning and the first sampled pass; [`check_settings`] catches what the settings
//! alone already exceed while the file is read (also for `armsim::scenarios::check`).
//!
//! A run over budget is refused naming the key that sets the work: the step or rate when
//! it was written and the motion alone would fit, else `simulation.settle` when settling
//! is the longer part, else the task step that lasts longest (its timing comes from the
//! limits, `trajectory.tool_speed` or a dwell).

use crate::core::diag::LocatedError as ScenarioError;
use crate::motion::Trajectory;
use crate::scenarios::arm::scene::arm_scene::Scene;
pub use crate::scenarios::arm::scene::arm_scene::SettingLines;
use crate::scenarios::arm::task_motion::Plan;

/// At most this many simulation steps (simulated time / `simulation.dt`).
pub const MAX_SIM_STEPS: f64 = 5e7;
/// At most this many recorded simulation samples (simulated time × the record rate).
pub const MAX_RECORDED: f64 = 1e7;
/// At most this many samples of the dense torque, limits and CSV passes (motion duration
/// / `trajectory.check_dt`).
pub const MAX_CHECK_SAMPLES: f64 = 1e7;

/// The default step of the dense checks (s).
pub const DEFAULT_CHECK_DT: f64 = 1e-3;
/// The default simulation step (s).
pub const DEFAULT_SIM_DT: f64 = 1e-3;

/// `x` in the messages: plain for ordinary magnitudes, else in `e` notation.
pub fn num(x: f64) -> String {
    crate::core::diag::fmt_num(x)
}

/// The task step that lasts longest: `(key, line, duration)`.
fn longest_step(scene: &Scene, plan: &Plan) -> (String, Option<usize>, f64) {
    let p = plan
        .pieces
        .iter()
        .filter(|p| !p.duration_s.is_nan())
        .max_by(|a, b| a.duration_s.total_cmp(&b.duration_s));
    match p {
        Some(p) => {
            let line = scene
                .steps
                .iter()
                .find(|s| s.key == p.from)
                .and_then(|s| s.line);
            (p.from.clone(), line, p.duration_s)
        }
        None => ("task".into(), None, f64::NAN),
    }
}

/// The error at the longest task step, `what` saying what would be too much.
fn at_longest(scene: &Scene, plan: &Plan, what: String) -> ScenarioError {
    let (key, line, d) = longest_step(scene, plan);
    ScenarioError::new(
        &scene.file,
        line,
        key,
        format!(
            "this step lasts {} s: {what} (its timing comes from the joint limits, \
             trajectory.tool_speed and tool_acceleration, or the dwell)",
            num(d)
        ),
    )
}

/// Refuses a planned run whose dense checks or simulation would exceed the budgets,
/// before any of them starts.
pub fn check(scene: &Scene, plan: &Plan) -> Result<(), ScenarioError> {
    let d = plan.trajectory.duration();
    let lines = &scene.setting_lines;
    let err = |line, key: &str, msg: String| ScenarioError::new(&scene.file, line, key, msg);
    if !d.is_finite() {
        return Err(at_longest(
            scene,
            plan,
            "the motion's duration is not finite".into(),
        ));
    }
    let samples = d / scene.check_dt;
    if samples > MAX_CHECK_SAMPLES {
        let what = format!(
            "the torque and limit checks would take {} samples of trajectory.check_dt = {} s \
             over the {} s motion, more than the budget of {}",
            num(samples),
            num(scene.check_dt),
            num(d),
            num(MAX_CHECK_SAMPLES)
        );
        return Err(match lines.check_dt {
            Some(l) if d / DEFAULT_CHECK_DT <= MAX_CHECK_SAMPLES => err(
                Some(l),
                "trajectory.check_dt",
                format!("{what}: raise the step"),
            ),
            _ => at_longest(scene, plan, what),
        });
    }
    let Some(ss) = &scene.simulation else {
        return Ok(());
    };
    if ss.duration.is_some() {
        return Ok(()); // checked with the settings
    }
    let total = d + ss.settle;
    let steps = total / ss.dt;
    let every = ((1.0 / (ss.record_rate * ss.dt)).round()).max(1.0);
    let recorded = steps / every;
    let (what, fits_default, line, key) = if steps > MAX_SIM_STEPS {
        (
            format!(
                "the simulation would take {} steps of simulation.dt = {} s over {} s \
                 (motion {} s + settle {} s), more than the budget of {}",
                num(steps),
                num(ss.dt),
                num(total),
                num(d),
                num(ss.settle),
                num(MAX_SIM_STEPS)
            ),
            total / DEFAULT_SIM_DT <= MAX_SIM_STEPS,
            lines.dt,
            "simulation.dt",
        )
    } else if recorded > MAX_RECORDED {
        (
            format!(
                "the simulation would record {} samples over {} s (motion {} s + settle {} s), \
                 more than the budget of {}",
                num(recorded),
                num(total),
                num(d),
                num(ss.settle),
                num(MAX_RECORDED)
            ),
            total * 100.0 <= MAX_RECORDED,
            lines.record_rate,
            "simulation.record_rate",
        )
    } else {
        return Ok(());
    };
    Err(match line {
        Some(l) if fits_default => err(Some(l), key, format!("{what}: raise it")),
        _ if ss.settle > d => err(
            lines.settle,
            "simulation.settle",
            format!("{what}: shorten it"),
        ),
        _ => at_longest(scene, plan, what),
    })
}

/// What the settings alone exceed (the motion counted as zero): `settle / dt` steps, or
/// `duration / dt` when the duration is written; `Err((key, message))`, the key being
/// `simulation.duration`, `simulation.dt` or `simulation.settle`.
pub fn check_settings(
    dt: f64,
    duration: Option<f64>,
    settle: f64,
    lines: &SettingLines,
) -> Result<(), (&'static str, String)> {
    let (total, key) = match duration {
        Some(d) => (d, "simulation.duration"),
        None if lines.dt.is_some() && settle / DEFAULT_SIM_DT <= MAX_SIM_STEPS => {
            (settle, "simulation.dt")
        }
        None => (settle, "simulation.settle"),
    };
    let steps = total / dt;
    if steps > MAX_SIM_STEPS {
        return Err((
            key,
            format!(
                "the simulation would take at least {} steps ({} s at simulation.dt = {} s), \
                 more than the budget of {}: shorten it or raise the step",
                num(steps.floor()),
                num(total),
                num(dt),
                num(MAX_SIM_STEPS)
            ),
        ));
    }
    Ok(())
}
