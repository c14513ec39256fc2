//! Forward dynamics `M(q) q̈ = τ − h(q, q̇)`: the one place that chooses the algorithm and
//! the one NaN policy, for the model's own dynamics ([`forward_dynamics`],
//! [`forward_dynamics_crba`]) and for the effect composition
//! ([`crate::dynamics::forward_dynamics_with`], [`crate::dynamics::elastic_forward_dynamics`]).
//!
//! - ABA ([`crate::dynamics::aba`], O(n)) when every body has its own coordinate;
//! - with mimic joints, or when asked for ([`forward_dynamics_crba`]), the projected mass
//!   matrix from [`crate::dynamics::crba`] and the bias from [`crate::dynamics::rnea`], solved by
//!   an in-place Cholesky factorisation `M = L Lᵀ` (no allocation).
//!
//! Either way a `q̈` with a NaN or an infinite entry is a [`SingularMassMatrix`] error: a
//! failed Cholesky pivot reports that pivot and its value, a non-finite result the first
//! non-finite coordinate (value 0).

use crate::core::linalg::{cholesky_in_place, cholesky_solve_in_place, SingularMassMatrix};
use crate::dynamics::aba::aba_impl;
use crate::dynamics::crba::crba_impl;
use crate::dynamics::effects::{Applied, EffectTerms, Effects};
use crate::dynamics::rnea::rnea_impl;
use crate::dynamics::terms::Terms;
use crate::model::data::Data;
use crate::model::Model;

/// `q̈` into `data.qdd` with the model's gravity and armature: ABA when every body has its
/// own coordinate, CRBA + Cholesky with mimic joints; a non-finite `q̈` is an error.
pub fn forward_dynamics<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'a [f64], SingularMassMatrix> {
    let model_effects = Applied::of_model(model);
    forward(model, data, &model_effects, Method::Auto, q, v, tau)
}

/// [`forward_dynamics`] always through the mass matrix (CRBA + Cholesky), whatever the
/// joints.
pub fn forward_dynamics_crba<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'a [f64], SingularMassMatrix> {
    forward(
        model,
        data,
        &Applied::of_model(model),
        Method::Crba,
        q,
        v,
        tau,
    )
}

/// Which algorithm solves for `q̈`.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Method {
    /// ABA unless the model has mimic joints.
    Auto,
    /// CRBA + Cholesky.
    Crba,
}

/// `q̈` into `data.qdd` with the applied effects (see the module docs).
pub(crate) fn forward<'a>(
    model: &Model,
    data: &'a mut Data,
    e: &Applied<'_>,
    method: Method,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
) -> Result<&'a [f64], SingularMassMatrix> {
    // Net applied torque after friction.
    let mut net = std::mem::take(&mut data.scratch_tau);
    net.copy_from_slice(tau);
    if let Some(fr) = e.friction {
        data.effect_runs.friction += 1;
        for k in 0..model.nv {
            net[k] -= fr.torque(k, qd[k]);
        }
    }
    let set = EffectTerms::set_up(model, data, e, q);
    let (terms, payload) = (set.terms(), set.payload);
    // The one choice of algorithm.
    let solved = if method == Method::Auto && !model.has_mimic {
        aba_impl(model, data, q, qd, &net, &terms);
        Ok(())
    } else {
        crba_solve(model, data, q, qd, &net, &terms)
    };
    set.restore(data);
    data.scratch_tau = net;
    // The one NaN policy.
    if let Err(mut e) = solved.and_then(|()| all_finite(&data.qdd)) {
        let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
        if !(finite(tau) && finite(qd) && finite(q)) {
            e.inputs_overflow = true;
        } else if e.value == 0.0 {
            // A non-finite q̈ (ABA): the mass matrix's own pivot names the coordinate
            // without mass; when it factors, the inputs overflowed.
            match mass_factors(model, data, q, payload) {
                Ok(()) => e.inputs_overflow = true,
                Err(c) => e = c,
            }
        }
        return Err(name_joint(e, model));
    }
    Ok(&data.qdd)
}

