//! The `[kinetostatics]`, `[[loads]]`, `[counterweight]` and `[flywheel]` sections:
//! gravity, the report positions, point forces and torques on links, pin friction, the
//! counterweight's links, the flywheel's speed and torque table, and the two bearing
//! points of prismatic guides (`[[sliders]] contacts`), each error naming the file, the
//! line and the key.

use crate::core::diag::{all_finite, LocatedError as ScenarioError};
use crate::machines::linkage::description::{Linkage, PlanarJoint};
use crate::machines::linkage::kinetostatics::{Loads, PointForce};
use crate::machines::linkage::Vec2;
use crate::scenarios::linkage::linkage_scenario::{
    CounterweightScenario, FlywheelScenario, KinetostaticsScenario, MechanismScenario, PinFriction,
};
use crate::scenarios::linkage::linkage_spec::{
    moving_link, FlywheelSpec, KinetoSpec, LoadSpec, Spec,
};
use crate::scenarios::source::Source;
use toml::Spanned;

/// The `[kinetostatics]` table with its `[[loads]]`: gravity, the report positions (the
/// sweep's by default), the loads and the pin friction.
pub(super) fn parse_kineto(
    cx: &Source,
    k: &Spanned<KinetoSpec>,
    loads: &[Spanned<LoadSpec>],
    l: &Linkage,
    angle_input: bool,
    sweep_report: &[f64],
) -> Result<KinetostaticsScenario, ScenarioError> {
    let span = k.span();
    let ks = k.get_ref();
    let g = ks.gravity.unwrap_or([0.0, -9.81]);
    if !all_finite(&g) {
        return Err(cx.err(
            cx.key_line(&span, "gravity"),
            "kinetostatics.gravity",
            "non-finite",
        ));
    }
    if angle_input && !ks.report_at.is_empty() {
        return Err(cx.err(
            cx.key_line(&span, "report_at"),
            "kinetostatics.report_at",
            "an angle driver: use report_at_deg",
        ));
    }
    if !angle_input && !ks.report_at_deg.is_empty() {
        return Err(cx.err(
            cx.key_line(&span, "report_at_deg"),
            "kinetostatics.report_at_deg",
            "a slide driver: use report_at (m)",
        ));
    }
    let mut report_at: Vec<f64> = if angle_input {
        ks.report_at_deg.iter().map(|x| x.to_radians()).collect()
    } else {
        ks.report_at.clone()
    };
    if report_at.is_empty() {
        report_at = sweep_report.to_vec();
    }
    let mut out = Loads {
        gravity: Vec2::new(g[0], g[1]),
        ..Default::default()
    };
    for (i, ls) in loads.iter().enumerate() {
        parse_load(cx, i, ls, l, &mut out)?;
    }
    let friction = parse_pin_friction(cx, k, l)?
        .or_else(|| crate::scenarios::linkage::contacts_section::contact_friction_only(l));
    Ok(KinetostaticsScenario {
        loads: out,
        friction,
        report_at,
    })
}

/// `loads[i]`: a force at a named point of a link, and/or a torque on it, into `out`.
fn parse_load(
    cx: &Source,
    i: usize,
    ls: &Spanned<LoadSpec>,
    l: &Linkage,
    out: &mut Loads,
) -> Result<(), ScenarioError> {
    let s = ls.get_ref();
    let span = ls.span();
    let key = format!("loads[{i}]");
    let link = moving_link(cx, &l.links, &s.link, &span, (&key, "link"))?;
    if s.force.is_none() && s.torque.is_none() {
        return Err(cx.err(
            cx.line(&span),
            key,
            "a load needs `force` (with `point`) or `torque`",
        ));
    }
    if let Some(f) = s.force {
        let pn = s.point.as_ref().ok_or_else(|| {
            cx.err(
                cx.key_line(&span, "force"),
                format!("{key}.point"),
                "missing: where the force acts",
            )
        })?;
        let p = l.links[link].point(pn).ok_or_else(|| {
            cx.err(
                cx.key_line(&span, "point"),
                format!("{key}.point"),
                format!("link '{}' has no point '{pn}'", s.link),
            )
        })?;
        if !all_finite(&f) {
            return Err(cx.err(
                cx.key_line(&span, "force"),
                format!("{key}.force"),
                "non-finite",
            ));
        }
        out.forces.push(PointForce {
            link,
            p,
            force: Vec2::new(f[0], f[1]),
        });
    }
    if let Some(t) = s.torque {
        if !t.is_finite() {
            return Err(cx.err(
                cx.key_line(&span, "torque"),
                format!("{key}.torque"),
                "non-finite",
            ));
        }
        out.torques.push((link, t));
    }
    Ok(())
}

