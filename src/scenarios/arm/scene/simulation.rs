//! The `[trajectory]` timing settings and the `[simulation]` settings (integrator,
//! controller and gains, step, duration, settling time, record rate).

use crate::core::diag::LocatedError as ScenarioError;
use crate::scenarios::arm::scene::arm_scene::SettingLines;
use crate::scenarios::arm::scene::arm_scene::SECTIONS;
use crate::scenarios::arm::scene::arm_scene::{SimSettings, Timing};
use crate::scenarios::arm::scene::section_reader::{get_f, per_joint, positive_all, Sections};
use crate::scenarios::arm::schema::PerJoint;
use crate::scenarios::arm::schema::SimulationSec;
use crate::sim::{Controller, Integrator};
use toml::Spanned;

/// The trajectory settings.
pub(super) struct TrajectorySection {
    pub timing: Timing,
    pub topp_segments: usize,
    pub line_samples: usize,
    pub tool_speed: f64,
    pub tool_acceleration: f64,
    pub check_dt: f64,
}

/// The `[trajectory]` section.
pub(super) fn trajectory(sx: &Sections) -> Result<TrajectorySection, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let trs = file.trajectory.as_ref().map(|t| t.get_ref());
    let timing = match trs.and_then(|t| t.kind.as_ref()) {
        None => Timing::Quintic,
        Some(k) => match k.get_ref().as_str() {
            "trapezoidal" => Timing::Trapezoidal,
            "quintic" => Timing::Quintic,
            "minimum_jerk" => Timing::MinimumJerk,
            "time_optimal" => Timing::TimeOptimal,
            other => {
                return Err(cx.at(
                    k.span(),
                    "trajectory.type",
                    format!("unknown trajectory type '{other}' (expected trapezoidal, quintic, minimum_jerk or time_optimal)"),
                ))
            }
        },
    };
    let usize_in = |v: &Option<Spanned<usize>>, key: &str, d: usize, lo: usize, hi: usize| match v {
        None => Ok(d),
        Some(s) if (lo..=hi).contains(s.get_ref()) => Ok(*s.get_ref()),
        Some(s) => Err(cx.at(s.span(), key, format!("must be between {lo} and {hi}"))),
    };
    let topp_segments = usize_in(
        &trs.and_then(|t| t.segments.clone()),
        "trajectory.segments",
        200,
        10,
        20_000,
    )?;
    let line_samples = usize_in(
        &trs.and_then(|t| t.line_samples.clone()),
        "trajectory.line_samples",
        41,
        4,
        10_000,
    )?;
    let tool_speed = get_f(
        cx,
        &trs.and_then(|t| t.tool_speed.clone()),
        "trajectory.tool_speed",
        0.25,
    )?;
    let tool_acceleration = get_f(
        cx,
        &trs.and_then(|t| t.tool_acceleration.clone()),
        "trajectory.tool_acceleration",
        1.0,
    )?;
    let check_dt = get_f(
        cx,
        &trs.and_then(|t| t.check_dt.clone()),
        "trajectory.check_dt",
        1e-3,
    )?;
    Ok(TrajectorySection {
        timing,
        topp_segments,
        line_samples,
        tool_speed,
        tool_acceleration,
        check_dt,
    })
}

