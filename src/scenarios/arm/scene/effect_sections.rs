//! The effects of an arm scenario: which are named (`effects = [...]`, in
//! [`EFFECT_NAMES`] order) and their parameter tables (gravity, friction, rotor inertia,
//! joint elasticity, payload), checked per joint against the model.

use crate::core::diag::LocatedError as ScenarioError;
use crate::core::spatial::{Inertia, Mat3, Vec3};
use crate::dynamics::{Effects, Elasticity, Friction, Payload, Rotor};
use crate::scenarios::arm::scene::arm_scene::EFFECT_NAMES;
use crate::scenarios::arm::scene::model::link_by_name;
use crate::scenarios::arm::scene::section_reader::{get_f, per_joint_checked, Sections};
use crate::scenarios::arm::schema::*;

/// The named effects (each once, known, in [`EFFECT_NAMES`] order); a parameter table
/// for an effect left out is a warning, a needed one missing an error.
pub(super) fn named(
    cx: &crate::scenarios::source::Source,
    file: &ArmFile,
    warnings: &mut Vec<String>,
) -> Result<Vec<&'static str>, ScenarioError> {
    // Effects named.
    let mut named: Vec<&'static str> = Vec::new();
    for e in file.effects.get_ref() {
        let Some(k) = EFFECT_NAMES.iter().position(|n| n == e.get_ref()) else {
            return Err(cx.at(
                e.span(),
                "effects",
                format!(
                    "unknown effect '{}' (known: {})",
                    e.get_ref(),
                    EFFECT_NAMES.join(", ")
                ),
            ));
        };
        if named.contains(&EFFECT_NAMES[k]) {
            return Err(cx.at(
                e.span(),
                "effects",
                format!("effect '{}' listed twice", e.get_ref()),
            ));
        }
        named.push(EFFECT_NAMES[k]);
    }
    named.sort_by_key(|n| EFFECT_NAMES.iter().position(|m| m == n));
    let has = |e: &str| named.contains(&e);
    // Parameter tables for effects left out: ignored, with a warning.
    let tables = [
        file.gravity.is_some(),
        file.friction.is_some(),
        file.rotor_inertia.is_some(),
        file.joint_elasticity.is_some(),
        file.payload.is_some(),
        file.contact.is_some(),
    ];
    for (&sec, present) in EFFECT_NAMES.iter().zip(tables) {
        if present && !has(sec) {
            warnings.push(format!(
                "[{sec}] is given but '{sec}' is not in effects: it is not simulated"
            ));
        }
    }
    if has("contact") && file.contact.is_none() {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'contact' needs a [contact] table (table, box, pusher)",
        ));
    }
    if has("contact") && !has("gravity") {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'contact' needs 'gravity' (the box rests on the table under its weight)",
        ));
    }
    if has("joint_elasticity") && file.joint_elasticity.is_none() {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'joint_elasticity' needs a [joint_elasticity] table with the stiffness",
        ));
    }
    if has("payload") && file.payload.is_none() {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'payload' needs a [payload] table with the mass",
        ));
    }
    Ok(named)
}

