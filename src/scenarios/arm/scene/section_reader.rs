//! What the section readers share: the [`Sections`] they read from (the file, the model,
//! its coordinate names, the tool and the base pose) and the readers of per-joint values,
//! positive numbers and poses, each error naming the file, the line and the key.

pub(super) use crate::core::diag::finite_positive as finite_pos;
use crate::core::diag::LocatedError as ScenarioError;
use crate::core::spatial::Se3;
use crate::model::Model;
use crate::scenarios::arm::schema::{ArmFile, PerJoint, PoseSec};
use crate::scenarios::source::Source;
use std::path::Path;
use toml::Spanned;

/// What the sections after `[model]` read: the file, the model, its coordinate names,
/// the tool and the base pose.
pub(super) struct Sections<'a> {
    pub(super) cx: Source<'a>,
    /// The scenario file, as the user named it.
    pub(super) file: &'a ArmFile,
    pub(super) dir: &'a Path,
    /// The compiled model.
    pub(super) model: &'a Model,
    pub(super) names: Vec<String>,
    pub(super) n: usize,
    /// The tool frame.
    pub(super) tool: usize,
    /// The robot base pose in scene axes.
    pub(super) base: Se3,
    pub(super) base_inv: Se3,
}

/// `x` in radians when `degrees` is set and coordinate `k` turns (prismatic joints keep
/// their metres).
pub(super) fn to_radians_if(model: &Model, x: f64, k: usize, degrees: bool) -> f64 {
    if degrees && model.dof_joint(k).jtype != crate::model::JointType::Prismatic {
        x.to_radians()
    } else {
        x
    }
}

/// Reads a per-joint value: a number for all, a list in joint order, or a table by joint
/// name over `default`.
pub fn per_joint(
    cx: &Source,
    v: &PerJoint,
    key: &str,
    names: &[String],
    default: &[f64],
) -> Result<Vec<f64>, ScenarioError> {
    let n = names.len();
    let num = |x: &toml::Value| -> Option<f64> {
        match x {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        }
    };
    let out = match v.get_ref() {
        toml::Value::Array(a) => {
            if a.len() != n {
                return Err(cx.at(
                    v.span(),
                    key,
                    format!("{} values for {n} joints ({})", a.len(), names.join(", ")),
                ));
            }
            a.iter()
                .enumerate()
                .map(|(k, x)| {
                    num(x).ok_or_else(|| {
                        cx.at(
                            v.span(),
                            key,
                            format!("value {k} (joint {}) is not a number", names[k]),
                        )
                    })
                })
                .collect::<Result<Vec<_>, _>>()?
        }
        toml::Value::Table(t) => {
            let mut out = default.to_vec();
            for (name, x) in t {
                let k = names.iter().position(|j| j == name).ok_or_else(|| {
                    let hint = closest(name, names)
                        .map(|c| format!(" (did you mean '{c}'?)"))
                        .unwrap_or_default();
                    cx.at(
                        v.span(),
                        format!("{key}.{name}"),
                        format!(
                            "unknown joint '{name}'{hint}; the joints are: {}",
                            names.join(", ")
                        ),
                    )
                })?;
                out[k] = num(x)
                    .ok_or_else(|| cx.at(v.span(), format!("{key}.{name}"), "expected a number"))?;
            }
            out
        }
        x => match num(x) {
            Some(f) => vec![f; n],
            None => {
                return Err(cx.at(
                    v.span(),
                    key,
                    format!(
                        "expected a number, a list of {n} numbers or a table by joint name, got {}",
                        x.type_str()
                    ),
                ))
            }
        },
    };
    if let Some(k) = out.iter().position(|x| !x.is_finite()) {
        return Err(cx.at(
            v.span(),
            key,
            format!("joint {}: the value is not finite", names[k]),
        ));
    }
    Ok(out)
}

/// The name in `names` closest to `name` (edit distance ≤ 3), for "did you mean".
pub(super) fn closest<'a>(name: &str, names: &'a [String]) -> Option<&'a str> {
    fn dist(a: &str, b: &str) -> usize {
        let b: Vec<char> = b.chars().collect();
        let mut prev: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.chars().enumerate() {
            let mut cur = vec![i + 1; b.len() + 1];
            for (j, cb) in b.iter().enumerate() {
                cur[j + 1] = (prev[j] + usize::from(ca != *cb))
                    .min(prev[j + 1] + 1)
                    .min(cur[j] + 1);
            }
            prev = cur;
        }
        prev[b.len()]
    }
    names
        .iter()
        .map(|n| (dist(name, n), n))
        .filter(|(d, _)| *d <= 3)
        .min_by_key(|(d, _)| *d)
        .map(|(_, n)| n.as_str())
}

/// `v` read per joint ([`per_joint`], `default` where absent) and checked `> 0` (`≥ 0`
/// with `allow_zero`); `default` itself when `v` is absent.
pub(super) fn per_joint_checked(
    cx: &Source,
    v: Option<&PerJoint>,
    key: &str,
    names: &[String],
    default: &[f64],
    allow_zero: bool,
) -> Result<Vec<f64>, ScenarioError> {
    let Some(v) = v else {
        return Ok(default.to_vec());
    };
    let vals = per_joint(cx, v, key, names, default)?;
    positive_all(cx, v, key, names, &vals, allow_zero)?;
    Ok(vals)
}

pub(super) fn positive_all(
    cx: &Source,
    v: &PerJoint,
    key: &str,
    names: &[String],
    vals: &[f64],
    allow_zero: bool,
) -> Result<(), ScenarioError> {
    for (k, x) in vals.iter().enumerate() {
        if *x < 0.0 || (!allow_zero && *x == 0.0) {
            return Err(cx.at(
                v.span(),
                key,
                format!(
                    "joint {}: must be {} (got {x})",
                    names[k],
                    if allow_zero { ">= 0" } else { "> 0" }
                ),
            ));
        }
    }
    Ok(())
}

pub(super) fn pose_of(p: &PoseSec) -> Se3 {
    Se3::from_xyz_rpy(p.xyz, p.rpy)
}

pub(super) fn finite_pose(p: &PoseSec) -> bool {
    p.xyz.iter().chain(p.rpy.iter()).all(|x| x.is_finite())
}

pub(super) fn get_f(
    cx: &Source,
    v: &Option<Spanned<f64>>,
    key: &str,
    default: f64,
) -> Result<f64, ScenarioError> {
    match v {
        None => Ok(default),
        Some(s) if finite_pos(*s.get_ref()) => Ok(*s.get_ref()),
        Some(s) => Err(cx.at(
            s.span(),
            key,
            format!(
                "must be finite and positive (got {})",
                crate::core::diag::fmt_num(*s.get_ref())
            ),
        )),
    }
}