/// The `[simulation]` section (`None` when disabled); implicit integration by default
/// for an elastic model.
pub(super) fn simulation(
    sx: &Sections,
    effects: &crate::dynamics::Effects,
) -> Result<Option<SimSettings>, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let ssec = file.simulation.as_ref().map(|s| s.get_ref());
    if !ssec.is_none_or(|s| s.enabled) {
        return Ok(None);
    }
    let elastic = effects.elasticity.is_some();
    let integrator = match ssec.and_then(|s| s.integrator.as_ref()) {
        None if elastic => Integrator::Implicit,
        None => Integrator::Rk4,
        Some(i) => match i.get_ref().as_str() {
            "semi_implicit_euler" => Integrator::SemiImplicitEuler,
            "rk4" => Integrator::Rk4,
            "implicit" => Integrator::Implicit,
            other => {
                return Err(cx.at(
                    i.span(),
                    "simulation.integrator",
                    format!(
                    "unknown integrator '{other}' (expected semi_implicit_euler, rk4 or implicit)"
                ),
                ))
            }
        },
    };
    let controller = controller(sx, ssec)?;
    let dt = get_f(cx, &ssec.and_then(|s| s.dt.clone()), "simulation.dt", 1e-3)?;
    if dt > 0.1 {
        let sp = ssec
            .and_then(|s| s.dt.as_ref())
            .map(|d| d.span())
            .unwrap_or(0..0);
        return Err(cx.at(
            sp,
            "simulation.dt",
            format!("step {dt} s is too large (at most 0.1 s)"),
        ));
    }
    let duration = match ssec.and_then(|s| s.duration.as_ref()) {
        None => None,
        Some(d) => Some(get_f(cx, &Some(d.clone()), "simulation.duration", 0.0)?),
    };
    let settle = match ssec.and_then(|s| s.settle.as_ref()) {
        None => 0.5,
        Some(s) if s.get_ref().is_finite() && *s.get_ref() >= 0.0 => *s.get_ref(),
        Some(s) => return Err(cx.at(s.span(), "simulation.settle", "must be finite and >= 0")),
    };
    let lines = setting_lines(sx);
    if let Err((key, msg)) =
        crate::scenarios::arm::budget::check_settings(dt, duration, settle, &lines)
    {
        let sp = match key {
            "simulation.duration" => ssec.and_then(|s| s.duration.as_ref()),
            "simulation.dt" => ssec.and_then(|s| s.dt.as_ref()),
            _ => ssec.and_then(|s| s.settle.as_ref()),
        };
        let line = sp.map(|s| cx.line(&s.span())).or(lines.settle);
        return Err(ScenarioError::new(cx.file, line, key, msg));
    }
    let record_rate = get_f(
        cx,
        &ssec.and_then(|s| s.record_rate.clone()),
        "simulation.record_rate",
        100.0,
    )?;
    Ok(Some(SimSettings {
        controller,
        integrator,
        dt,
        duration,
        settle,
        record_rate,
    }))
}

/// The controller and its gains.
fn controller(sx: &Sections, ssec: Option<&SimulationSec>) -> Result<Controller, ScenarioError> {
    let cx = &sx.cx;
    let names = &sx.names;
    let n = sx.n;
    let ctrl_name = ssec
        .and_then(|s| s.controller.as_ref())
        .map(|c| (c.get_ref().as_str(), c.span()))
        .unwrap_or(("computed_torque", 0..0));
    let gains = |v: Option<&PerJoint>, key: &str, d: f64| -> Result<Vec<f64>, ScenarioError> {
        match v {
            None => Ok(vec![d; n]),
            Some(v) => {
                let g = per_joint(cx, v, key, names, &vec![d; n])?;
                positive_all(cx, v, key, names, &g, true)?;
                Ok(g)
            }
        }
    };
    let (kp, kd) = (
        ssec.and_then(|s| s.kp.as_ref()),
        ssec.and_then(|s| s.kd.as_ref()),
    );
    let controller = match ctrl_name.0 {
        "computed_torque" => Controller::ComputedTorque {
            kp: gains(kp, "simulation.kp", 400.0)?,
            kd: gains(kd, "simulation.kd", 40.0)?,
        },
        "pd_gravity" => Controller::PdGravity {
            kp: gains(kp, "simulation.kp", 800.0)?,
            kd: gains(kd, "simulation.kd", 40.0)?,
        },
        "none" => Controller::None,
        other => {
            return Err(cx.at(
                ctrl_name.1,
                "simulation.controller",
                format!(
                    "unknown controller '{other}' (expected computed_torque, pd_gravity or none)"
                ),
            ))
        }
    };
    Ok(controller)
}

/// Where the settings that set the amount of work are written.
pub(super) fn setting_lines(sx: &Sections) -> SettingLines {
    let cx = &sx.cx;
    let line = |v: Option<&Spanned<f64>>| v.map(|s| cx.line(&s.span()));
    let ssec = sx.file.simulation.as_ref().map(|s| s.get_ref());
    let tsec = sx.file.trajectory.as_ref().map(|t| t.get_ref());
    let section = cx.section("simulation", "").line;
    SettingLines {
        dt: line(ssec.and_then(|s| s.dt.as_ref())),
        settle: line(ssec.and_then(|s| s.settle.as_ref())).or(section),
        record_rate: line(ssec.and_then(|s| s.record_rate.as_ref())),
        check_dt: line(tsec.and_then(|t| t.check_dt.as_ref())),
        sections: SECTIONS.map(|name| cx.section(name, "").line),
    }
}