/// The effects for dynamics, the payload masses of a sweep and the payload inertia.
pub(super) fn build(sx: &Sections, named: &[&'static str]) -> Result<Built, ScenarioError> {
    let mut effects = Effects::default();
    gravity_and_friction(sx, named, &mut effects)?;
    let transmissions = rotor_inertia(sx, named, &mut effects)?;
    joint_elasticity(sx, named, &mut effects)?;
    let (payload_masses, payload_inertia) = payload(sx, named, &mut effects)?;
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    effects
        .validate(model)
        .map_err(|e| cx.at(file.effects.span(), "effects", e.to_string()))?;
    Ok((effects, payload_masses, payload_inertia, transmissions))
}

/// The effects, the payload masses of a sweep, the payload inertia on its link, the
/// joints' gear trains.
pub(super) type Built = (
    Effects,
    Vec<f64>,
    Option<(usize, Inertia)>,
    Vec<crate::scenarios::arm::scene::transmission::JointTransmission>,
);

fn gravity_and_friction(
    sx: &Sections,
    named: &[&str],
    effects: &mut Effects,
) -> Result<(), ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let names = &sx.names;
    let n = sx.n;
    let base = &sx.base;
    let has = |e: &str| named.contains(&e);
    if has("gravity") {
        let g = match file
            .gravity
            .as_ref()
            .and_then(|g| g.get_ref().vector.as_ref())
        {
            Some(v) if v.get_ref().iter().all(|x| x.is_finite()) => *v.get_ref(),
            Some(v) => return Err(cx.at(v.span(), "gravity.vector", "not finite")),
            None => [0.0, 0.0, -9.81],
        };
        effects.gravity = Some(base.rot.transpose() * Vec3::new(g[0], g[1], g[2]));
    }
    if has("friction") {
        let mut f = Friction::from_model(model);
        if let Some(sec) = &file.friction {
            let s = sec.get_ref();
            let read = |v: &Option<PerJoint>, key: &str, cur: &[f64], zero_ok: bool| {
                per_joint_checked(cx, v.as_ref(), key, names, cur, zero_ok)
            };
            f.viscous = read(&s.viscous, "friction.viscous", &f.viscous, true)?;
            f.coulomb = read(&s.coulomb, "friction.coulomb", &f.coulomb, true)?;
            f.stiction = read(&s.stiction, "friction.stiction", &f.stiction, true)?;
            let key = "friction.stribeck_velocity";
            f.stribeck_velocity = read(&s.stribeck_velocity, key, &f.stribeck_velocity, false)?;
            // Stiction defaults to the Coulomb level when only that is given.
            if s.coulomb.is_some() && s.stiction.is_none() {
                f.stiction = f.coulomb.clone();
            }
            if let Some(v) = &s.stiction {
                let low = (0..n).find(|&k| f.stiction[k] < f.coulomb[k]);
                if let Some(k) = low {
                    return Err(cx.at(
                        v.span(),
                        "friction.stiction",
                        format!(
                            "joint {}: stiction {} is below the Coulomb level {}",
                            names[k], f.stiction[k], f.coulomb[k]
                        ),
                    ));
                }
            }
            f.smoothing = get_f(cx, &s.smoothing, "friction.smoothing", f.smoothing)?;
        }
        effects.friction = Some(f);
    }
    Ok(())
}

fn rotor_inertia(
    sx: &Sections,
    named: &[&str],
    effects: &mut Effects,
) -> Result<Vec<crate::scenarios::arm::scene::transmission::JointTransmission>, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let names = &sx.names;
    let has = |e: &str| named.contains(&e);
    let mut trains = Vec::new();
    if has("rotor_inertia") {
        let mut r = Rotor::from_model(model, 1.0);
        if let Some(sec) = &file.rotor_inertia {
            let s = sec.get_ref();
            let key = "rotor_inertia.inertia";
            r.inertia = per_joint_checked(cx, s.inertia.as_ref(), key, names, &r.inertia, true)?;
            let key = "rotor_inertia.gear_ratio";
            r.gear_ratio =
                per_joint_checked(cx, s.gear_ratio.as_ref(), key, names, &r.gear_ratio, false)?;
            let key = "rotor_inertia.efficiency";
            r.efficiency =
                per_joint_checked(cx, s.efficiency.as_ref(), key, names, &r.efficiency, false)?;
            if let Some(v) = &s.efficiency {
                if let Some(k) = r.efficiency.iter().position(|e| *e > 1.0) {
                    return Err(cx.at(
                        v.span(),
                        key,
                        format!(
                            "joint {}: efficiency {} is above 1",
                            names[k], r.efficiency[k]
                        ),
                    ));
                }
            }
            if let Some(g) = &s.gear_train {
                trains = crate::scenarios::arm::scene::transmission::apply(sx, g, &mut r)?;
            }
        }
        if r.inertia.iter().all(|x| *x == 0.0) {
            let span = file
                .rotor_inertia
                .as_ref()
                .map(|s| s.span())
                .unwrap_or(file.effects.span());
            return Err(cx.at(
                span,
                "rotor_inertia.inertia",
                "effect 'rotor_inertia' is named but every rotor inertia is 0 (the model gives none): set rotor_inertia.inertia",
            ));
        }
        effects.rotor = Some(r);
    }
    Ok(trains)
}

