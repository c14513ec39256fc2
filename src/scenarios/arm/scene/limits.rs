//! The `[limits]` section (position limits inside the model's, velocity scale, velocity,
//! acceleration and effort limits) and the `[initial]` configuration inside them.

use crate::core::diag::LocatedError as ScenarioError;
use crate::motion::JointLimits;
use crate::scenarios::arm::scene::section_reader::{
    per_joint, positive_all, to_radians_if, Sections,
};
use crate::scenarios::arm::schema::PerJoint;
use crate::scenarios::source::Source;

/// Largest joint acceleration limit a scene accepts (rad/s², or m/s² for a prismatic
/// joint): a hundred times an industrial arm's.
pub const MAX_ACCELERATION: f64 = 1000.0;

/// The position limits: the model's, narrowed by `limits.lower`/`limits.upper`.
pub(super) fn position_limits(sx: &Sections) -> Result<(Vec<f64>, Vec<f64>), ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let names = &sx.names;
    let n = sx.n;
    let lsec = file.limits.as_ref().map(|l| l.get_ref());
    let mut lower = model.lower.clone();
    let mut upper = model.upper.clone();
    if let Some(l) = lsec {
        for (v, key, dst, model_lim, is_lower) in [
            (&l.lower, "limits.lower", &mut lower, &model.lower, true),
            (&l.upper, "limits.upper", &mut upper, &model.upper, false),
        ] {
            if let Some(v) = v {
                let vals = per_joint(cx, v, key, names, model_lim)?;
                for k in 0..n {
                    let outside = if is_lower {
                        vals[k] < model_lim[k]
                    } else {
                        vals[k] > model_lim[k]
                    };
                    if outside {
                        return Err(cx.at(
                            v.span(),
                            key,
                            format!(
                                "joint {}: {} is outside the model's range [{}, {}]",
                                names[k], vals[k], model.lower[k], model.upper[k]
                            ),
                        ));
                    }
                }
                *dst = vals;
            }
        }
    }
    for k in 0..n {
        if lower[k] >= upper[k] {
            let span = lsec
                .and_then(|l| l.lower.as_ref().or(l.upper.as_ref()))
                .map(|v| v.span())
                .unwrap_or(0..0);
            return Err(cx.at(
                span,
                "limits.lower",
                format!(
                    "joint {}: lower limit {} is not below the upper limit {}",
                    names[k], lower[k], upper[k]
                ),
            ));
        }
    }
    Ok((lower, upper))
}

/// The rate limits: planning limits (velocity scaled), and the velocity and effort the
/// torque check judges against.
pub(super) fn rate_limits(sx: &Sections) -> Result<RateLimits, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let names = &sx.names;
    let lsec = file.limits.as_ref().map(|l| l.get_ref());
    let scale = match lsec.and_then(|l| l.velocity_scale.as_ref()) {
        None => 1.0,
        Some(s) if *s.get_ref() > 0.0 && *s.get_ref() <= 1.0 => *s.get_ref(),
        Some(s) => {
            return Err(cx.at(
                s.span(),
                "limits.velocity_scale",
                format!("must be in (0, 1] (got {})", s.get_ref()),
            ))
        }
    };
    let velocity_in = lsec.and_then(|l| l.velocity.as_ref());
    let mut velocity = within_model(cx, velocity_in, "velocity", names, &model.velocity_limit)?;
    if let Some(k) = velocity.iter().position(|v| !v.is_finite()) {
        let span = file
            .limits
            .as_ref()
            .map(|l| l.span())
            .unwrap_or(file.model.span());
        return Err(cx.at(
            span,
            "limits.velocity",
            format!(
                "joint {}: the model gives no velocity limit; set limits.velocity",
                names[k]
            ),
        ));
    }
    let check_velocity = velocity.clone();
    for v in &mut velocity {
        *v *= scale;
    }
    let default_acc: Vec<f64> = velocity.iter().map(|v| 4.0 * v).collect();
    let acceleration = match lsec.and_then(|l| l.acceleration.as_ref()) {
        Some(v) => {
            let vals = per_joint(cx, v, "limits.acceleration", names, &default_acc)?;
            positive_all(cx, v, "limits.acceleration", names, &vals, false)?;
            if let Some(k) = vals.iter().position(|a| *a > MAX_ACCELERATION) {
                return Err(cx.at(
                    v.span(),
                    "limits.acceleration",
                    format!(
                        "joint {}: at most {MAX_ACCELERATION} rad/s² (m/s²) is accepted, got {}: \
                         beyond any arm, and the motion's collision certificate subdivides \
                         with it",
                        names[k], vals[k]
                    ),
                ));
            }
            vals
        }
        None => default_acc,
    };
    let effort_in = lsec.and_then(|l| l.effort.as_ref());
    let effort = within_model(cx, effort_in, "effort", names, &model.effort_limit)?;
    let jerk = match lsec.and_then(|l| l.jerk.as_ref()) {
        Some(v) => Some(jerk_limits(cx, v, names)?),
        None => None,
    };
    let limits = JointLimits {
        velocity,
        acceleration,
        effort: effort.clone(),
        jerk,
    };
    Ok(RateLimits {
        limits,
        check_velocity,
        effort,
    })
}