/// The pin friction: none, or a coefficient in `[0, 1]` with a radius ≥ 0 for every pin
/// (`pin_radius`, 0 by default) and radii of named pins (`pin_radii`); a radius without
/// a coefficient is an error, and so is a name that is not a pin of the linkage.
fn parse_pin_friction(
    cx: &Source,
    k: &Spanned<KinetoSpec>,
    l: &Linkage,
) -> Result<Option<PinFriction>, ScenarioError> {
    let span = k.span();
    let ks = k.get_ref();
    let radius_ok = |r: f64| r.is_finite() && (0.0..=1e3).contains(&r);
    let Some(f) = ks.friction_coefficient else {
        let key = match (&ks.pin_radius, &ks.pin_radii) {
            (None, None) => return Ok(None),
            (Some(_), _) => "pin_radius",
            (None, Some(_)) => "pin_radii",
        };
        return Err(cx.err(
            cx.key_line(&span, key),
            format!("kinetostatics.{key}"),
            "a pin radius needs friction_coefficient (the friction circle is f r)",
        ));
    };
    if !(0.0..=1.0).contains(&f) {
        return Err(cx.err(
            cx.key_line(&span, "friction_coefficient"),
            "kinetostatics.friction_coefficient",
            format!("must be in [0, 1], got {f}"),
        ));
    }
    let r = ks.pin_radius.unwrap_or(0.0);
    if !radius_ok(r) {
        return Err(cx.err(
            cx.key_line(&span, "pin_radius"),
            "kinetostatics.pin_radius",
            format!("must be a radius in 0 … 1000 m, got {r}"),
        ));
    }
    let mut radii = vec![r; l.joints.len()];
    let mut named = Vec::new();
    let pins: Vec<&str> = l
        .joints
        .iter()
        .filter(|j| matches!(j, PlanarJoint::Revolute { .. }))
        .map(PlanarJoint::name)
        .collect();
    for (name, &rj) in ks.pin_radii.iter().flatten() {
        let bad = |m: String| {
            cx.err(
                cx.key_line(&span, "pin_radii"),
                format!("kinetostatics.pin_radii.{name}"),
                m,
            )
        };
        let Some(j) = l.joints.iter().position(|j| j.name() == name) else {
            return Err(bad(format!(
                "no joint of the linkage is named '{name}' (its pins: {})",
                pins.join(", ")
            )));
        };
        if !matches!(l.joints[j], PlanarJoint::Revolute { .. }) {
            return Err(bad(format!(
                "'{name}' is a slider or a contact: a pin radius does not apply (its pins: {})",
                pins.join(", ")
            )));
        }
        if !radius_ok(rj) {
            return Err(bad(format!("must be a radius in 0 … 1000 m, got {rj}")));
        }
        radii[j] = rj;
        named.push((name.clone(), rj));
    }
    Ok(Some(PinFriction {
        coefficient: f,
        default_radius: r,
        radii,
        named,
    }))
}

pub(super) fn parse_flywheel(
    cx: &Source,
    f: &Spanned<FlywheelSpec>,
    mech: Option<&MechanismScenario>,
) -> Result<FlywheelScenario, ScenarioError> {
    let span = f.span();
    let s = f.get_ref();
    if !(s.speed_fluctuation.is_finite() && s.speed_fluctuation > 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "speed_fluctuation"),
            "flywheel.speed_fluctuation",
            "must be positive",
        ));
    }
    let speed = match (s.speed, mech) {
        (Some(w), _) => w,
        (None, Some(m)) if m.angle_input => m.speed,
        _ => {
            return Err(cx.err(
                cx.line(&span),
                "flywheel.speed",
                "missing: the mean speed (rad/s)",
            ))
        }
    };
    if !(speed.is_finite() && speed != 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "speed"),
            "flywheel.speed",
            "must be non-zero",
        ));
    }
    let table = match &s.torque_deg {
        Some(t) => {
            if t.len() < 3
                || t.iter().any(|r| !all_finite(r))
                || t.windows(2).any(|w| w[1][0] <= w[0][0])
            {
                return Err(cx.err(
                    cx.key_line(&span, "torque_deg"),
                    "flywheel.torque_deg",
                    "needs at least three finite [angle_deg, torque] rows with increasing angles",
                ));
            }
            Some(t.iter().map(|r| (r[0].to_radians(), r[1])).collect())
        }
        None => {
            if mech.and_then(|m| m.kinetostatics.as_ref()).is_none()
                || !mech.is_some_and(|m| m.angle_input)
            {
                return Err(cx.err(
                    cx.line(&span),
                    "flywheel",
                    "needs `torque_deg` or a crank-driven linkage with [kinetostatics]",
                ));
            }
            None
        }
    };
    Ok(FlywheelScenario {
        delta: s.speed_fluctuation,
        speed,
        load: s.load,
        table,
    })
}

