//! `[[task.path_constraints]]` of a `type = "plan"` task: each entry becomes a
//! [`PathConstraint`] in the robot's base frame (the planner's), every number checked
//! (finite, in range) and every key that does not apply to its `type` or `shape` refused,
//! each error naming `task.path_constraints[i].key` and its line.
//!
//! - `type = "axis"`: the link's `axis` (link frame) stays within `tolerance` (rad, in
//!   (0, π)) of the scene `direction` (a cup kept upright);
//! - `type = "orientation"`: the link's orientation stays within the geodesic angle
//!   `tolerance` of `rpy` (scene axes);
//! - `type = "position"`: the point `offset` of the link (link frame, default its origin)
//!   stays inside a `shape`: "box" with `size` (full extents), "sphere" with `radius`,
//!   "cylinder" with `radius` and `length` (full, along its z), placed at `xyz`, `rpy`.
//!
//! `link` names the link (default the scenario's tool). Vectors need not be unit (they
//! are normalised) but may not be zero.

use crate::core::diag::{fmt_num, LocatedError as ScenarioError};
use crate::core::spatial::{Se3, Vec3};
use crate::planning::path_constraints::{ConstraintKind, PathConstraint, RegionShape};
use crate::scenarios::arm::scene::section_reader::Sections;
use crate::scenarios::arm::schema::ConstraintSec;
use toml::Spanned;

/// Largest coordinate or size accepted (m).
const MAX_LENGTH: f64 = 1e4;

/// The task's path constraints (none when the key is absent).
pub(super) fn path_constraints(sx: &Sections) -> Result<Vec<PathConstraint>, ScenarioError> {
    let Some(list) = &sx.file.task.get_ref().path_constraints else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    for (i, c) in list.get_ref().iter().enumerate() {
        let at = format!("task.path_constraints[{i}]");
        let pc = one(sx, &at, c)?;
        if let Some(why) = pc.problem(sx.model) {
            return Err(sx.cx.at(c.span(), at, why));
        }
        out.push(pc);
    }
    if out.iter().map(PathConstraint::functions).sum::<usize>()
        > crate::planning::path_constraints::MAX_FUNCTIONS
    {
        return Err(sx.cx.at(
            list.span(),
            "task.path_constraints",
            format!(
                "too many constraints: at most {} scalar conditions (a box counts 3, a cylinder 2, others 1)",
                crate::planning::path_constraints::MAX_FUNCTIONS
            ),
        ));
    }
    Ok(out)
}

/// The keys each kind reads (besides `type` and `link`).
fn keys_of(kind: &str, shape: Option<&str>) -> &'static [&'static str] {
    match (kind, shape) {
        ("axis", _) => &["axis", "direction", "tolerance"],
        ("orientation", _) => &["rpy", "tolerance"],
        (_, Some("box")) => &["offset", "shape", "xyz", "rpy", "size"],
        (_, Some("sphere")) => &["offset", "shape", "xyz", "rpy", "radius"],
        _ => &["offset", "shape", "xyz", "rpy", "radius", "length"],
    }
}

fn one(
    sx: &Sections,
    at: &str,
    c: &Spanned<ConstraintSec>,
) -> Result<PathConstraint, ScenarioError> {
    let cx = &sx.cx;
    let s = c.get_ref();
    let key = |k: &str| format!("{at}.{k}");
    let kind = s.kind.get_ref().as_str();
    if !["axis", "orientation", "position"].contains(&kind) {
        let msg = format!("expected \"axis\", \"orientation\" or \"position\", got {kind:?}");
        return Err(cx.at(s.kind.span(), key("type"), msg));
    }
    let shape = s.shape.as_ref().map(|x| x.get_ref().as_str());
    if let (Some(sh), true) = (&s.shape, kind == "position") {
        if !["box", "sphere", "cylinder"].contains(&sh.get_ref().as_str()) {
            let msg = format!(
                "expected \"box\", \"sphere\" or \"cylinder\", got {:?}",
                sh.get_ref()
            );
            return Err(cx.at(sh.span(), key("shape"), msg));
        }
    }
    let written = [
        ("axis", s.axis.as_ref().map(|v| v.span())),
        ("direction", s.direction.as_ref().map(|v| v.span())),
        ("tolerance", s.tolerance.as_ref().map(|v| v.span())),
        ("rpy", s.rpy.as_ref().map(|v| v.span())),
        ("xyz", s.xyz.as_ref().map(|v| v.span())),
        ("offset", s.offset.as_ref().map(|v| v.span())),
        ("shape", s.shape.as_ref().map(|v| v.span())),
        ("size", s.size.as_ref().map(|v| v.span())),
        ("radius", s.radius.as_ref().map(|v| v.span())),
        ("length", s.length.as_ref().map(|v| v.span())),
    ];
    let allowed = keys_of(kind, shape);
    if let Some((k, Some(span))) = written
        .into_iter()
        .find(|(k, sp)| sp.is_some() && !allowed.contains(k))
    {
        let what = match (kind, shape) {
            ("position", Some(sh)) => format!("a {sh} position constraint"),
            _ => format!("an {kind} constraint").replace("an position", "a position"),
        };
        let msg = format!(
            "does not apply to {what} (it reads type, link, {})",
            allowed.join(", ")
        );
        return Err(cx.at(span, key(k), msg));
    }
    let link = match &s.link {
        None => sx.tool,
        Some(l) => sx.model.link_id(l.get_ref()).ok_or_else(|| {
            cx.at(
                l.span(),
                key("link"),
                format!("no link {:?} in the model", l.get_ref()),
            )
        })?,
    };
    let need = |k: &str| cx.at(c.span(), key(k), format!("a {kind} constraint needs {k}"));
    let rot = sx.base_inv.rot;
    let kind = match kind {
        "axis" => ConstraintKind::Axis {
            axis: direction(
                sx,
                &key("axis"),
                s.axis.as_ref().ok_or_else(|| need("axis"))?,
            )?,
            direction: rot
                * direction(
                    sx,
                    &key("direction"),
                    s.direction.as_ref().ok_or_else(|| need("direction"))?,
                )?,
            tolerance: tolerance(
                sx,
                &key("tolerance"),
                s.tolerance.as_ref().ok_or_else(|| need("tolerance"))?,
            )?,
        },
        "orientation" => {
            let rpy = triple(sx, &key("rpy"), s.rpy.as_ref().ok_or_else(|| need("rpy"))?)?;
            ConstraintKind::Orientation {
                rotation: rot * Se3::from_xyz_rpy([0.0; 3], rpy).rot,
                tolerance: tolerance(
                    sx,
                    &key("tolerance"),
                    s.tolerance.as_ref().ok_or_else(|| need("tolerance"))?,
                )?,
            }
        }
        _ => position(sx, at, c)?,
    };
    Ok(PathConstraint { link, kind })
}

