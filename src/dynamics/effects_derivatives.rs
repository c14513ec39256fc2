//! Analytical derivatives of the dynamics with the scene's [`Effects`]: the partials of
//! [`inverse_dynamics`](crate::dynamics::inverse_dynamics) and of
//! [`forward_dynamics_with`](crate::dynamics::forward_dynamics_with), the same functions
//! differentiated, effect by effect:
//!
//! - **gravity** and **payload** enter the rigid recursion of
//!   [`crate::dynamics::rnea_derivatives`] (a payload is part of its body's inertia);
//! - **rotor armature** `I_m N²` adds to `M`'s diagonal, i.e. to `∂τ/∂q̈`;
//! - **friction** `τ_f(q̇)` (viscous, Coulomb and Stribeck, regularised) adds its slope
//!   `τ_f'(q̇)` to the diagonal of `∂τ/∂q̇`;
//! - **external wrenches** are fixed in the world (force `F` and moment `M` at the link
//!   origin `p(q)`, world axes): only their moment about the world origin,
//!   `n = M + p × F`, turns with `q`. The rigid recursion treats a wrench as fixed to its
//!   body, whose derivative `S_k ×* f` also turns `F` and `M` with the body; the
//!   difference is the wrench `δ_k = (ω_k × F, ω_k × M + p × (ω_k × F))` (Jacobi's
//!   identity), so `∂τ_j/∂q_k` gains `S_jᵀ δ_k` for every pair of joints `j`, `k`
//!   that carry the link.
//!
//! Forward dynamics `q̈ = M̃⁻¹(τ − τ_f(q̇) − h(q, q̇))` (`M̃` with payload and armature) is
//! differentiated through `ID(q, q̇, q̈) = τ`: `∂q̈/∂q = −M̃⁻¹ ∂ID/∂q`,
//! `∂q̈/∂q̇ = −M̃⁻¹ ∂ID/∂q̇`, `∂q̈/∂τ = M̃⁻¹`, with `ID` the inverse dynamics with the same
//! effects. **Elasticity is not in these functions**, as it is not in the two they
//! differentiate: its motor angles are extra states, which the step linearisation
//! ([`crate::dynamics::StepLinearisation`]) refuses rather than drop.

use crate::core::linalg::SingularMassMatrix;
use crate::core::spatial::Force;
use crate::dynamics::aba_derivatives::neg_product;
use crate::dynamics::aba_derivatives::AbaPartials;
use crate::dynamics::effects::{Applied, EffectTerms, Effects, ExternalWrench};
use crate::dynamics::forward::{forward_dynamics_with, name_joint};
use crate::dynamics::minverse::{invert_spd, inverts_mass_matrix, minverse_after_placements};
use crate::dynamics::rnea_derivatives::RneaPartials;
use crate::dynamics::rnea_derivatives::{rnea_derivatives_impl, rnea_partials};
use crate::model::data::Data;
use crate::model::{Model, WORLD};

/// `∂τ/∂q`, `∂τ/∂q̇` and `∂τ/∂q̈ = M̃` of [`crate::dynamics::inverse_dynamics`] at
/// `(q, q̇, q̈)` with `effects` (see the module docs; elasticity is ignored there and
/// here); `data.tau` gets `τ`.
pub fn inverse_dynamics_derivatives<'a>(
    model: &Model,
    data: &'a mut Data,
    effects: &Effects,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> RneaPartials<'a> {
    data.effects_used = effects.set();
    let set = EffectTerms::set_up(model, data, &Applied::of(effects), q);
    rnea_derivatives_impl(model, data, q, qd, qdd, &set.terms());
    set.restore(data);
    if !effects.external.is_empty() {
        for w in &effects.external {
            unturn_wrench(model, data, w);
        }
    }
    if let Some(fr) = &effects.friction {
        data.effect_runs.friction += 1;
        for (k, v) in qd.iter().enumerate() {
            data.tau[k] += fr.torque(k, *v);
            data.deriv.dtau_dv[(k, k)] += fr.slope(k, *v);
        }
    }
    rnea_partials(data)
}

/// Turns the rigid recursion's body-fixed derivative of wrench `w` into the world-fixed
/// one: `∂τ_j/∂q_k += S_jᵀ δ_k` for the joints `j`, `k` carrying `w`'s link (module docs).
/// Needs `data.o_m_i` and `data.s_world` current.
fn unturn_wrench(model: &Model, data: &mut Data, w: &ExternalWrench) {
    let link = &model.links[w.link];
    if link.body == WORLD {
        return;
    }
    let p = data.o_m_i[link.body].act_point(&link.offset.trans);
    let dq = &mut data.deriv.dtau_dq;
    let mut k = link.body;
    while k != WORLD {
        let omega = data.s_world[k].w;
        let turned = omega.cross(&w.force);
        let delta = Force::new(turned, omega.cross(&w.moment) + p.cross(&turned));
        let (ck, mk) = (model.q_index[k], model.q_mult[k]);
        let mut j = link.body;
        while j != WORLD {
            let (cj, mj) = (model.q_index[j], model.q_mult[j]);
            dq[(cj, ck)] += mj * mk * delta.dot_motion(&data.s_world[j]);
            j = model.parent[j];
        }
        k = model.parent[k];
    }
}

/// `∂q̈/∂q`, `∂q̈/∂q̇` and `∂q̈/∂τ = M̃⁻¹` of [`crate::dynamics::forward_dynamics_with`]
/// at `(q, q̇, τ)` with `effects` (module docs); `data.qdd` gets `q̈`. Fails as forward
/// dynamics does: a singular mass matrix or a non-finite `q̈`, naming the joint.
pub fn forward_dynamics_derivatives<'a>(
    model: &Model,
    data: &'a mut Data,
    effects: &Effects,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
) -> Result<AbaPartials<'a>, SingularMassMatrix> {
    data.deriv.ensure(model);
    forward_dynamics_with(model, data, effects, q, qd, tau)?;
    let qdd = std::mem::take(&mut data.qdd);
    inverse_dynamics_derivatives(model, data, effects, q, qd, &qdd);
    data.qdd = qdd;
    if inverts_mass_matrix(model) || effects.payload.is_some() || effects.rotor.is_some() {
        // M̃ is `∂τ/∂q̈`, just computed.
        let d = &mut data.deriv;
        invert_spd(&d.dtau_da, &mut data.chol, &mut d.minv).map_err(|e| name_joint(e, model))?;
    } else {
        // M̃ is the model's own M, whose inverse the O(n²) recursion gives from the
        // placements the derivatives left current.
        minverse_after_placements(model, data, q)?;
    }
    let d = &mut data.deriv;
    neg_product(&mut d.ddq_dq, &d.minv, &d.dtau_dq, d.isa);
    neg_product(&mut d.ddq_dv, &d.minv, &d.dtau_dv, d.isa);
    Ok(AbaPartials {
        ddq_dq: &data.deriv.ddq_dq,
        ddq_dv: &data.deriv.ddq_dv,
        minv: &data.deriv.minv,
    })
}