fn joint_elasticity(
    sx: &Sections,
    named: &[&str],
    effects: &mut Effects,
) -> Result<(), ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let names = &sx.names;
    let n = sx.n;
    let has = |e: &str| named.contains(&e);
    if has("joint_elasticity") {
        let sec = file.joint_elasticity.as_ref().expect("checked above");
        let s = sec.get_ref();
        let zeros = vec![0.0; n];
        let key = "joint_elasticity.stiffness";
        let stiffness = per_joint_checked(cx, Some(&s.stiffness), key, names, &zeros, false)?;
        let key = "joint_elasticity.damping";
        let damping = per_joint_checked(cx, s.damping.as_ref(), key, names, &zeros, true)?;
        let from_rotor: Vec<f64> = match &effects.rotor {
            Some(r) => (0..n).map(|k| r.armature(k)).collect(),
            None => (0..n)
                .map(|k| {
                    let j = model.dof_joint(k);
                    j.motor_inertia * j.gear_ratio * j.gear_ratio
                })
                .collect(),
        };
        let key = "joint_elasticity.motor_inertia";
        let motor_inertia = match &s.motor_inertia {
            Some(_) => {
                per_joint_checked(cx, s.motor_inertia.as_ref(), key, names, &from_rotor, false)?
            }
            None => {
                if let Some(k) = from_rotor.iter().position(|b| *b <= 0.0) {
                    return Err(cx.at(
                        sec.span(),
                        "joint_elasticity.motor_inertia",
                        format!(
                            "joint {}: no motor inertia in the model; set joint_elasticity.motor_inertia (reflected, I_m N², kg m²)",
                            names[k]
                        ),
                    ));
                }
                from_rotor
            }
        };
        effects.elasticity = Some(Elasticity {
            stiffness,
            damping,
            motor_inertia,
        });
    }
    Ok(())
}

type PayloadOut = (Vec<f64>, Option<(usize, Inertia)>);

fn payload(
    sx: &Sections,
    named: &[&str],
    effects: &mut Effects,
) -> Result<PayloadOut, ScenarioError> {
    let cx = &sx.cx;
    let file = sx.file;
    let model = sx.model;
    let tool = sx.tool;
    let has = |e: &str| named.contains(&e);
    if !has("payload") {
        return Ok((Vec::new(), None));
    }
    {
        let sec = file.payload.as_ref().expect("checked above");
        let s = sec.get_ref();
        let link = match &s.link {
            Some(l) => link_by_name(cx, model, l, "payload.link")?,
            None => tool,
        };
        let as_num = |x: &toml::Value| match x {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        };
        let payload_masses = match s.mass.get_ref() {
            toml::Value::Array(a) if !a.is_empty() => a
                .iter()
                .map(as_num)
                .collect::<Option<Vec<f64>>>()
                .ok_or_else(|| cx.at(s.mass.span(), "payload.mass", "expected numbers"))?,
            x => vec![as_num(x).ok_or_else(|| {
                cx.at(
                    s.mass.span(),
                    "payload.mass",
                    "expected a mass (kg) or a non-empty list of masses for a sweep",
                )
            })?],
        };
        if let Some(m) = payload_masses
            .iter()
            .find(|m| !(m.is_finite() && **m >= 0.0))
        {
            return Err(cx.at(
                s.mass.span(),
                "payload.mass",
                format!("masses must be finite and >= 0 (got {m})"),
            ));
        }
        if !s.com.iter().all(|x| x.is_finite()) {
            return Err(cx.at(sec.span(), "payload.com", "not finite"));
        }
        let inertia_com = match &s.inertia {
            None => Mat3::zeros(),
            Some(v) => {
                let i = v.get_ref();
                let m = match i.len() {
                    3 => Mat3::from_diagonal(&Vec3::new(i[0], i[1], i[2])),
                    6 => Mat3::new(i[0], i[3], i[4], i[3], i[1], i[5], i[4], i[5], i[2]),
                    k => {
                        return Err(cx.at(
                            v.span(),
                            "payload.inertia",
                            format!("expected 3 or 6 values, got {k}"),
                        ))
                    }
                };
                let eig = m.symmetric_eigenvalues();
                if !i.iter().all(|x| x.is_finite()) || eig.iter().any(|e| *e < -1e-12) {
                    return Err(cx.at(
                        v.span(),
                        "payload.inertia",
                        "the inertia is not symmetric positive semi-definite",
                    ));
                }
                m
            }
        };
        let com = Vec3::new(s.com[0], s.com[1], s.com[2]);
        let mass = *payload_masses.last().expect("non-empty");
        let inertia = Inertia::new(mass, com, inertia_com);
        let p = Payload::new(model, link, inertia)
            .map_err(|e| cx.at(sec.span(), "payload.link", e.to_string()))?;
        effects.payload = Some(p);
        Ok((payload_masses, Some((link, inertia))))
    }
}