/// A position constraint's region and point.
fn position(
    sx: &Sections,
    at: &str,
    c: &Spanned<ConstraintSec>,
) -> Result<ConstraintKind, ScenarioError> {
    let cx = &sx.cx;
    let s = c.get_ref();
    let key = |k: &str| format!("{at}.{k}");
    let need = |k: &str| cx.at(c.span(), key(k), format!("a position constraint needs {k}"));
    let sh = s.shape.as_ref().ok_or_else(|| need("shape"))?;
    let size = |k: &str, v: Option<&Spanned<f64>>| -> Result<f64, ScenarioError> {
        let v = v.ok_or_else(|| need(k))?;
        positive(sx, &key(k), *v.get_ref(), v.span())
    };
    let shape = match sh.get_ref().as_str() {
        "box" => {
            let v = s.size.as_ref().ok_or_else(|| need("size"))?;
            let mut half = [0.0; 3];
            for (h, x) in half.iter_mut().zip(v.get_ref()) {
                *h = positive(sx, &key("size"), *x, v.span())? / 2.0;
            }
            RegionShape::Box { half }
        }
        "sphere" => RegionShape::Sphere {
            radius: size("radius", s.radius.as_ref())?,
        },
        "cylinder" => RegionShape::Cylinder {
            radius: size("radius", s.radius.as_ref())?,
            half_length: size("length", s.length.as_ref())? / 2.0,
        },
        other => {
            let msg = format!("expected \"box\", \"sphere\" or \"cylinder\", got {other:?}");
            return Err(cx.at(sh.span(), key("shape"), msg));
        }
    };
    let or_zero = |k: &str, v: Option<&Spanned<[f64; 3]>>| match v {
        Some(v) => triple(sx, &key(k), v),
        None => Ok([0.0; 3]),
    };
    let [ox, oy, oz] = or_zero("offset", s.offset.as_ref())?;
    let xyz = or_zero("xyz", s.xyz.as_ref())?;
    let rpy = or_zero("rpy", s.rpy.as_ref())?;
    Ok(ConstraintKind::Position {
        offset: Vec3::new(ox, oy, oz),
        pose: sx.base_inv.mul(&Se3::from_xyz_rpy(xyz, rpy)),
        shape,
    })
}

/// Three finite numbers of magnitude at most [`MAX_LENGTH`].
fn triple(sx: &Sections, key: &str, v: &Spanned<[f64; 3]>) -> Result<[f64; 3], ScenarioError> {
    let x = *v.get_ref();
    if x.iter().all(|a| a.is_finite() && a.abs() <= MAX_LENGTH) {
        Ok(x)
    } else {
        let shown: Vec<String> = x.iter().map(|a| fmt_num(*a)).collect();
        let msg = format!(
            "expected three finite numbers of magnitude at most {MAX_LENGTH:e}, got [{}]",
            shown.join(", ")
        );
        Err(sx.cx.at(v.span(), key, msg))
    }
}

/// A non-zero vector, normalised.
fn direction(sx: &Sections, key: &str, v: &Spanned<[f64; 3]>) -> Result<Vec3, ScenarioError> {
    let [x, y, z] = triple(sx, key, v)?;
    let d = Vec3::new(x, y, z);
    if d.norm() < 1e-9 {
        return Err(sx.cx.at(v.span(), key, "must not be the zero vector"));
    }
    Ok(d / d.norm())
}

/// An angle in (0, π) rad.
fn tolerance(sx: &Sections, key: &str, v: &Spanned<f64>) -> Result<f64, ScenarioError> {
    let t = *v.get_ref();
    if t.is_finite() && t > 0.0 && t < std::f64::consts::PI {
        Ok(t)
    } else {
        let msg = format!("must be an angle in (0, π) rad, got {}", fmt_num(t));
        Err(sx.cx.at(v.span(), key, msg))
    }
}

/// A size in (0, [`MAX_LENGTH`]] m.
fn positive(
    sx: &Sections,
    key: &str,
    x: f64,
    span: std::ops::Range<usize>,
) -> Result<f64, ScenarioError> {
    if x.is_finite() && x > 0.0 && x <= MAX_LENGTH {
        Ok(x)
    } else {
        let msg = format!(
            "must be a size in (0, {MAX_LENGTH:e}] m, got {}",
            fmt_num(x)
        );
        Err(sx.cx.at(span, key, msg))
    }
}