/// The `[counterweight]` (needs the kinetostatics).
pub(super) fn parse_counterweight(
    cx: &Source,
    spec: &Spec,
    linkage: &Linkage,
    has_kinetostatics: bool,
) -> Result<Option<CounterweightScenario>, ScenarioError> {
    let counterweight = match &spec.counterweight {
        None => None,
        Some(c) => {
            let span = c.span();
            let cs = c.get_ref();
            let find = |key: &str, n: &str| {
                moving_link(cx, &linkage.links, n, &span, ("counterweight", key))
            };
            if !has_kinetostatics {
                return Err(cx.err(
                    cx.line(&span),
                    "counterweight",
                    "needs [kinetostatics] (the shaking force comes from it)",
                ));
            }
            if !(cs.radius.is_finite() && cs.radius > 0.0) {
                return Err(cx.err(
                    cx.key_line(&span, "radius"),
                    "counterweight.radius",
                    "must be positive",
                ));
            }
            let fraction = match (cs.fraction, cs.rod_radius) {
                (Some(k), None) if k.is_finite() && (0.0..=1.0).contains(&k) => k,
                (Some(_), None) => {
                    return Err(cx.err(
                        cx.key_line(&span, "fraction"),
                        "counterweight.fraction",
                        "must be in [0, 1]",
                    ))
                }
                (None, Some(e)) if e.is_finite() && e > 0.0 => 0.0,
                (None, Some(_)) => {
                    return Err(cx.err(
                        cx.key_line(&span, "rod_radius"),
                        "counterweight.rod_radius",
                        "must be positive",
                    ))
                }
                (Some(_), Some(_)) | (None, None) => {
                    return Err(cx.err(
                        cx.key_line(&span, "fraction"),
                        "counterweight.fraction",
                        "give fraction (a crank counterweight) or rod_radius (full balancing by counterweights on the rod and the crank), one of the two",
                    ))
                }
            };
            Some(CounterweightScenario {
                crank: find("crank", &cs.crank)?,
                rod: find("rod", &cs.rod)?,
                slider: find("slider", &cs.slider)?,
                fraction,
                radius: cs.radius,
                rod_radius: cs.rod_radius,
            })
        }
    };
    Ok(counterweight)
}

/// `[[sliders]] contacts = [a, b]` (and `contacts_on`): prismatic guides that bear at two
/// points of their line; they need `[kinetostatics]` (the split of the guide's reaction).
pub(super) fn parse_guide_contacts(
    cx: &Source,
    spec: &Spec,
    l: &Linkage,
    kinetostatics: bool,
) -> Result<Vec<crate::machines::friction::two_point_guide::TwoPointGuide>, ScenarioError> {
    let n_pins = l.joints.len() - spec.sliders.len();
    let mut out = Vec::new();
    for (k, sp) in spec.sliders.iter().enumerate() {
        let (s, span) = (sp.get_ref(), sp.span());
        let key = format!("sliders[{k}]");
        let Some(c) = &s.contacts else {
            if s.contacts_on.is_some() {
                return Err(cx.err(
                    cx.key_line(&span, "contacts_on"),
                    format!("{key}.contacts_on"),
                    "applies only with `contacts = [a, b]`",
                ));
            }
            continue;
        };
        let err = |m: &str| cx.err(cx.key_line(&span, "contacts"), format!("{key}.contacts"), m);
        if s.kind != "prismatic" {
            return Err(err(
                "two bearing points need a prismatic slider (a pin in a slot carries no couple)",
            ));
        }
        if !kinetostatics {
            return Err(err(
                "the two bearing forces are a kinetostatic result: add a [kinetostatics] table",
            ));
        }
        let scale = l.length_scale().max(1e-300);
        let at = match c.as_slice() {
            [a, b] if a.is_finite() && b.is_finite() => [*a, *b],
            [_, _] => return Err(err("non-finite")),
            _ => return Err(err("needs two positions along the line, [a, b] (m)")),
        };
        if (at[0] - at[1]).abs() <= 1e-9 * scale {
            return Err(err("the two bearing points must differ"));
        }
        if at
            .iter()
            .any(|x| x.abs() > crate::scenarios::source::MAX_SCALE_RATIO * scale)
        {
            return Err(err("a bearing point lies far outside the linkage"));
        }
        let on_link = match s.contacts_on.as_deref() {
            None | Some("guide") => false,
            Some("link") => true,
            Some(other) => {
                return Err(cx.err(
                    cx.key_line(&span, "contacts_on"),
                    format!("{key}.contacts_on"),
                    format!("unknown '{other}' (expected \"guide\" or \"link\")"),
                ))
            }
        };
        out.push(crate::machines::friction::two_point_guide::TwoPointGuide {
            joint: n_pins + k,
            at,
            on_link,
        });
    }
    Ok(out)
}