/// `limits.jerk`: finite and positive values; a joint a table leaves out has none.
fn jerk_limits(cx: &Source, v: &PerJoint, names: &[String]) -> Result<Vec<f64>, ScenarioError> {
    let mut vals = per_joint(cx, v, "limits.jerk", names, &vec![1.0; names.len()])?;
    for (k, x) in vals.iter_mut().enumerate() {
        if let toml::Value::Table(t) = v.get_ref() {
            if !t.contains_key(&names[k]) {
                *x = f64::INFINITY;
                continue;
            }
        }
        if !(x.is_finite() && *x > 0.0) {
            return Err(cx.at(
                v.span(),
                "limits.jerk",
                format!("joint {}: must be finite and > 0 (got {x})", names[k]),
            ));
        }
    }
    Ok(vals)
}

/// `limits.jerk` applies only where the timing is TOPP's: time-optimal joint and line
/// motion, or planned motion. Refused otherwise, at its line.
pub(super) fn jerk_applies(
    sx: &Sections,
    time_optimal: bool,
    plans: bool,
) -> Result<(), ScenarioError> {
    let jerk = sx
        .file
        .limits
        .as_ref()
        .and_then(|l| l.get_ref().jerk.as_ref());
    match jerk {
        Some(v) if !time_optimal && !plans => Err(sx.cx.at(
            v.span(),
            "limits.jerk",
            "a jerk limit applies only to time-optimal timing (trajectory.type = \"time_optimal\") \
             or planned motion; this scenario has neither",
        )),
        _ => Ok(()),
    }
}

/// What [`rate_limits`] returns.
pub(super) struct RateLimits {
    pub limits: JointLimits,
    pub check_velocity: Vec<f64>,
    pub effort: Vec<f64>,
}

/// The initial configuration (`[initial]`, degrees allowed), inside the limits; the
/// neutral pose clamped into them by default.
pub(super) fn initial(
    sx: &Sections,
    lower: &[f64],
    upper: &[f64],
) -> Result<Vec<f64>, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let names = &sx.names;
    let n = sx.n;
    let deg = |x: f64, k: usize, degrees: bool| to_radians_if(model, x, k, degrees);
    let neutral: Vec<f64> = (0..n).map(|k| 0.0f64.clamp(lower[k], upper[k])).collect();
    let q0 = match &file.initial {
        Some(init) => {
            let s = init.get_ref();
            let raw_default: Vec<f64> = neutral
                .iter()
                .enumerate()
                .map(|(k, x)| {
                    if s.degrees && deg(1.0, k, true) != 1.0 {
                        x.to_degrees()
                    } else {
                        *x
                    }
                })
                .collect();
            let vals = per_joint(cx, &s.q, "initial.q", names, &raw_default)?;
            let q: Vec<f64> = vals
                .iter()
                .enumerate()
                .map(|(k, x)| deg(*x, k, s.degrees))
                .collect();
            check_in_limits(cx, &s.q, "initial.q", names, &q, lower, upper)?;
            q
        }
        None => neutral.clone(),
    };
    Ok(q0)
}

pub(super) fn check_in_limits(
    cx: &Source,
    v: &PerJoint,
    key: &str,
    names: &[String],
    q: &[f64],
    lower: &[f64],
    upper: &[f64],
) -> Result<(), ScenarioError> {
    for k in 0..q.len() {
        if q[k] < lower[k] - 1e-9 || q[k] > upper[k] + 1e-9 {
            return Err(cx.at(
                v.span(),
                key,
                format!(
                    "joint {}: {} is outside the limits [{}, {}]",
                    names[k], q[k], lower[k], upper[k]
                ),
            ));
        }
    }
    Ok(())
}

/// `limits.<what>`: the model's limits, or the given positive values, none above the
/// model's (a scenario may only be more careful than its robot).
fn within_model(
    cx: &Source,
    given: Option<&PerJoint>,
    what: &str,
    names: &[String],
    model_limit: &[f64],
) -> Result<Vec<f64>, ScenarioError> {
    let Some(v) = given else {
        return Ok(model_limit.to_vec());
    };
    let key = format!("limits.{what}");
    let vals = per_joint(cx, v, &key, names, model_limit)?;
    positive_all(cx, v, &key, names, &vals, false)?;
    for (k, (x, m)) in vals.iter().zip(model_limit).enumerate() {
        if x > m {
            return Err(cx.at(
                v.span(),
                &key,
                format!(
                    "joint {}: {x} exceeds the model's {what} limit {m}",
                    names[k]
                ),
            ));
        }
    }
    Ok(vals)
}