/// `M q̈ = net − h` through CRBA and Cholesky, into `data.qdd`.
fn crba_solve(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    qd: &[f64],
    net: &[f64],
    terms: &Terms<'_>,
) -> Result<(), SingularMassMatrix> {
    // h(q, q̇) = RNEA at q̈ = 0 (armature times zero adds nothing).
    let zero = std::mem::take(&mut data.scratch_nv);
    let bias_terms = Terms {
        rotor_armature: None,
        ..*terms
    };
    rnea_impl(model, data, q, qd, &zero, &bias_terms);
    data.scratch_nv = zero;
    for ((out, n), t) in data.qdd.iter_mut().zip(net).zip(&data.tau) {
        *out = n - t;
    }
    crba_impl(model, data, q, terms.payload);
    if let Some(a) = terms.rotor_armature {
        for (k, ak) in a.iter().enumerate() {
            data.mass[(k, k)] += ak;
        }
    }
    data.chol.copy_from(&data.mass);
    cholesky_in_place(&mut data.chol)?;
    cholesky_solve_in_place(&data.chol, &mut data.qdd);
    Ok(())
}

/// Whether the mass matrix at `q` (with the payload, without armature) factors: when it
/// does, a non-finite `q̈` comes from the inputs, not from a coordinate without mass;
/// when not, the failing pivot.
fn mass_factors(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    payload: Option<(usize, &crate::core::spatial::InertiaO)>,
) -> Result<(), SingularMassMatrix> {
    let mut m = crba_impl(model, data, q, payload).clone();
    cholesky_in_place(&mut m)
}

/// `Ok` when every entry of `qdd` is finite, else the first bad coordinate (value 0).
fn all_finite(qdd: &[f64]) -> Result<(), SingularMassMatrix> {
    match qdd.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(pivot) => Err(SingularMassMatrix::at(pivot, 0.0)),
    }
}

/// Forward dynamics with `effects` (rigid joints): `q̈` into `data.qdd`, through the one
/// dispatcher of [`crate::dynamics::forward_dynamics`] (ABA, or CRBA + Cholesky with mimic joints;
/// a non-finite `q̈` is an error).
pub fn forward_dynamics_with<'a>(
    model: &Model,
    data: &'a mut Data,
    effects: &Effects,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
) -> Result<&'a [f64], SingularMassMatrix> {
    data.effects_used = effects.set();
    forward(model, data, &Applied::of(effects), Method::Auto, q, qd, tau)
}

/// Flexible-joint forward dynamics (Spong's model, see the module docs). Link
/// accelerations go to `data.qdd`, motor accelerations to `thetadd`. Friction, when
/// included, acts on the motor side; `effects.rotor` is ignored here (the motor inertia is
/// `effects.elasticity.motor_inertia`). Panics if `effects.elasticity` is `None`.
#[allow(clippy::too_many_arguments)]
pub fn elastic_forward_dynamics<'a>(
    model: &Model,
    data: &'a mut Data,
    effects: &Effects,
    q: &[f64],
    qd: &[f64],
    theta: &[f64],
    thetad: &[f64],
    tau_m: &[f64],
    thetadd: &mut [f64],
) -> Result<&'a [f64], SingularMassMatrix> {
    let el = effects
        .elasticity
        .as_ref()
        .expect("elastic_forward_dynamics needs effects.elasticity");
    data.effect_runs.elasticity += 1;
    let mut spring = std::mem::take(&mut data.scratch_spring);
    for k in 0..model.nv {
        spring[k] = el.stiffness[k] * (theta[k] - q[k]) + el.damping[k] * (thetad[k] - qd[k]);
        let fric = effects
            .friction
            .as_ref()
            .map_or(0.0, |f| f.torque(k, thetad[k]));
        thetadd[k] = (tau_m[k] - spring[k] - fric) / el.motor_inertia[k];
    }
    if effects.friction.is_some() {
        data.effect_runs.friction += 1;
    }
    let link_side = Applied {
        friction: None,
        rotor: None,
        ..Applied::of(effects)
    };
    let r = forward(model, data, &link_side, Method::Auto, q, qd, &spring).map(|_| ());
    data.effects_used = effects.set();
    data.scratch_spring = spring;
    r.map(|()| &data.qdd[..])
}

/// `e` with the name of the joint of its coordinate (`e.pivot`).
pub(crate) fn name_joint(mut e: SingularMassMatrix, model: &Model) -> SingularMassMatrix {
    e.joint = model.dof_names().get(e.pivot).cloned().unwrap_or_default();
    e
}
