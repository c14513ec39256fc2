//! Analytical derivatives of forward dynamics, `∂q̈/∂q`, `∂q̈/∂q̇` and `∂q̈/∂τ = M⁻¹`
//! (Carpentier & Mansard, RSS 2018, §IV-C). Differentiating `ID(q, q̇, FD(q, q̇, τ)) = τ`:
//!
//! `∂q̈/∂q = −M⁻¹ ∂ID/∂q`, `∂q̈/∂q̇ = −M⁻¹ ∂ID/∂q̇`, `∂q̈/∂τ = M⁻¹`,
//!
//! with the inverse-dynamics partials ([`crate::dynamics::rnea_derivatives`]) taken at
//! `q̈ = FD(q, q̇, τ)` and `M⁻¹` from [`crate::dynamics::compute_minverse`].

use crate::core::linalg::SingularMassMatrix;
use crate::dynamics::forward::forward_dynamics;
use crate::dynamics::minverse::compute_minverse;
use crate::dynamics::rnea_derivatives::rnea_derivatives_impl;
use crate::dynamics::terms::Terms;
use crate::model::data::Data;
use crate::model::derivative_data::DerivativeData;
use crate::model::Model;
use nalgebra::DMatrix;

/// The partial derivatives of `q̈ = FD(q, q̇, τ)` ([`aba_derivatives`]), held in
/// [`Data::deriv`].
#[derive(Clone, Copy, Debug)]
pub struct AbaPartials<'a> {
    /// `∂q̈/∂q`, nv × nv.
    pub ddq_dq: &'a DMatrix<f64>,
    /// `∂q̈/∂q̇`, nv × nv.
    pub ddq_dv: &'a DMatrix<f64>,
    /// `∂q̈/∂τ = M(q)⁻¹`.
    pub minv: &'a DMatrix<f64>,
}

/// `∂q̈/∂q`, `∂q̈/∂q̇` and `M⁻¹` at `(q, q̇, τ)` with the model's gravity and armature, as
/// Pinocchio's `computeABADerivatives(model, data, q, v, tau)`; `data.qdd` gets `q̈`.
/// Fails when the mass matrix is singular or `q̈` is not finite.
pub fn aba_derivatives<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<AbaPartials<'a>, SingularMassMatrix> {
    forward_dynamics(model, data, q, v, tau)?;
    let qdd = std::mem::take(&mut data.qdd);
    rnea_derivatives_impl(model, data, q, v, &qdd, &Terms::of_model(model));
    data.qdd = qdd;
    compute_minverse(model, data, q)?;
    let DerivativeData {
        dtau_dq,
        dtau_dv,
        ddq_dq,
        ddq_dv,
        minv,
        ..
    } = &mut data.deriv;
    ddq_dq.gemm(-1.0, minv, dtau_dq, 0.0);
    ddq_dv.gemm(-1.0, minv, dtau_dv, 0.0);
    Ok(AbaPartials {
        ddq_dq: &data.deriv.ddq_dq,
        ddq_dv: &data.deriv.ddq_dv,
        minv: &data.deriv.minv,
    })
}
