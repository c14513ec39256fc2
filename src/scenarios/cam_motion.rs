//! The `[motion]` section of `kind = "cam"` files (`docs/machines.md`): a dwell–rise–
//! dwell–return law with its timing, or a table (`table = "displacement" | "velocity" |
//! "acceleration"` with `points`), for a translating (`stroke`, mm) or an oscillating
//! (`swing_deg`) follower.

use crate::core::diag::LocatedError as ScenarioError;
use crate::machines::cams::laws::{Law, MotionLaw};
use crate::machines::cams::motion_table::{CamMotion, MotionTable, TableKind};
use crate::scenarios::source::{in_range, Source};
use serde::Deserialize;
use toml::Spanned;

/// Most points of a motion table.
pub const MAX_TABLE_POINTS: usize = 10_000;

/// The keys of `[motion]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    stroke: Option<f64>,
    swing_deg: Option<f64>,
    rise_deg: Option<f64>,
    dwell_top_deg: Option<f64>,
    return_deg: Option<f64>,
    law: Option<String>,
    return_law: Option<String>,
    table: Option<String>,
    points: Option<Vec<[f64; 2]>>,
}

/// The follower's motion of a `[motion]` section; `moving` is the follower's
/// `translating` or `oscillating`.
pub fn motion(
    cx: &Source,
    ms: &Spanned<MotionSpec>,
    moving: &str,
) -> Result<CamMotion, ScenarioError> {
    let m = ms.get_ref();
    let err = |k: &str, msg: String| cx.field(ms.span(), k, format!("motion.{k}"), msg);
    match &m.table {
        Some(t) => table(m, t, moving, &err).map(CamMotion::Table),
        None => {
            if m.points.is_some() {
                return Err(err(
                    "points",
                    "applies only to a `table` (displacement, velocity or acceleration)".into(),
                ));
            }
            law(m, moving, &err).map(CamMotion::Law)
        }
    }
}

type KeyErr<'a> = dyn Fn(&str, String) -> ScenarioError + 'a;

/// The lift: `stroke` (translating) or `swing_deg` (oscillating, rad), each refused for
/// the other follower; `None` when neither is given and `optional`.
fn lift(
    m: &MotionSpec,
    moving: &str,
    optional: bool,
    err: &KeyErr,
) -> Result<Option<f64>, ScenarioError> {
    match (moving, m.stroke, m.swing_deg) {
        ("translating", Some(h), None) if in_range(h, 1e-9, 1e7) => Ok(Some(h)),
        ("translating", Some(h), None) => {
            Err(err("stroke", format!("must be a positive lift, got {h}")))
        }
        ("translating", None, None) if optional => Ok(None),
        ("translating", _, _) => Err(err(
            "stroke",
            "a translating follower needs `stroke` (mm), not `swing_deg`".into(),
        )),
        (_, None, Some(s)) if in_range(s, 1e-6, 170.0) => Ok(Some(s.to_radians())),
        (_, None, Some(_)) => Err(err("swing_deg", "must be in (0°, 170°]".into())),
        (_, None, None) if optional => Ok(None),
        _ => Err(err(
            "swing_deg",
            "an oscillating follower needs `swing_deg`, not `stroke`".into(),
        )),
    }
}

fn law(m: &MotionSpec, moving: &str, err: &KeyErr) -> Result<MotionLaw, ScenarioError> {
    let stroke = lift(m, moving, false, err)?.unwrap_or_default();
    let name = m.law.as_deref().ok_or_else(|| {
        err(
            "law",
            "missing: a `law` (or a `table` with `points`)".into(),
        )
    })?;
    let rise_deg = m
        .rise_deg
        .ok_or_else(|| err("rise_deg", "missing: the rise angle".into()))?;
    let law = |k: &str, s: &str| {
        Law::parse(s).ok_or_else(|| err(k, format!("unknown law '{s}' (uniform, parabolic, harmonic, cycloidal, cubic, polynomial)")))
    };
    let rise_law = law("law", name)?;
    let return_law = law("return_law", m.return_law.as_deref().unwrap_or(name))?;
    let ret = m.return_deg.unwrap_or(rise_deg);
    let dwell = m.dwell_top_deg.unwrap_or(0.0);
    for (k, v) in [("rise_deg", rise_deg), ("return_deg", ret)] {
        if !in_range(v, 1e-3, 360.0) {
            return Err(err(k, format!("must be in (0°, 360°], got {v}")));
        }
    }
    if !in_range(dwell, 0.0, 360.0) || rise_deg + dwell + ret > 360.0 + 1e-9 {
        return Err(err(
            "dwell_top_deg",
            format!(
                "rise + dwell + return = {}° exceeds a turn",
                rise_deg + dwell + ret
            ),
        ));
    }
    Ok(MotionLaw {
        stroke,
        rise: rise_deg.to_radians(),
        dwell_top: dwell.to_radians(),
        ret: ret.to_radians(),
        rise_law,
        return_law,
    })
}

/// A table: the law's keys are refused; a displacement table's values are mm
/// (translating) or degrees of swing (oscillating) and take no lift; a velocity or
/// acceleration diagram is scaled to `stroke` / `swing_deg` when given, else its values
/// are `ds/dφ` or `d²s/dφ²` per radian (mm or rad of swing).
fn table(
    m: &MotionSpec,
    t: &str,
    moving: &str,
    err: &KeyErr,
) -> Result<MotionTable, ScenarioError> {
    let kind = match t {
        "displacement" => TableKind::Displacement,
        "velocity" => TableKind::Velocity,
        "acceleration" => TableKind::Acceleration,
        other => {
            return Err(err(
                "table",
                format!("unknown table '{other}' (displacement, velocity or acceleration)"),
            ))
        }
    };
    for (k, given) in [
        ("law", m.law.is_some()),
        ("return_law", m.return_law.is_some()),
        ("rise_deg", m.rise_deg.is_some()),
        ("dwell_top_deg", m.dwell_top_deg.is_some()),
        ("return_deg", m.return_deg.is_some()),
    ] {
        if given {
            return Err(err(
                k,
                "does not apply to a table (its points give the timing)".into(),
            ));
        }
    }
    let pts = m.points.as_ref().ok_or_else(|| {
        err(
            "points",
            "missing: the table's [cam angle (deg), value] points".into(),
        )
    })?;
    if pts.len() > MAX_TABLE_POINTS {
        return Err(err(
            "points",
            format!("{} points: at most {MAX_TABLE_POINTS}", pts.len()),
        ));
    }
    let oscillating = moving != "translating";
    let mut points = Vec::with_capacity(pts.len());
    for (i, p) in pts.iter().enumerate() {
        if !in_range(p[0], 0.0, 360.0) || !p[1].is_finite() || p[1].abs() > 1e9 {
            return Err(err(
                "points",
                format!(
                    "point {i}: the cam angle lies in 0 … 360° and the value is finite, got {:?}",
                    p
                ),
            ));
        }
        let value = if oscillating && kind == TableKind::Displacement {
            p[1].to_radians()
        } else {
            p[1]
        };
        points.push((p[0].to_radians(), value));
    }
    let lifted = lift(m, moving, true, err)?;
    if kind == TableKind::Displacement && lifted.is_some() {
        let k = if oscillating { "swing_deg" } else { "stroke" };
        return Err(err(
            k,
            "does not apply to a displacement table (its values are the lift)".into(),
        ));
    }
    let t = MotionTable::new(kind, &points).map_err(|e| err("points", e.0))?;
    Ok(match lifted {
        Some(h) => t.scaled_to(h),
        None => t,
    })
}
