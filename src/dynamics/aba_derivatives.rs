//! Analytical derivatives of forward dynamics, `∂q̈/∂q`, `∂q̈/∂q̇` and `∂q̈/∂τ = M⁻¹`
//! (Carpentier & Mansard, RSS 2018, §IV-C). Differentiating `ID(q, q̇, FD(q, q̇, τ)) = τ`:
//!
//! `∂q̈/∂q = −M⁻¹ ∂ID/∂q`, `∂q̈/∂q̇ = −M⁻¹ ∂ID/∂q̇`, `∂q̈/∂τ = M⁻¹`,
//!
//! with the inverse-dynamics partials ([`crate::dynamics::rnea_derivatives`]) taken at
//! `q̈ = FD(q, q̇, τ) = M⁻¹(τ − h)` and `M⁻¹` from [`crate::dynamics::compute_minverse`].

use crate::core::linalg::SingularMassMatrix;
use crate::dynamics::forward::name_joint;
use crate::dynamics::minverse::minverse_after_placements;
use crate::dynamics::rnea::add_armature;
use crate::dynamics::rnea_derivatives::{add_joint_accelerations, backward_pass, forward_pass};
use crate::dynamics::terms::Terms;
use crate::kinematics::forward_kinematics;
use crate::model::data::Data;
use crate::model::derivative_data::DerivativeData;
use crate::model::{Model, WORLD};
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
///
/// One forward pass serves both: run with `q̈ = 0` it gives the bias `h(q, q̇)`, then
/// `q̈ = M⁻¹(τ − h)`, whose accelerations are added to it
/// ([`crate::dynamics::rnea_derivatives`] is affine in `q̈`) before the backward pass.
pub fn aba_derivatives<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<AbaPartials<'a>, SingularMassMatrix> {
    let nv = model.nv;
    assert!(
        q.len() == nv && v.len() == nv && tau.len() == nv,
        "q, v, tau need nv values"
    );
    data.deriv.ensure(model);
    let terms = Terms::of_model(model);
    forward_kinematics(model, data, q);
    let zero = std::mem::take(&mut data.scratch_nv);
    forward_pass(model, data, v, &zero, &terms);
    data.scratch_nv = zero;
    bias_to_rhs(model, data, tau);
    minverse_after_placements(model, data, q)?;
    solve_accelerations(model, data)?;
    let qdd = std::mem::take(&mut data.qdd);
    add_joint_accelerations(model, data, &qdd);
    backward_pass(model, data, &terms);
    add_armature(model, &terms, &qdd, &mut data.tau);
    data.qdd = qdd;
    let DerivativeData {
        dtau_dq,
        dtau_dv,
        ddq_dq,
        ddq_dv,
        minv,
        ..
    } = &mut data.deriv;
    neg_product(ddq_dq, minv, dtau_dq);
    neg_product(ddq_dv, minv, dtau_dv);
    Ok(AbaPartials {
        ddq_dq: &data.deriv.ddq_dq,
        ddq_dv: &data.deriv.ddq_dv,
        minv: &data.deriv.minv,
    })
}

/// `τ − h(q, q̇)` into `data.deriv.rhs`, from the forces of a forward pass with `q̈ = 0`.
fn bias_to_rhs(model: &Model, data: &mut Data, tau: &[f64]) {
    let d = &mut data.deriv;
    d.bias_f.copy_from_slice(&d.of);
    d.rhs.copy_from_slice(tau);
    for i in (0..model.nbodies()).rev() {
        let f = d.bias_f[i];
        d.rhs[model.q_index[i]] -= model.q_mult[i] * f.dot_motion(&data.s_world[i]);
        let parent = model.parent[i];
        if parent != WORLD {
            d.bias_f[parent] = d.bias_f[parent].add(&f);
        }
    }
}

/// `q̈ = M⁻¹ (τ − h)` into `data.qdd`; a non-finite `q̈` with a factorable `M` means the
/// inputs overflowed.
fn solve_accelerations(model: &Model, data: &mut Data) -> Result<(), SingularMassMatrix> {
    let n = model.nv;
    let (minv, rhs) = (data.deriv.minv.as_slice(), &data.deriv.rhs);
    data.qdd.fill(0.0);
    for (k, col) in minv.chunks_exact(n).enumerate() {
        let x = rhs[k];
        for (o, m) in data.qdd.iter_mut().zip(col) {
            *o += m * x;
        }
    }
    if let Some(bad) = data.qdd.iter().position(|x| !x.is_finite()) {
        let mut e = SingularMassMatrix::at(bad, 0.0);
        e.inputs_overflow = true;
        return Err(name_joint(e, model));
    }
    Ok(())
}

/// Up to this many coordinates [`neg_product`] sums columns directly; above, the blocked
/// product of nalgebra (matrixmultiply) is faster.
pub(crate) const DIRECT_PRODUCT_MAX: usize = 24;

/// `out = −a b` for square column-major matrices: at arm sizes column by column as sums
/// of `a`'s columns (contiguous, so the inner loop vectorises, and no packing), else the
/// blocked general product.
pub(crate) fn neg_product(out: &mut DMatrix<f64>, a: &DMatrix<f64>, b: &DMatrix<f64>) {
    let n = a.nrows();
    if n > DIRECT_PRODUCT_MAX {
        out.gemm(-1.0, a, b, 0.0);
        return;
    }
    let (a, b) = (a.as_slice(), b.as_slice());
    for (c, oc) in out.as_mut_slice().chunks_exact_mut(n).enumerate() {
        oc.fill(0.0);
        for (k, ak) in a.chunks_exact(n).enumerate() {
            let x = -b[c * n + k];
            for (o, y) in oc.iter_mut().zip(ak) {
                *o += x * y;
            }
        }
    }
}
